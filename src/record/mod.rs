//! Recording the per-wavelength physics as a program: [`Var`] is a [`Real`] whose operations
//! are written to a tape instead of computed, [`Flag`] the mask of its comparisons. Run the
//! physics on `Var` inputs inside [`record`] and the tape is a straight-line [`Program`]
//! (arithmetic, square roots, sines, exponentials, comparisons and `select` for every branch
//! that depends on a lane) that the shim replays with Dr.Jit arrays while Mitsuba traces a
//! kernel: one source, written in Rust, run on `f64` by the scalar variants and inside
//! Mitsuba's kernels by the JIT variants.
//!
//! While recording, operations on constants are folded (in `f64`, as the host would compute
//! them), equal instructions are recorded once, and `x + 0`, `x · 1`, `x · 0`, `x − x`,
//! `x == x`, a `select` of a known mask and the like are simplified (identities of finite
//! numbers; a lane with a non-finite value fails anyway): a lossless medium's complex
//! arithmetic becomes real arithmetic by itself, and a medium whose two indices are the same
//! value is known to be isotropic.

pub mod program;

use crate::error::{Error, Result};
use crate::real::{Mask, Real, Select};
pub use program::{Instr, Op, Program};
use std::cell::RefCell;
use std::collections::HashMap;
use std::ops::{
    Add, AddAssign, BitAnd, BitOr, Div, DivAssign, Mul, MulAssign, Neg, Not, Rem, RemAssign, Sub,
    SubAssign,
};

/// A recorded number: a value number of the program being recorded.
#[derive(Clone, Copy, Debug)]
pub struct Var(u32);

/// A recorded mask.
#[derive(Clone, Copy, Debug)]
pub struct Flag(u32);

/// The program being recorded on this thread.
struct Tape {
    instrs: Vec<Instr>,
    /// Each instruction's value number, for sharing equal ones.
    index: HashMap<(Op, u32, u32, u32, u64), u32>,
    inputs: usize,
    /// Lanes that cannot be computed ([`Mask::fail`]).
    failed: Option<u32>,
}

thread_local! {
    static TAPE: RefCell<Option<Tape>> = const { RefCell::new(None) };
}

/// Runs `f` on the tape of this thread; panics outside [`record`] (a recorded number used
/// after its recording ended: a bug of the caller).
fn with_tape<R>(f: impl FnOnce(&mut Tape) -> R) -> R {
    TAPE.with(|t| {
        let mut t = t.borrow_mut();
        f(t.as_mut().expect("a recorded number used outside record()"))
    })
}

impl Tape {
    fn constant(&self, k: u32) -> Option<f64> {
        let i = &self.instrs[k as usize];
        matches!(i.op, Op::Const | Op::Flag).then_some(i.value)
    }

    /// Appends `op(a, b, c)` (or finds the equal instruction, or folds it).
    fn push(&mut self, op: Op, mut a: u32, mut b: u32, c: u32, value: f64) -> u32 {
        let n = op.operands();
        // A value compared with itself (the same recorded value: a finite lane's, or the lane
        // fails anyway), or subtracted from itself.
        if n == 2 && a == b {
            match op {
                Op::Eq | Op::Le => return self.push(Op::Flag, 0, 0, 0, 1.0),
                Op::Lt => return self.push(Op::Flag, 0, 0, 0, 0.0),
                Op::Sub => return self.push(Op::Const, 0, 0, 0, 0.0),
                _ => {}
            }
        }
        if n > 0 {
            if let Some(k) = self.simplify(op, a, b, c) {
                return k;
            }
        }
        let known: Vec<Option<f64>> = [a, b, c][..n].iter().map(|&k| self.constant(k)).collect();
        if n > 0 && known.iter().all(Option::is_some) {
            let v: Vec<f64> = known.iter().map(|x| x.unwrap()).collect();
            let at = |i: usize| v.get(i).copied().unwrap_or(0.0);
            let folded = program::apply(op, at(0), at(1), at(2), value);
            let constant = if op.gives_mask() { Op::Flag } else { Op::Const };
            return self.push(constant, 0, 0, 0, folded);
        }
        if op.commutes() && a > b {
            std::mem::swap(&mut a, &mut b);
        }
        let key = (op, a, b, c, value.to_bits());
        if let Some(&k) = self.index.get(&key) {
            return k;
        }
        let k = self.instrs.len() as u32;
        self.instrs.push(Instr { op, a, b, c, value });
        self.index.insert(key, k);
        k
    }

