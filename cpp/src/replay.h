/* Replaying a program the core recorded (src/record: the per-wavelength physics written once in
 * Rust, recorded as straight-line instructions) with Dr.Jit arrays, in the JIT variants.
 *
 * Each instruction becomes the Dr.Jit operation of the same name on the values of its operands,
 * so Mitsuba traces the program into its kernels like its own plugins' code: inside symbolic
 * loops and calls, on LLVM or CUDA, with Dr.Jit's derivatives flowing from the inputs (si.wi,
 * texture values, parameters) to the outputs, and unused outputs never computed. The shim
 * writes no physics of its own: this file only maps operation codes to operations.
 */
#pragma once

#include <drjit/math.h>
#include <drjit/autodiff.h>

#include <vector>

#include "rust/cxx.h"
#include "birefringent/src/ffi/mod.rs.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/** The values of a program run on the double-precision counterparts `Value` of the variant's
 * Dr.Jit floats `Float` (inputs and outputs are `Float`s). Double precision inside the kernel:
 * the phases of thick layers reach 2e4 rad (1 mm at 400 nm), and near grazing incidence the
 * normal components cancel (1 - sin^2); in single precision a replayed plate differed from the
 * core by up to 2e-1 (1 mm) and 3e-3 (89.8 degrees) in a Mueller entry, in double by 2e-6
 * (tests/python/test_jit_recorded.py), at the same render time on the CPU (docs/architecture.md). */
template <typename Float> class Replay {
public:
    using Value = dr::float64_array_t<Float>;
    using Mask = dr::mask_t<Value>;
    using Scalar = dr::scalar_t<Value>;

    /// Runs `program` on `inputs` (one array per program input, in its input order).
    Replay(const bfr::Program &program, const std::vector<Float> &inputs) {
        std::vector<Value> wide(inputs.begin(), inputs.end());
        broadcast_differentiable(wide);
        rust::Slice<const bfr::Instr> code = program.instructions();
        m_number.resize(code.size());
        m_mask.resize(code.size());
        for (size_t i = 0; i < code.size(); ++i)
            step(code[i], i, wide);
        m_outputs = program.outputs();
    }

    /// Output `k` (a number), in the variant's precision.
    Float number(size_t k) const { return Float(m_number[m_outputs[k]]); }

    /// Output `k` (a mask).
    const Mask &mask(size_t k) const { return m_mask[m_outputs[k]]; }

private:
    /** A parameter (one value for every lane) that carries gradients, broadcast to the lanes
     * once. Used as it is, each instruction reading it would be an edge of its own from one
     * value to many, and Dr.Jit's reverse mode reduces the gradient of each such edge in a
     * kernel of its own (measured: 48 reductions, each a kernel compiled anew, for one plate
     * parameter); broadcast here, the gradient is reduced once. */
    static void broadcast_differentiable(std::vector<Value> &inputs) {
        if constexpr (dr::is_diff_v<Value>) {
            size_t width = 1;
            for (const Value &v : inputs)
                width = std::max(width, dr::width(v));
            for (Value &v : inputs)
                if (width > 1 && dr::width(v) == 1 && dr::grad_enabled(v))
                    v = v * dr::opaque<Value>(1.0, width);
        }
    }

    void step(const bfr::Instr &c, size_t i, const std::vector<Value> &inputs) {
        using Op = bfr::Op;
        const auto &n = m_number;
        const auto &m = m_mask;
        Value &out = m_number[i];
        Mask &flag = m_mask[i];
        switch (c.op) {
            case Op::Const: out = Value((Scalar) c.value); break;
            case Op::Input: out = inputs.at(c.a); break;
            case Op::Neg: out = -n[c.a]; break;
            case Op::Add: out = n[c.a] + n[c.b]; break;
            case Op::Sub: out = n[c.a] - n[c.b]; break;
            case Op::Mul: out = n[c.a] * n[c.b]; break;
            case Op::Div: out = n[c.a] / n[c.b]; break;
            case Op::Sqrt: out = dr::sqrt(n[c.a]); break;
            case Op::SafeSqrt: out = dr::safe_sqrt(n[c.a]); break;
            case Op::Sin: out = dr::sin(n[c.a]); break;
            case Op::Cos: out = dr::cos(n[c.a]); break;
            case Op::Exp: out = dr::exp(n[c.a]); break;
            case Op::Abs: out = dr::abs(n[c.a]); break;
            case Op::Min: out = dr::minimum(n[c.a], n[c.b]); break;
            case Op::Max: out = dr::maximum(n[c.a], n[c.b]); break;
            case Op::CopySign: out = dr::copysign(n[c.a], n[c.b]); break;
            case Op::Detach: out = dr::detach(n[c.a]); break;
            case Op::Select: out = dr::select(m[c.a], n[c.b], n[c.c]); break;
            case Op::Lt: flag = n[c.a] < n[c.b]; break;
            case Op::Le: flag = n[c.a] <= n[c.b]; break;
            case Op::Eq: flag = n[c.a] == n[c.b]; break;
            case Op::Finite: flag = dr::isfinite(n[c.a]); break;
            case Op::And: flag = m[c.a] && m[c.b]; break;
            case Op::Or: flag = m[c.a] || m[c.b]; break;
            case Op::Not: flag = !m[c.a]; break;
            case Op::Flag: flag = Mask(c.value != 0.0); break;
            default:
                throw std::runtime_error("a recorded program holds an unknown operation (the "
                                         "plugin library and the core are out of step)");
        }
    }

    std::vector<Value> m_number;
    std::vector<Mask> m_mask;
    rust::Slice<const uint32_t> m_outputs;
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
