/**!

.. _bsdf-birefringent:

Bulk birefringent crystal (:monosp:`birefringent`)
--------------------------------------------------

.. pluginparameters::

 * - material
   - |string|
   - A named uniaxial crystal of the core's catalogue: calcite, crystalline quartz (quartz),
     sapphire, rutile, magnesium fluoride (mgf2), lithium niobate, beta barium borate, potassium
     dihydrogen phosphate (aliases accepted); dispersive. Each uses one cited dispersion fit
     over its range; Mitsuba samples 360-830 nm, and where a fit's data stop short (rutile:
     DeVore 1951, 430-1530 nm; lithium niobate: Zelmon et al. 1997, 400-5000 nm) the fit is
     extrapolated down to 360 nm (finite and of normal dispersion there, but without rutile's
     absorption below about 410 nm) and loading logs one warning saying so; the calculator
     applies the same rule. (Default: ``calcite``)

 * - eta_o, eta_e
   - |float|
   - Constant ordinary / extraordinary indices instead of ``material`` (give both; not together
     with ``material``), within [1e-3, 1e3] (as is every index). Spectra are not supported
     yet. Exposed only when given.
   - |exposed|

 * - kappa_o, kappa_e
   - |float|
   - Extinction coefficients added to the indices (``n + i kappa``, ``0 <= kappa <= 1e3``),
     accepted only for an isotropic material (a metal-like surface): in an absorbing
     birefringent crystal the o and e waves are not power-orthogonal, so the power of each
     refracted ray is undefined (refused at load with that reason; use
     :monosp:`thinbirefringent` for a dichroic plate). An absorbing bulk is opaque, like
     :monosp:`conductor`: what refracts into it is absorbed at the surface, so there is the
     reflection alone from outside and nothing from inside. (Default: 0)
   - |exposed|

 * - optic_axis
   - |vector|
   - The optic axis, any non-zero length, in the frame that ``optic_axis_space`` names.
     (Default: ``[1, 0, 0]``)
   - |exposed|

 * - optic_axis_space
   - |string|
   - ``"local"``: ``optic_axis`` is in the shading frame (x = dp/du, z = normal; fine for a flat
     face, e.g. a ``rectangle``); ``"world"``: in world space, converted to each hit's shading
     frame, so that every face of a crystal object (a ``cube``, a mesh) sees the same crystal.
     (Default: ``"local"``)

 * - ext_ior
   - |float| or |string|
   - Real index of the medium on the side the normal points to, a number or a Mitsuba IOR name.
     (Default: ``"air"``, 1.000277)
   - |exposed|

The surface of a bulk uniaxial crystal, like :monosp:`dielectric`: the crystal is on the side
opposite to the normal. Components: 0 the specular reflection (``DeltaReflection``), 1 the
ordinary and 2 the extraordinary refraction (``DeltaTransmission``), each ray in its own
(Poynting) direction; the extraordinary ray leaves the plane of incidence. Seen from inside, the
core returns up to 6 lobes (the reflected o and e rays and the transmitted ray, for each of the
o and e rays that can travel along ``wi``): the reflected rays are component 0 and the ray
refracted out is component 1 or 2 by its mode inside. Lobes are sampled in proportion to their
unpolarised weight. Which of o and e a ray inside the crystal is lives in its Stokes vector, so
double refraction needs a polarized variant; an isotropic material (``eta_o == eta_e``,
``kappa_o == kappa_e``) works in every variant. The physics is the core's
``bfr_crystal_lobes`` (docs/physics.md, sections 2 and 5).

.. tabs::
    .. code-tab:: xml
        :name: birefringent-calcite

        <bsdf type="birefringent">
            <string name="material" value="calcite"/>
            <vector name="optic_axis" x="0.577" y="0.577" z="0.577"/>
            <string name="optic_axis_space" value="world"/>
        </bsdf>

    .. code-tab:: python

        'type': 'birefringent',
        'material': 'calcite',
        'optic_axis': [0.577, 0.577, 0.577],
        'optic_axis_space': 'world'
*/
#include "common.h"
#include "last_valid.h"

NAMESPACE_BEGIN(mitsuba)