    /// An existing value equal to `op(a, b, c)` by an identity exact in `f64` for finite
    /// operands (`x + 0`, `x · 1`, `x · 0`, `−(−x)`, a `select` of a known mask, ...).
    fn simplify(&self, op: Op, a: u32, b: u32, c: u32) -> Option<u32> {
        let ka = self.constant(a);
        let kb = (op.operands() >= 2).then(|| self.constant(b)).flatten();
        let zero = |k: Option<f64>| k == Some(0.0);
        let one = |k: Option<f64>| k == Some(1.0);
        let instr = |k: u32| self.instrs[k as usize];
        match op {
            Op::Add if zero(kb) => Some(a),
            Op::Add if zero(ka) => Some(b),
            Op::Sub if zero(kb) => Some(a),
            Op::Mul | Op::And if one(kb) => Some(a),
            Op::Mul | Op::And if one(ka) => Some(b),
            Op::Mul | Op::And if zero(ka) => Some(a),
            Op::Mul | Op::And if zero(kb) => Some(b),
            Op::Or if zero(kb) => Some(a),
            Op::Or if zero(ka) => Some(b),
            Op::Or if one(ka) => Some(a),
            Op::Or if one(kb) => Some(b),
            Op::Div if one(kb) || zero(ka) => Some(a),
            Op::Neg | Op::Not if instr(a).op == op => Some(instr(a).a),
            Op::Select if ka.is_some() => Some(if ka != Some(0.0) { b } else { c }),
            Op::Select if b == c => Some(b),
            Op::Detach if ka.is_some() => Some(a),
            _ => None,
        }
    }
}

/// Records `f` run on `inputs` recorded numbers: the program that computes its outputs (and,
/// as its last output, the mask of the lanes that cannot be computed, [`Mask::fail`]).
/// Fails with `f`'s error, or if a recording is already under way on this thread.
pub fn record(inputs: usize, f: impl FnOnce(&[Var]) -> Result<Vec<Output>>) -> Result<Program> {
    let busy = TAPE.with(|t| t.borrow().is_some());
    if busy {
        return Err(Error::new("record", "a recording is already under way"));
    }
    TAPE.with(|t| {
        *t.borrow_mut() = Some(Tape {
            instrs: Vec::new(),
            index: HashMap::new(),
            inputs,
            failed: None,
        })
    });
    // The tape is taken back even if `f` panics (the bridge catches the panic).
    struct Finish;
    impl Drop for Finish {
        fn drop(&mut self) {
            TAPE.with(|t| t.borrow_mut().take());
        }
    }
    let _finish = Finish;
    let vars: Vec<Var> = (0..inputs)
        .map(|i| Var(with_tape(|t| t.push(Op::Input, i as u32, 0, 0, 0.0))))
        .collect();
    let outputs = f(&vars)?;
    let failed = with_tape(|t| t.failed).map_or_else(|| Flag::cst(false), Flag);
    with_tape(|t| {
        let mut ids: Vec<u32> = outputs.iter().map(|o| o.id()).collect();
        ids.push(failed.0);
        Ok(Program::pruned(&t.instrs, t.inputs, &ids))
    })
}

/// An output of a recording: a number or a mask.
#[derive(Clone, Copy, Debug)]
pub enum Output {
    /// A number.
    Number(Var),
    /// A mask.
    Mask(Flag),
}

impl Output {
    fn id(&self) -> u32 {
        match *self {
            Output::Number(v) => v.0,
            Output::Mask(m) => m.0,
        }
    }
}

impl From<Var> for Output {
    fn from(v: Var) -> Self {
        Output::Number(v)
    }
}

impl From<Flag> for Output {
    fn from(m: Flag) -> Self {
        Output::Mask(m)
    }
}

impl Var {
    fn op(op: Op, a: u32, b: u32, c: u32) -> Var {
        Var(with_tape(|t| t.push(op, a, b, c, 0.0)))
    }
    fn unary(self, op: Op) -> Var {
        Var::op(op, self.0, 0, 0)
    }
    fn binary(self, op: Op, other: Var) -> Var {
        Var::op(op, self.0, other.0, 0)
    }
    fn compare(self, op: Op, other: Var) -> Flag {
        Flag(with_tape(|t| t.push(op, self.0, other.0, 0, 0.0)))
    }
}

impl PartialEq for Var {
    /// The same recorded value (equal instructions are recorded once).
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}

