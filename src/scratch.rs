//! Per-thread working memory for the spectral hot path: large arrays (the interface blocks at
//! every node of the band, the path classes of one node) taken from a per-thread pool and
//! given back when dropped, so that a query neither allocates them nor moves them.

use std::cell::RefCell;
use std::thread::LocalKey;

/// The free boxes of one kind, per thread.
pub type Pool<T> = RefCell<Vec<Box<T>>>;

/// A box from a [`Pool`], returned to it when dropped (its contents as they are: each user
/// resets what it reads).
pub struct Pooled<T: 'static> {
    value: Option<Box<T>>,
    pool: &'static LocalKey<Pool<T>>,
}

impl<T: 'static> Pooled<T> {
    /// A box from `pool`, or a new one from `make` when the pool is empty (the first queries of
    /// a thread, or nested ones).
    pub fn take(pool: &'static LocalKey<Pool<T>>, make: impl FnOnce() -> Box<T>) -> Self {
        let reused = pool.with(|p| p.borrow_mut().pop());
        Pooled {
            value: Some(reused.unwrap_or_else(make)),
            pool,
        }
    }
}

impl<T> std::ops::Deref for Pooled<T> {
    type Target = T;
    fn deref(&self) -> &T {
        self.value.as_ref().expect("a box until dropped")
    }
}

impl<T> std::ops::DerefMut for Pooled<T> {
    fn deref_mut(&mut self) -> &mut T {
        self.value.as_mut().expect("a box until dropped")
    }
}

impl<T> Drop for Pooled<T> {
    fn drop(&mut self) {
        if let Some(b) = self.value.take() {
            // During thread teardown the pool may be gone: the box is then simply freed.
            let _ = self.pool.try_with(|p| p.borrow_mut().push(b));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    thread_local! {
        static TEST_POOL: Pool<[u64; 4]> = const { RefCell::new(Vec::new()) };
    }

    /// A box goes back to its pool when dropped and is handed out again, contents kept.
    #[test]
    fn boxes_are_reused() {
        let address = {
            let mut a = Pooled::take(&TEST_POOL, || Box::new([0; 4]));
            a[1] = 7;
            &*a as *const [u64; 4] as usize
        };
        let b = Pooled::take(&TEST_POOL, || Box::new([0; 4]));
        assert_eq!(&*b as *const [u64; 4] as usize, address);
        assert_eq!(b[1], 7);
        // A nested take while the first is held gets a fresh box.
        let c = Pooled::take(&TEST_POOL, || Box::new([1; 4]));
        assert_eq!(c[0], 1);
    }
}
