//! Writing each lane's sampled lobe into the output columns (`bridge::Samples`).

use super::bridge::{Samples, Status};
use super::columns::check_output;
use super::guard::{non_finite, status};
use crate::error::{Error, Result};
use crate::render::choice::Choice;
use crate::render::slots::Slots;

/// The output columns of a batch of `count` lanes and `channels` channels, validated.
pub struct Output<'o, 'a> {
    out: &'o mut Samples<'a>,
    count: usize,
    channels: usize,
    frames: bool,
    full: bool,
    first_failure: Option<Status>,
}

/// One lane's numbers, gathered before they are checked and written.
struct Lane {
    component: u32,
    pdf: f64,
    eta: f64,
    wo: [f64; 3],
    in_x: [[f64; 3]; 4],
    out_x: [[f64; 3]; 4],
    value: [[f64; 16]; 4],
}

impl<'o, 'a> Output<'o, 'a> {
    /// Checks every column's length.
    pub fn new(out: &'o mut Samples<'a>, count: usize, channels: usize) -> Result<Self> {
        let per_channel = channels * count;
        check_output("status", out.status, count, false)?;
        check_output("component", out.component, count, false)?;
        check_output("pdf", out.pdf, count, false)?;
        check_output("eta", out.eta, count, false)?;
        for c in &out.wo {
            check_output("wo", c, count, false)?;
        }
        let frames = !out.in_stokes_x[0].is_empty();
        for c in out.in_stokes_x.iter().chain(&out.out_stokes_x) {
            check_output("stokes_x", c, if frames { per_channel } else { 0 }, !frames)?;
        }
        check_output("value", out.value[0], per_channel, false)?;
        let full = !out.value[1].is_empty();
        for c in &out.value[1..] {
            check_output("value", c, if full { per_channel } else { 0 }, !full)?;
        }
        Ok(Output {
            out,
            count,
            channels,
            frames,
            full,
            first_failure: None,
        })
    }

    /// Channels per lane.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Lane `i` samples nothing.
    pub fn nothing(&mut self, i: usize) {
        let (n, channels) = (self.count, self.channels);
        let o = &mut *self.out;
        o.status[i] = Status::Ok;
        o.component[i] = 0;
        o.pdf[i] = 0.0;
        o.eta[i] = 0.0;
        for c in o.wo.iter_mut() {
            c[i] = 0.0;
        }
        for ch in 0..channels {
            let at = ch * n + i;
            for c in o.in_stokes_x.iter_mut().chain(o.out_stokes_x.iter_mut()) {
                if let Some(x) = c.get_mut(at) {
                    *x = 0.0;
                }
            }
            for c in o.value.iter_mut() {
                if let Some(x) = c.get_mut(at) {
                    *x = 0.0;
                }
            }
        }
    }

    /// Lane `i` failed with `e`: it samples nothing; the first failure's message is kept.
    pub fn fail(&mut self, i: usize, e: &Error) {
        self.nothing(i);
        let s = status(e);
        self.out.status[i] = s;
        if self.first_failure.is_none() {
            self.first_failure = Some(s);
            self.out.message = e.to_string();
        }
    }

    /// The call's status: `Ok`, or the first failure's.
    pub fn status(&self) -> Status {
        self.first_failure.unwrap_or(Status::Ok)
    }

    /// Lane `i` samples `choice` among `lobes` (one slot array per channel, the query's
    /// channels in order), with Mitsuba component `component`.
    pub fn write<const S: usize>(
        &mut self,
        i: usize,
        lobes: &[Slots<S>],
        choice: Choice,
        component: usize,
    ) -> Result<()> {
        let lane = gather(lobes, choice, component);
        if !lane.is_finite(self.channels) {
            return Err(non_finite());
        }
        let (n, o) = (self.count, &mut *self.out);
        o.status[i] = Status::Ok;
        o.component[i] = lane.component;
        o.pdf[i] = lane.pdf;
        o.eta[i] = lane.eta;
        for (c, x) in o.wo.iter_mut().zip(lane.wo) {
            c[i] = x;
        }
        for ch in 0..self.channels {
            let at = ch * n + i;
            if self.frames {
                for k in 0..3 {
                    o.in_stokes_x[k][at] = lane.in_x[ch][k];
                    o.out_stokes_x[k][at] = lane.out_x[ch][k];
                }
            }
            let entries = if self.full { 16 } else { 1 };
            for k in 0..entries {
                o.value[k][at] = lane.value[ch][k];
            }
        }
        Ok(())
    }
}