macro_rules! arithmetic {
    ($($trait:ident $method:ident $assign:ident $assign_method:ident $op:ident),*) => {$(
        impl $trait for Var {
            type Output = Var;
            #[inline]
            fn $method(self, other: Var) -> Var {
                self.binary(Op::$op, other)
            }
        }
        impl $trait<f64> for Var {
            type Output = Var;
            #[inline]
            fn $method(self, other: f64) -> Var {
                self.binary(Op::$op, Var::cst(other))
            }
        }
        impl $assign for Var {
            #[inline]
            fn $assign_method(&mut self, other: Var) {
                *self = self.binary(Op::$op, other);
            }
        }
    )*};
}
arithmetic!(
    Add add AddAssign add_assign Add,
    Sub sub SubAssign sub_assign Sub,
    Mul mul MulAssign mul_assign Mul,
    Div div DivAssign div_assign Div
);

impl Neg for Var {
    type Output = Var;
    fn neg(self) -> Var {
        self.unary(Op::Neg)
    }
}

/// Programs have no remainder; `num_traits::Num` asks for one.
impl Rem for Var {
    type Output = Var;
    fn rem(self, _: Var) -> Var {
        unreachable!("the remainder is not recorded")
    }
}

impl RemAssign for Var {
    fn rem_assign(&mut self, _: Var) {
        unreachable!("the remainder is not recorded")
    }
}

impl num_traits::Zero for Var {
    fn zero() -> Self {
        Var::cst(0.0)
    }
    fn is_zero(&self) -> bool {
        self.value() == Some(0.0)
    }
}

impl num_traits::One for Var {
    fn one() -> Self {
        Var::cst(1.0)
    }
}

impl num_traits::Num for Var {
    type FromStrRadixErr = <f64 as num_traits::Num>::FromStrRadixErr;
    fn from_str_radix(s: &str, radix: u32) -> std::result::Result<Self, Self::FromStrRadixErr> {
        <f64 as num_traits::Num>::from_str_radix(s, radix).map(Var::cst)
    }
}

impl Select<Flag> for Var {
    fn select(m: Flag, a: Self, b: Self) -> Self {
        Var::op(Op::Select, m.0, a.0, b.0)
    }
}

impl Real for Var {
    type Mask = Flag;
    const RECORDED: bool = true;
    fn cst(x: f64) -> Self {
        Var(with_tape(|t| t.push(Op::Const, 0, 0, 0, x)))
    }
    fn value(self) -> Option<f64> {
        with_tape(|t| t.constant(self.0))
    }
    fn sqrt(self) -> Self {
        self.unary(Op::Sqrt)
    }
    fn safe_sqrt(self) -> Self {
        self.unary(Op::SafeSqrt)
    }
    fn sin(self) -> Self {
        self.unary(Op::Sin)
    }
    fn cos(self) -> Self {
        self.unary(Op::Cos)
    }
    fn exp(self) -> Self {
        self.unary(Op::Exp)
    }
    fn abs(self) -> Self {
        self.unary(Op::Abs)
    }
    fn min(self, other: Self) -> Self {
        self.binary(Op::Min, other)
    }
    fn max(self, other: Self) -> Self {
        self.binary(Op::Max, other)
    }
    fn copysign(self, sign: Self) -> Self {
        self.binary(Op::CopySign, sign)
    }
    fn detach(self) -> Self {
        self.unary(Op::Detach)
    }
    fn lt(self, other: Self) -> Flag {
        self.compare(Op::Lt, other)
    }
    fn le(self, other: Self) -> Flag {
        self.compare(Op::Le, other)
    }
    fn equals(self, other: Self) -> Flag {
        self.compare(Op::Eq, other)
    }
    fn finite(self) -> Flag {
        Flag(with_tape(|t| t.push(Op::Finite, self.0, 0, 0, 0.0)))
    }
}

impl BitAnd for Flag {
    type Output = Flag;
    fn bitand(self, other: Flag) -> Flag {
        Flag(with_tape(|t| t.push(Op::And, self.0, other.0, 0, 0.0)))
    }
}

impl BitOr for Flag {
    type Output = Flag;
    fn bitor(self, other: Flag) -> Flag {
        Flag(with_tape(|t| t.push(Op::Or, self.0, other.0, 0, 0.0)))
    }
}

impl Not for Flag {
    type Output = Flag;
    fn not(self) -> Flag {
        Flag(with_tape(|t| t.push(Op::Not, self.0, 0, 0, 0.0)))
    }
}

impl Select<Flag> for Flag {
    fn select(m: Flag, a: Self, b: Self) -> Self {
        (m & a) | (!m & b)
    }
}