template <typename Float, typename Spectrum>
class Birefringent final : public BSDF<Float, Spectrum> {
public:
    MI_IMPORT_BASE(BSDF, m_flags, m_components)
    MI_IMPORT_TYPES()
    using Lobes = bfr::Lobes<Float, Spectrum>;

    /// Wavelength (nm) used in the RGB variant, which has no wavelengths: only isotropic
    /// constant indices are allowed there, so it does not matter.
    static constexpr double RgbWavelength = 550.0;

    Birefringent(const Properties &props) : Base(props) {
        m_params = bfr::parse_material(props, ClassName);
        m_ext_ior = bfr::parse_ior(props, "ext_ior", "air", ClassName);
        m_optic_axis = props.get<ScalarVector3f>("optic_axis", ScalarVector3f(1.f, 0.f, 0.f));
        std::string space = props.get<std::string>("optic_axis_space", "local");
        if (space != "local" && space != "world")
            Throw("\"optic_axis_space\" must be \"local\" (the shading frame) or \"world\", got \"%s\"", space);
        m_axis_in_world = space == "world";
        parameters_changed();
    }

    void traverse(TraversalCallback *cb) override {
        if (!m_params.named) {
            cb->put("eta_o", m_params.eta_o, ParamFlags::NonDifferentiable);
            cb->put("eta_e", m_params.eta_e, ParamFlags::NonDifferentiable);
        }
        cb->put("kappa_o", m_params.kappa_o, ParamFlags::NonDifferentiable);
        cb->put("kappa_e", m_params.kappa_e, ParamFlags::NonDifferentiable);
        cb->put("ext_ior", m_ext_ior, ParamFlags::NonDifferentiable);
        cb->put("optic_axis", m_optic_axis, ParamFlags::NonDifferentiable);
    }

    /// Applies changed parameters; a rejected update leaves the last valid state in force
    /// (bfr::update_or_restore).
    void parameters_changed(const std::vector<std::string> & /*keys*/ = {}) override {
        bfr::update_or_restore<Float, Spectrum>(this, m_valid, [this] { rebuild(); });
    }

private:
    /// Rebuilds the core material and the flags, and checks every parameter with one core query.
    void rebuild() {
        if (!is_polarized_v<Spectrum> && !m_params.isotropic())
            Throw("double refraction (eta_o != eta_e, or a named crystal: %s) needs a polarized "
                  "variant, which carries whether a ray in the crystal is ordinary or "
                  "extraordinary: use scalar_spectral_polarized (the llvm/cuda polarized "
                  "variants are not supported). In this variant only an isotropic material "
                  "(eta_o == eta_e, kappa_o == kappa_e) works.", m_params.to_string());
        m_material = bfr::make_material(m_params, ClassName);
        uint32_t aniso = m_params.isotropic() ? 0u : (uint32_t) BSDFFlags::Anisotropic;
        uint32_t sides = (uint32_t) (BSDFFlags::FrontSide | BSDFFlags::BackSide) | aniso;
        m_types[0] = BSDFFlags::DeltaReflection;
        m_types[1] = m_types[2] = BSDFFlags::DeltaTransmission;
        m_components.clear();
        // A lobe between different ray indices (a refraction; inside a birefringent crystal
        // also a reflection that converts o into e) carries the radiance factor
        // (n_wi / n_wo)^2 in its Radiance weight and not in its Importance weight:
        // non-symmetric, as Mitsuba's `dielectric` declares its refraction.
        for (size_t k = 0; k < 3; ++k) {
            bool asym = k > 0 || !m_params.isotropic();
            m_components.push_back((uint32_t) m_types[k] | sides |
                                   (asym ? (uint32_t) BSDFFlags::NonSymmetric : 0u));
        }
        m_flags = m_components[0] | m_components[1] | m_components[2];

        bfr_geometry g = geometry(m_optic_axis);
        const double wi[3] = { 0.0, 0.0, 1.0 };
        bfr_path_lobe out[BFR_CRYSTAL_LOBES];
        char message[bfr::MessageLen] = { 0 };
        int32_t rc = bfr_crystal_lobes(m_material.get(), &g, 550.0, wi, BFR_RADIANCE, out,
                                       message, sizeof(message));
        if (rc != BFR_OK)
            Throw("%s", bfr::core_error(rc, message));
    }

public:
    std::pair<BSDFSample3f, Spectrum> sample(const BSDFContext &ctx, const SurfaceInteraction3f &si,
                                             Float sample1, const Point2f & /*sample2*/,
                                             Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFSample, active);
        constexpr size_t N = BFR_CRYSTAL_LOBES;
        bfr_path_lobe lobes[Lobes::Channels * N];
        if (!active || !query(si, ctx.mode, lobes))
            return { dr::zeros<BSDFSample3f>(), dr::zeros<Spectrum>() };
        return Lobes::sample(ctx, si, sample1, lobes, N, m_types, 3);
    }

    Spectrum eval(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
                  Mask) const override {
        return dr::zeros<Spectrum>();  // delta lobes only
    }

    Float pdf(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
              Mask) const override {
        return 0.f;
    }

    std::string to_string() const override {
        std::ostringstream oss;
        oss << "Birefringent[" << std::endl
            << "  " << m_params.to_string() << "," << std::endl
            << "  ext_ior = " << m_ext_ior << "," << std::endl
            << "  optic_axis = " << m_optic_axis << " (" << (m_axis_in_world ? "world" : "local")
            << " frame)" << std::endl
            << "]";
        return oss.str();
    }

    MI_DECLARE_CLASS(Birefringent)

