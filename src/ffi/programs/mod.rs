//! The programs the shim replays in Mitsuba's JIT variants: the per-wavelength physics of a
//! query recorded once ([`crate::record`]) with the query's per-lane values as inputs, so that
//! Mitsuba traces it into its kernels like its own plugins' code (symbolic loops and calls, CUDA,
//! Dr.Jit's derivatives). The inputs and outputs of each program are the bridge's enums
//! (`PlateInput`, `SampleOutput`): the one contract with the shim. One module per plugin.

mod crystal;
mod layer;
mod plate;
mod stack;

pub use crystal::record_crystal;
pub use plate::record_plate;
pub use stack::record_stack;

use super::bridge::{Instr, Op as BridgeOp, SampleOutput, Transport};
use crate::error::{Error, Result};
use crate::plate::slab::{Output as Intensity, Want};
use crate::real::{Mask, Real};
use crate::record::{self, Op, Output, Var};
use crate::render::choice::Sampled;
use crate::render::thin::MAX_BANDS;
use crate::render::Transport as CoreTransport;

/// A recorded program, as the shim reads it.
pub struct Program {
    recorded: record::Program,
    instrs: Vec<Instr>,
}

impl Program {
    pub(super) fn new(recorded: record::Program) -> Self {
        Program {
            instrs: recorded.instrs.iter().map(bridge_instr).collect(),
            recorded,
        }
    }

    /// The program as recorded (which [`record::Program::run`] runs on the host).
    pub fn recorded(&self) -> &record::Program {
        &self.recorded
    }

    /// The instructions, operands before their uses.
    pub fn instructions(&self) -> &[Instr] {
        &self.instrs
    }

    /// The value numbers of the outputs (`SampleOutput` order).
    pub fn outputs(&self) -> &[u32] {
        &self.recorded.outputs
    }

    /// How many inputs it reads.
    pub fn inputs(&self) -> usize {
        self.recorded.inputs
    }

    /// Instructions other than constants and inputs.
    pub fn operations(&self) -> usize {
        self.instrs
            .iter()
            .filter(|i| !matches!(i.op, BridgeOp::Const | BridgeOp::Input | BridgeOp::Flag))
            .count()
    }
}

/// The bridge's form of an instruction (the same operations in the same order).
fn bridge_instr(i: &record::Instr) -> Instr {
    Instr {
        op: BridgeOp { repr: i.op as u8 },
        a: i.a,
        b: i.b,
        c: i.c,
        value: i.value,
    }
}

/// The outputs of a sample in `SampleOutput` order; lanes with a non-finite output fail.
pub(super) fn outputs<const C: usize>(s: &Sampled<Var, C>) -> Result<Vec<Output>> {
    let mut numbers = vec![s.slot, s.component, s.pdf, s.eta, s.wo.x, s.wo.y, s.wo.z];
    for c in 0..MAX_BANDS {
        let c = c.min(C - 1);
        numbers.extend(s.in_x[c].iter().chain(s.out_x[c].iter()));
        numbers.extend(s.value[c].transpose().iter());
    }
    let finite = numbers.iter().fold(s.valid, |m, x| m & x.finite()) | !s.valid;
    (!finite).fail(|| Error::internal("sample", "a non-finite number"))?;
    let mut out = vec![Output::Mask(s.valid)];
    out.extend(numbers.into_iter().map(Output::Number));
    debug_assert_eq!(out.len(), SampleOutput::Count.repr as usize);
    Ok(out)
}

/// The core's transport mode.
/// The number of exact wavelengths a recipe asks for, checked once (1 to [`MAX_BANDS`]).
pub(super) fn channel_count(channels: u32) -> Result<usize> {
    let channels = channels as usize;
    if (1..=MAX_BANDS).contains(&channels) {
        Ok(channels)
    } else {
        Err(Error::new(
            "channels",
            format!("must be 1 to {MAX_BANDS}, got {channels}"),
        ))
    }
}

/// The lobes of a thin element a recipe's `components` bits ask for (bit 0 reflection, bit 1
/// transmission).
pub(super) fn wanted(components: u32) -> Want {
    Want {
        reflection: components & 1 != 0,
        transmission: components & 2 != 0,
    }
}

/// Only `M00` (an unpolarized variant) or the whole Mueller matrix.
pub(super) fn output(intensity_only: bool) -> Intensity {
    if intensity_only {
        Intensity::Intensity
    } else {
        Intensity::Mueller
    }
}

pub(super) fn core_transport(t: Transport) -> Result<CoreTransport> {
    match t {
        Transport::Radiance => Ok(CoreTransport::Radiance),
        Transport::Importance => Ok(CoreTransport::Importance),
        t => Err(Error::new(
            "transport",
            format!("must be Radiance (0) or Importance (1), got {}", t.repr),
        )),
    }
}

/// The recorder's operations are the bridge's, in the same order.
const _: () = {
    assert!(Op::Const as u8 == BridgeOp::Const.repr);
    assert!(Op::Flag as u8 == BridgeOp::Flag.repr);
    assert!(Op::Select as u8 == BridgeOp::Select.repr);
};
