/* Gradients in the JIT (llvm_ad) variants: which inputs of a query carry gradients in Dr.Jit's
 * AD graph, asked of the core as derivative columns, and how the columns are attached.
 *
 * The core computes, per lane, the derivatives of the sampled direction and of the sample
 * weight (in Mitsuba's implicit Stokes frames) with respect to each input that carries
 * gradients, holding the lobe choice and its probability fixed (attached sampling; see
 * src/render/tangents.rs). The shim attaches them as the gradient of `value + Σ_k J_k δ_k`,
 * with `δ_k = x_k - detach(x_k)` (zero, with the gradient of the input `x_k`), on the value
 * itself (`dr::replace_grad`), so that forward and reverse mode both see `dy/dx_k = J_k`. An
 * input without gradients is not asked for and costs nothing; a query without any is the plain
 * query.
 */
#pragma once

#include <mitsuba/core/vector.h>
#include <drjit/autodiff.h>

#include <vector>

#include "rust/cxx.h"
#include "birefringent/src/ffi/mod.rs.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// The inputs of one query that carry gradients: the core's request and their variations.
template <typename Float> class TangentInputs {
public:
    using Vector3f = Vector<Float, 3>;

    /// Asks for the derivative with respect to `x` if it carries gradients; the core's input
    /// is `scale` times `x` (e.g. a thickness in nm from micrometres).
    void add(bfr::Tangent t, const Float &x, double scale = 1.0) {
        if constexpr (dr::is_diff_v<Float>) {
            if (dr::grad_enabled(x)) {
                m_request.push_back(t);
                m_deltas.push_back(Float(scale) * (x - dr::detach(x)));
            }
        } else {
            (void) t, (void) x, (void) scale;
        }
    }

    /// The same for a vector input (three columns, x, y, z).
    void add(bfr::Tangent t, const Vector3f &v) {
        if constexpr (dr::is_diff_v<Float>) {
            if (dr::grad_enabled(v)) {
                m_request.push_back(t);
                for (size_t j = 0; j < 3; ++j)
                    m_deltas.push_back(v[j] - dr::detach(v[j]));
            }
        } else {
            (void) t, (void) v;
        }
    }

    bool empty() const { return m_request.empty(); }

    /// Derivative columns (a vector input counts three).
    size_t columns() const { return m_deltas.size(); }

    /// The core's request.
    rust::Slice<const bfr::Tangent> request() const { return { m_request.data(), m_request.size() }; }

    /// `value` with the gradient of `value + Σ_k column(k) δ_k` (see the file comment) over
    /// the columns with `used(k)`. `replace_grad` keeps the primal computation the plain value
    /// (the sum is never evaluated: it only carries the graph's edges, weighted by the columns).
    template <typename Column, typename Used>
    Float attach(const Float &value, Column &&column, Used &&used) const {
        if constexpr (dr::is_diff_v<Float>) {
            Float y = value;
            bool any = false;
            for (size_t k = 0; k < m_deltas.size(); ++k)
                if (used(k)) {
                    y = dr::fmadd(column(k), m_deltas[k], y);
                    any = true;
                }
            return any ? dr::replace_grad(value, y) : value;
        } else {
            (void) column, (void) used;
            return value;
        }
    }

private:
    std::vector<bfr::Tangent> m_request;
    std::vector<Float> m_deltas;
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
