/* The scalar parameters both plugins expose as differentiable in the JIT variants: `eta_o`,
 * `eta_e` (constant indices), `kappa_o`, `kappa_e` and `optic_axis`. (`thickness`,
 * `birefringence` and `axis_angle` are textures, differentiable through their own parameters.)
 *
 * The core reads these values as doubles (MaterialParams, the axis). In the scalar variants
 * `mi.traverse` exposes the doubles themselves, not differentiable (there is no AD). In the JIT
 * variants it exposes a Dr.Jit handle of each (a Float, a Vector3f), flagged differentiable, so
 * that `dr.enable_grad(params[...])` and optimisers work on them; the query attaches the core's
 * derivatives to the handles (tangents.h). An update that changes a handle's value sets the
 * double to it; a handle left as it was keeps the double exactly as given (a scene's 1.6 stays
 * the double 1.6, not the float nearest to it, so the JIT variants answer as the scalar ones).
 */
#pragma once

#include <mitsuba/core/object.h>
#include <mitsuba/core/vector.h>
#include <drjit/autodiff.h>

#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "params.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// The flags of a texture parameter: differentiable (through the texture's own values) in the
/// JIT variants, not in the scalar ones.
template <typename Float> constexpr ParamFlags texture_flags() {
    return dr::is_diff_v<Float> ? ParamFlags::Differentiable : ParamFlags::NonDifferentiable;
}

template <typename Float> class Differentiable {
public:
    static constexpr bool Jit = dr::is_jit_v<Float>;
    using Vector3f = Vector<Float, 3>;
    using ScalarVector3f = Vector<dr::scalar_t<Float>, 3>;

    /// The values the core uses (the last valid ones).
    MaterialParams material;
    ScalarVector3f axis;

    /// Sets the values and the handles to them.
    void set(const MaterialParams &m, const ScalarVector3f &a) {
        material = m;
        axis = a;
        if constexpr (Jit) {
            m_eta_o = Float((float) m.eta_o);
            m_eta_e = Float((float) m.eta_e);
            m_kappa_o = Float((float) m.kappa_o);
            m_kappa_e = Float((float) m.kappa_e);
            m_axis = Vector3f(a);
            // Held in memory, not literals: a program that reads them as inputs (when they
            // carry derivatives) then runs one kernel whatever their values.
            dr::make_opaque(m_eta_o, m_eta_e, m_kappa_o, m_kappa_e, m_axis);
        }
        commit(m, a);
    }

    /// Exposes the parameters (eta_o and eta_e only for constant indices): the handles,
    /// differentiable, in the JIT variants; the values, not differentiable, in the scalar ones.
    void traverse(TraversalCallback *cb) {
        if constexpr (Jit) {
            if (!material.named) {
                cb->put("eta_o", m_eta_o, ParamFlags::Differentiable);
                cb->put("eta_e", m_eta_e, ParamFlags::Differentiable);
            }
            cb->put("kappa_o", m_kappa_o, ParamFlags::Differentiable);
            cb->put("kappa_e", m_kappa_e, ParamFlags::Differentiable);
            cb->put("optic_axis", m_axis, ParamFlags::Differentiable);
        } else {
            if (!material.named) {
                cb->put("eta_o", material.eta_o, ParamFlags::NonDifferentiable);
                cb->put("eta_e", material.eta_e, ParamFlags::NonDifferentiable);
            }
            cb->put("kappa_o", material.kappa_o, ParamFlags::NonDifferentiable);
            cb->put("kappa_e", material.kappa_e, ParamFlags::NonDifferentiable);
            cb->put("optic_axis", axis, ParamFlags::NonDifferentiable);
        }
    }

    /// The values after an update: those of the handles it changed, the others as they were.
    /// Not yet the plugin's: `commit` them once they are valid.
    std::pair<MaterialParams, ScalarVector3f> updated() const {
        MaterialParams m = material;
        ScalarVector3f a = axis;
        if constexpr (Jit) {
            pull(m_eta_o, m_seen[0], m.eta_o);
            pull(m_eta_e, m_seen[1], m.eta_e);
            pull(m_kappa_o, m_seen[2], m.kappa_o);
            pull(m_kappa_e, m_seen[3], m.kappa_e);
            ScalarVector3f h(host(m_axis.x()), host(m_axis.y()), host(m_axis.z()));
            if (!same(h, m_seen_axis))
                a = h;
        }
        return { m, a };
    }

    /// Makes `m`, `a` the values, and the handles' present values the reference the next
    /// update is compared with.
    void commit(const MaterialParams &m, const ScalarVector3f &a) {
        material = m;
        axis = a;
        if constexpr (Jit) {
            m_seen = { host(m_eta_o), host(m_eta_e), host(m_kappa_o), host(m_kappa_e) };
            m_seen_axis = ScalarVector3f(host(m_axis.x()), host(m_axis.y()), host(m_axis.z()));
        }
    }

    /// The handles (with their gradients) in the JIT variants, the values in the scalar ones.
    Float eta_o() const { return handle(m_eta_o, material.eta_o); }
    Float eta_e() const { return handle(m_eta_e, material.eta_e); }
    Float kappa_o() const { return handle(m_kappa_o, material.kappa_o); }
    Float kappa_e() const { return handle(m_kappa_e, material.kappa_e); }
    Vector3f optic_axis() const {
        if constexpr (Jit)
            return m_axis;
        else
            return Vector3f(axis);
    }

    /// Which parameters a recorded program reads per lane instead of folding them in as
    /// constants: those that carry gradients (a named crystal's indices are its dispersion fit,
    /// never inputs). The one decision for the programs of every plugin.
    struct Inputs {
        bool axis, indices, kappas;
    };
    Inputs program_inputs() const {
        return { dr::grad_enabled(optic_axis()),
                 !material.named && dr::grad_enabled(eta_o(), eta_e()),
                 dr::grad_enabled(kappa_o(), kappa_e()) };
    }

private:
    static float host(const Float &x) {
        if constexpr (Jit)
            return dr::width(x) > 0 ? (float) dr::slice(x, 0) : NAN;
        else
            return (float) x;
    }

    /// Bitwise equality (a NaN set by an update compares equal to itself).
    static bool same(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
    static bool same(const ScalarVector3f &a, const ScalarVector3f &b) {
        return same(a.x(), b.x()) && same(a.y(), b.y()) && same(a.z(), b.z());
    }

    static void pull(const Float &h, float seen, double &value) {
        float now = host(h);
        if (!same(now, seen))
            value = (double) now;
    }

    static Float handle(const Float &h, double value) {
        if constexpr (Jit)
            return h;
        else
            return Float(value);
    }

    /// The handles (unused in the scalar variants).
    Float m_eta_o{}, m_eta_e{}, m_kappa_o{}, m_kappa_e{};
    Vector3f m_axis{};
    std::array<float, 4> m_seen{};
    ScalarVector3f m_seen_axis{};
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