/// The numbers of the chosen slot: the hero channel's direction, each channel's frames and
/// Mueller matrix over the pdf (the hero's frames and zero where a channel lacks the lobe).
fn gather<const S: usize>(lobes: &[Slots<S>], choice: Choice, component: usize) -> Lane {
    let hero = lobes[choice.hero][choice.slot].expect("the hero channel has the chosen slot");
    let mut lane = Lane {
        component: component as u32,
        pdf: choice.pdf,
        eta: hero.eta,
        wo: hero.wo.into(),
        in_x: [hero.in_stokes_x.into(); 4],
        out_x: [hero.out_stokes_x.into(); 4],
        value: [[0.0; 16]; 4],
    };
    for (ch, slots) in lobes.iter().enumerate() {
        let Some(l) = &slots[choice.slot] else {
            continue;
        };
        lane.in_x[ch] = l.in_stokes_x.into();
        lane.out_x[ch] = l.out_stokes_x.into();
        for k in 0..16 {
            lane.value[ch][k] = l.mueller[(k / 4, k % 4)] / choice.pdf;
        }
    }
    lane
}

impl Lane {
    /// True if every number of the first `channels` channels is finite: `Σ 0·x` is 0 exactly
    /// when every `x` is finite (NaN otherwise), a branch-free sum.
    fn is_finite(&self, channels: usize) -> bool {
        let zero_sum = |xs: &[f64]| xs.iter().fold(0.0, |acc, x| acc + 0.0 * x);
        let mut total = zero_sum(&self.wo) + zero_sum(&[self.pdf, self.eta]);
        for ch in 0..channels {
            total +=
                zero_sum(&self.in_x[ch]) + zero_sum(&self.out_x[ch]) + zero_sum(&self.value[ch]);
        }
        total == 0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PathLobe;
    use nalgebra::{Matrix4, Vector3};

    /// `is_finite` rejects a NaN or an infinity in any number of any used channel, and
    /// accepts large, tiny and negative finite values (and ignores unused channels).
    #[test]
    fn finiteness_checks_every_number() {
        let z = Vector3::new(0.0, -1e300, 1e-300);
        let l = PathLobe::new(1, z, (z, z), Matrix4::repeat(2.0), 1.5);
        let lobes = [[Some(l), None], [Some(l), None]];
        let choice = Choice {
            slot: 0,
            pdf: f64::MIN_POSITIVE,
            hero: 0,
        };
        let good = gather(&lobes, choice, 1);
        assert!(good.is_finite(2));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for k in 0..(5 + 2 * 22) {
                let mut x = gather(&lobes, choice, 1);
                match k {
                    0..=2 => x.wo[k] = bad,
                    3 => x.pdf = bad,
                    4 => x.eta = bad,
                    _ => {
                        let (ch, j) = ((k - 5) / 22, (k - 5) % 22);
                        match j {
                            0..=2 => x.in_x[ch][j] = bad,
                            3..=5 => x.out_x[ch][j - 3] = bad,
                            _ => x.value[ch][j - 6] = bad,
                        }
                    }
                }
                assert!(!x.is_finite(2), "{bad} at {k} accepted");
            }
            let mut x = gather(&lobes, choice, 1);
            x.value[3][0] = bad;
            assert!(x.is_finite(2), "unused channel checked");
        }
    }
}
