//! A recorded program: straight-line instructions over numbers and masks, in the order they
//! were recorded (every operand precedes its use), the constants folded, equal instructions
//! shared, and only what the outputs need kept.

/// An operation of a program. Numbers are `f64` on the host and Dr.Jit floats in the shim;
/// masks are `bool` and Dr.Jit masks (0 or 1 in [`Program::run`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum Op {
    /// The number `value`.
    Const,
    /// Input number `a`.
    Input,
    /// `−a`.
    Neg,
    /// `a + b`.
    Add,
    /// `a − b`.
    Sub,
    /// `a · b`.
    Mul,
    /// `a / b`.
    Div,
    /// `√a`.
    Sqrt,
    /// `√max(a, 0)` with a finite derivative at 0.
    SafeSqrt,
    /// `sin a`.
    Sin,
    /// `cos a`.
    Cos,
    /// `eᵃ`.
    Exp,
    /// `|a|`.
    Abs,
    /// `min(a, b)`.
    Min,
    /// `max(a, b)`.
    Max,
    /// `|a|` with the sign of `b`.
    CopySign,
    /// `a`, through which no derivative flows.
    Detach,
    /// Number `b` where mask `a` holds, else number `c`.
    Select,
    /// Mask: `a < b`.
    Lt,
    /// Mask: `a <= b`.
    Le,
    /// Mask: `a == b`.
    Eq,
    /// Mask: `a` is finite.
    Finite,
    /// Mask: `a & b`.
    And,
    /// Mask: `a | b`.
    Or,
    /// Mask: `!a`.
    Not,
    /// The mask `value != 0`.
    Flag,
}

impl Op {
    /// True for an operation whose result is a mask.
    pub fn gives_mask(self) -> bool {
        matches!(
            self,
            Op::Lt | Op::Le | Op::Eq | Op::Finite | Op::And | Op::Or | Op::Not | Op::Flag
        )
    }

    /// True for an operation whose two operands can be swapped.
    pub(crate) fn commutes(self) -> bool {
        matches!(
            self,
            Op::Add | Op::Mul | Op::Min | Op::Max | Op::Eq | Op::And | Op::Or
        )
    }

    /// How many operands it reads (`Const`, `Flag` and `Input` read none).
    pub fn operands(self) -> usize {
        match self {
            Op::Const | Op::Input | Op::Flag => 0,
            Op::Neg
            | Op::Sqrt
            | Op::SafeSqrt
            | Op::Sin
            | Op::Cos
            | Op::Exp
            | Op::Abs
            | Op::Detach
            | Op::Finite
            | Op::Not => 1,
            Op::Select => 3,
            _ => 2,
        }
    }
}

/// One instruction: its result is the program's value number `i` (its position).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instr {
    /// The operation.
    pub op: Op,
    /// First operand (a value number; the input index for [`Op::Input`]).
    pub a: u32,
    /// Second operand.
    pub b: u32,
    /// Third operand.
    pub c: u32,
    /// The constant of [`Op::Const`] and [`Op::Flag`].
    pub value: f64,
}

/// A recorded straight-line program.
#[derive(Clone, Debug, PartialEq)]
pub struct Program {
    /// Instructions, operands before their uses.
    pub instrs: Vec<Instr>,
    /// How many inputs it reads.
    pub inputs: usize,
    /// The value numbers of its outputs, in the order the recording gave them.
    pub outputs: Vec<u32>,
}

/// `f64` arithmetic of one operation on operand values (masks as 0 or 1): the constant folding
/// of the recorder and [`Program::run`] share it.
pub(crate) fn apply(op: Op, a: f64, b: f64, c: f64, value: f64) -> f64 {
    let flag = |x: bool| if x { 1.0 } else { 0.0 };
    match op {
        Op::Const | Op::Flag => value,
        Op::Input => f64::NAN,
        Op::Neg => -a,
        Op::Add => a + b,
        Op::Sub => a - b,
        Op::Mul => a * b,
        Op::Div => a / b,
        Op::Sqrt => a.sqrt(),
        Op::SafeSqrt => a.max(0.0).sqrt(),
        Op::Sin => a.sin(),
        Op::Cos => a.cos(),
        Op::Exp => a.exp(),
        Op::Abs => a.abs(),
        Op::Min => a.min(b),
        Op::Max => a.max(b),
        Op::CopySign => a.copysign(b),
        Op::Detach => a,
        Op::Select => {
            if a != 0.0 {
                b
            } else {
                c
            }
        }
        Op::Lt => flag(a < b),
        Op::Le => flag(a <= b),
        Op::Eq => flag(a == b),
        Op::Finite => flag(a.is_finite()),
        Op::And => flag(a != 0.0 && b != 0.0),
        Op::Or => flag(a != 0.0 || b != 0.0),
        Op::Not => flag(a == 0.0),
    }
}

impl Program {
    /// Runs the program in `f64` on `inputs` (masks as 0 or 1): the reference a replay is
    /// compared with.
    pub fn run(&self, inputs: &[f64]) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.instrs.len());
        for ins in &self.instrs {
            let get = |k: u32| v.get(k as usize).copied().unwrap_or(f64::NAN);
            let x = match ins.op {
                Op::Input => inputs.get(ins.a as usize).copied().unwrap_or(f64::NAN),
                op => apply(op, get(ins.a), get(ins.b), get(ins.c), ins.value),
            };
            v.push(x);
        }
        self.outputs.iter().map(|&k| v[k as usize]).collect()
    }

    /// The number of instructions of each kind that are not constants or inputs: the size of
    /// the kernel the replay adds.
    pub fn operations(&self) -> usize {
        self.instrs
            .iter()
            .filter(|i| !matches!(i.op, Op::Const | Op::Flag | Op::Input))
            .count()
    }

    /// Keeps the instructions that the outputs need, renumbered in order.
    pub(crate) fn pruned(instrs: &[Instr], inputs: usize, outputs: &[u32]) -> Program {
        let mut live = vec![false; instrs.len()];
        for &o in outputs {
            live[o as usize] = true;
        }
        for k in (0..instrs.len()).rev() {
            if live[k] {
                let ins = &instrs[k];
                for operand in [ins.a, ins.b, ins.c].iter().take(ins.op.operands()) {
                    live[*operand as usize] = true;
                }
            }
        }
        let mut number = vec![u32::MAX; instrs.len()];
        let mut kept = Vec::new();
        for (k, ins) in instrs.iter().enumerate() {
            if live[k] {
                number[k] = kept.len() as u32;
                let mut ins = *ins;
                let n = ins.op.operands();
                let renumber = |x: u32, used: bool| if used { number[x as usize] } else { x };
                ins.a = renumber(ins.a, n >= 1);
                ins.b = renumber(ins.b, n >= 2);
                ins.c = renumber(ins.c, n >= 3);
                kept.push(ins);
            }
        }
        Program {
            instrs: kept,
            inputs,
            outputs: outputs.iter().map(|&o| number[o as usize]).collect(),
        }
    }
}