impl Mask for Flag {
    fn cst(b: bool) -> Self {
        Flag(with_tape(|t| {
            t.push(Op::Flag, 0, 0, 0, if b { 1.0 } else { 0.0 })
        }))
    }
    fn known(self) -> Option<bool> {
        with_tape(|t| t.constant(self.0)).map(|v| v != 0.0)
    }
    fn fail(self, err: impl FnOnce() -> Error) -> Result<()> {
        if self.known() == Some(true) {
            return Err(err());
        }
        let failed = with_tape(|t| t.failed).map_or(self, |f| Flag(f) | self);
        with_tape(|t| t.failed = Some(failed.0));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::real::complex::{self, Cx};

    /// A generic function recorded and run equals the same function on `f64`, branches and
    /// folding included.
    fn check<F: Fn(&[Var]) -> Vec<Var>, G: Fn(&[f64]) -> Vec<f64>>(
        inputs: &[&[f64]],
        recorded: F,
        direct: G,
    ) -> Program {
        let n = inputs[0].len();
        let p = record(n, |x| {
            Ok(recorded(x).into_iter().map(Output::from).collect())
        })
        .unwrap();
        for x in inputs {
            let got = p.run(x);
            let want = direct(x);
            for (g, w) in got.iter().zip(&want) {
                assert!(g == w || (g.is_nan() && w.is_nan()), "{x:?}: {g} vs {w}");
            }
            assert_eq!(got.last(), Some(&0.0), "no lane failed");
        }
        p
    }

    /// The complex square root on both sides of its branches.
    #[test]
    fn recorded_square_root_equals_the_host_one() {
        fn f<T: Real>(x: &[T]) -> Vec<T> {
            let z = complex::sqrt(Cx::new(x[0], x[1]));
            vec![z.re, z.im]
        }
        let inputs: Vec<Vec<f64>> = [
            (2.0, 0.0),
            (-2.0, 0.0),
            (-2.0, -0.0),
            (0.0, 0.0),
            (3.0, -4.0),
            (-3.0, 4.0),
            (-4.0, 1e-20),
        ]
        .iter()
        .map(|&(a, b)| vec![a, b])
        .collect();
        let refs: Vec<&[f64]> = inputs.iter().map(|v| v.as_slice()).collect();
        check(&refs, f::<Var>, f::<f64>);
    }

    /// Constants fold, equal instructions are shared, unused ones are dropped, and a complex
    /// product of real numbers records real arithmetic only.
    #[test]
    fn folding_sharing_and_pruning() {
        let p = check(
            &[&[1.5, 2.0]],
            |x| {
                let a = Cx::new(x[0], Var::cst(0.0));
                let b = Cx::new(x[1], Var::cst(0.0));
                let _unused = x[0].exp();
                let c = a * b + Cx::new(Var::cst(2.0) * Var::cst(3.0), Var::cst(0.0));
                vec![c.re, c.im, x[0] * x[1]]
            },
            |x| vec![x[0] * x[1] + 6.0, 0.0, x[0] * x[1]],
        );
        // Two inputs, one product, the constant 6, one sum, the zero and the failure flag.
        let ops: Vec<Op> = p.instrs.iter().map(|i| i.op).collect();
        assert_eq!(p.operations(), 2, "{ops:?}");
        assert!(!ops.contains(&Op::Exp));
    }

    /// A failing lane is reported in the last output; a failure known while recording is the
    /// error itself.
    #[test]
    fn failures_become_a_mask() {
        let p = record(1, |x| {
            x[0].lt(Var::cst(0.0))
                .fail(|| Error::new("x", "negative"))?;
            Ok(vec![x[0].sqrt().into()])
        })
        .unwrap();
        assert_eq!(p.run(&[-1.0])[1], 1.0);
        assert_eq!(p.run(&[4.0]), vec![2.0, 0.0]);
        let e = record(1, |_| {
            Flag::cst(true).fail(|| Error::new("x", "always"))?;
            Ok(vec![])
        })
        .unwrap_err();
        assert_eq!(e.parameter, "x");
    }

    /// A recording inside a recording is refused, and the tape is released after a panic.
    #[test]
    fn nested_recordings_are_refused() {
        let e = record(0, |_| {
            record(0, |_| Ok(vec![]))?;
            Ok(vec![])
        })
        .unwrap_err();
        assert_eq!(e.parameter, "record");
        let _ = std::panic::catch_unwind(|| record(0, |_| panic!("inside")));
        assert!(record(0, |_| Ok(vec![])).is_ok());
    }
}