private:
    /// The core's geometry; `axis` in the local shading frame.
    bfr_geometry geometry(const Vector3f &axis) const {
        bfr_geometry g{};
        g.ext_ior = m_ext_ior;
        g.exit_ior = m_ext_ior;  // unused by the crystal
        for (int k = 0; k < 3; ++k)
            g.optic_axis[k] = axis[k];
        return g;
    }

    /// lobes[ch * BFR_CRYSTAL_LOBES + i]; false (after one warning) if the core refuses.
    bool query(const SurfaceInteraction3f &si, TransportMode mode, bfr_path_lobe *lobes) const {
        bfr_geometry g = geometry(m_axis_in_world ? si.to_local(m_optic_axis) : m_optic_axis);
        const double wi[3] = { si.wi.x(), si.wi.y(), si.wi.z() };
        int32_t transport = mode == TransportMode::Radiance ? BFR_RADIANCE : BFR_IMPORTANCE;
        char message[bfr::MessageLen] = { 0 };
        int32_t rc = BFR_OK;
        if constexpr (is_spectral_v<Spectrum>) {
            for (size_t ch = 0; ch < Lobes::Channels && rc == BFR_OK; ++ch)
                rc = bfr_crystal_lobes(m_material.get(), &g, (double) si.wavelengths[ch], wi,
                                       transport, &lobes[ch * BFR_CRYSTAL_LOBES], message,
                                       sizeof(message));
        } else {  // RGB: isotropic constant indices only (checked at load), one query for all
            rc = bfr_crystal_lobes(m_material.get(), &g, RgbWavelength, wi, transport, lobes,
                                   message, sizeof(message));
            for (size_t ch = 1; ch < Lobes::Channels; ++ch)
                std::copy(lobes, lobes + BFR_CRYSTAL_LOBES, &lobes[ch * BFR_CRYSTAL_LOBES]);
        }
        if (rc != BFR_OK) {
            if (!m_warned.exchange(true))
                Log(Warn, "%s (returning no light; further errors are not reported)",
                    bfr::core_error(rc, message));
            return false;
        }
        return true;
    }

    bfr::MaterialParams m_params;
    bfr::MaterialPtr m_material;
    double m_ext_ior;
    ScalarVector3f m_optic_axis;
    bool m_axis_in_world = false;
    BSDFFlags m_types[3];
    mutable std::atomic<bool> m_warned { false };
    std::unique_ptr<bfr::Snapshot<Float, Spectrum>> m_valid;  ///< last valid state

    MI_TRAVERSE_CB(Base)
};

NAMESPACE_BEGIN(bfr)
void register_birefringent() { register_plugin<Birefringent>("birefringent"); }
NAMESPACE_END(bfr)

NAMESPACE_END(mitsuba)
