/**!

.. _bsdf-thinbirefringent:

Birefringent plate (:monosp:`thinbirefringent`)
-----------------------------------------------

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
   - Extinction coefficients added to the indices (``n + i kappa``, ``0 <= kappa <= 1e3``;
     dichroism when they differ). (Default: 0)
   - |exposed|

 * - optic_axis
   - |vector|
   - The optic axis in the local shading frame (x = dp/du, z = normal), any non-zero length; at
     each point rotated about the normal by ``axis_angle``. (Default: ``[1, 0, 0]``)
   - |exposed|

 * - ext_ior
   - |float| or |string|
   - Real index of the medium on the side the normal points to, a number or a Mitsuba IOR name.
     (Default: ``"air"``, 1.000277)
   - |exposed|

 * - exit_ior
   - |float| or |string|
   - Real index of the medium below the plate. (Default: ``ext_ior``)
   - |exposed|

 * - thickness
   - |float| or |texture|
   - Thickness in micrometres (times ``thickness_scale``), within [0, 1e6] (1 m); where a texture
     gives a value outside, that point returns no light (one warning). (Default: 1)
   - |exposed|

 * - thickness_scale
   - |float|
   - Multiplies ``thickness`` (e.g. a bitmap in [0, 1] times a maximum thickness). (Default: 1)
   - |exposed|

 * - birefringence
   - |float| or |texture|
   - Added to Re ``eta_e`` (times ``birefringence_scale``): the stress-induced birefringence
     ``C (sigma_1 - sigma_2)`` of a photoelastic plate. Exposed only when given. (Default: none)
   - |exposed|

 * - birefringence_scale
   - |float|
   - Multiplies ``birefringence``. (Default: 1)
   - |exposed|

 * - axis_angle
   - |float| or |texture|
   - Degrees; rotates ``optic_axis`` about the normal, counter-clockwise seen from the exterior
     (from x towards y): the principal stress direction of a photoelastic plate. Exposed only
     when given. (Default: 0)
   - |exposed|

 * - filter_bandwidth
   - |float|
   - Spectral variants: full width at half maximum (nm) of the Gaussian band around each sampled
     wavelength over which the plate is integrated in closed form; 0 (or below 1e-12 of the
     wavelength) is the exact plate at the wavelength (the default: a band never paid at equal
     error in the scene benchmark); at most a quarter of the wavelength. (Default: 0)
   - |exposed|

 * - absorbing_exit
   - |bool|
   - The medium below the plate absorbs all light that enters it (a film on a black substrate;
     ``exit_ior`` still sets the bottom interface): only the reflection lobe, on the front side,
     remains; light arriving from below is not reflected (it cannot reach the plate). Removes the
     noise of choosing between reflection and transmission when only the reflection is seen.
     (Default: |false|)

A plane-parallel uniaxial plate on a surface, like :monosp:`thindielectric`: the plate has no
geometric thickness in the scene. Component 0 is the specular reflection (``DeltaReflection``),
component 1 the transmission, which leaves in the direction Snell's law gives between
``ext_ior`` and ``exit_ior``: straight through, with the flag ``Null`` and
``eval_null_transmission`` (so that volpath reaches lights behind it), when
``exit_ior == ext_ior``; ``DeltaTransmission`` otherwise. Both carry the plate's full Mueller
matrix with every internal reflection, from either side and in both transport modes (the
physics is the core's ``bfr_plate_lobes``, ``bfr_plate_lobes_n`` and ``bfr_plate_lobes_rgb``;
see docs/physics.md, sections 3 and 4). Lobes are sampled in proportion to their unpolarised
weight. With ``absorbing_exit`` only component 0 remains, on the front side. Textures are
evaluated with ``eval_1`` at the hit point (use ``raw="true"`` for data bitmaps).

.. tabs::
    .. code-tab:: xml
        :name: thinbirefringent-photoelastic

        <bsdf type="thinbirefringent">
            <float name="eta_o" value="1.5"/>
            <float name="eta_e" value="1.5"/>
            <float name="thickness" value="3000"/>
            <texture type="bitmap" name="birefringence">
                <string name="filename" value="dsigma.exr"/>
                <boolean name="raw" value="true"/>
            </texture>
            <float name="birefringence_scale" value="1e-4"/>
        </bsdf>

    .. code-tab:: python

        'type': 'thinbirefringent',
        'material': 'quartz',
        'optic_axis': [1, 1, 0],
        'thickness': 30.0
*/
#include "common.h"
#include "last_valid.h"
#include "scalar_texture.h"
#include "signed_rgb.h"

NAMESPACE_BEGIN(mitsuba)

template <typename Float, typename Spectrum>
class ThinBirefringent final : public BSDF<Float, Spectrum> {
public:
    MI_IMPORT_BASE(BSDF, m_flags, m_components)
    MI_IMPORT_TYPES(Texture)
    using Lobes = bfr::Lobes<Float, Spectrum>;

    /// Default `filter_bandwidth` (nm, FWHM) of the spectral variants.
    static constexpr double DefaultFilterBandwidth = 0.0;

    ThinBirefringent(const Properties &props) : Base(props) {
        m_params = bfr::parse_material(props, ClassName);
        m_ext_ior = bfr::parse_ior(props, "ext_ior", "air", ClassName);
        m_exit_ior = props.has_property("exit_ior")
                         ? bfr::parse_ior(props, "exit_ior", "air", ClassName)
                         : m_ext_ior;
        m_optic_axis = props.get<ScalarVector3f>("optic_axis", ScalarVector3f(1.f, 0.f, 0.f));
        m_thickness = bfr::scalar_texture<Float, Spectrum>(props, "thickness", 1.0,
                                                           "micrometres", ClassName);
        m_thickness_scale = props.get<double>("thickness_scale", 1.0);
        if (props.has_property("birefringence"))
            m_birefringence = bfr::scalar_texture<Float, Spectrum>(
                props, "birefringence", 0.0, "added to eta_e", ClassName);
        m_birefringence_scale = props.get<double>("birefringence_scale", 1.0);
        if (props.has_property("axis_angle"))
            m_axis_angle = bfr::scalar_texture<Float, Spectrum>(props, "axis_angle", 0.0,
                                                                "degrees", ClassName);
        m_filter_bandwidth = props.get<double>("filter_bandwidth", DefaultFilterBandwidth);
        m_absorbing_exit = props.get<bool>("absorbing_exit", false);
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
        cb->put("exit_ior", m_exit_ior, ParamFlags::NonDifferentiable);
        cb->put("optic_axis", m_optic_axis, ParamFlags::NonDifferentiable);
        cb->put("thickness", m_thickness, ParamFlags::NonDifferentiable);
        cb->put("thickness_scale", m_thickness_scale, ParamFlags::NonDifferentiable);
        if (m_birefringence)
            cb->put("birefringence", m_birefringence, ParamFlags::NonDifferentiable);
        cb->put("birefringence_scale", m_birefringence_scale, ParamFlags::NonDifferentiable);
        if (m_axis_angle)
            cb->put("axis_angle", m_axis_angle, ParamFlags::NonDifferentiable);
        cb->put("filter_bandwidth", m_filter_bandwidth, ParamFlags::NonDifferentiable);
    }

    /// Applies changed parameters; a rejected update leaves the last valid state in force
    /// (bfr::update_or_restore).
    void parameters_changed(const std::vector<std::string> & /*keys*/ = {}) override {
        bfr::update_or_restore<Float, Spectrum>(this, m_valid, [this] { rebuild(); });
    }

private:
    /// Rebuilds the core material and the flags, and checks every parameter with one core query
    /// (textures at their mean), so that invalid input fails here, with the core's message.
    void rebuild() {
        m_material = bfr::make_material(m_params, ClassName);
        m_null = m_exit_ior == m_ext_ior && !m_absorbing_exit;
        uint32_t aniso = (m_params.isotropic() && !m_birefringence) ? 0u : (uint32_t) BSDFFlags::Anisotropic;
        uint32_t sides = (uint32_t) (BSDFFlags::FrontSide | BSDFFlags::BackSide) | aniso;
        m_types[0] = BSDFFlags::DeltaReflection;
        m_types[1] = m_null ? BSDFFlags::Null : BSDFFlags::DeltaTransmission;
        m_components.clear();
        if (m_absorbing_exit) {
            m_components.push_back((uint32_t) m_types[0] | (uint32_t) BSDFFlags::FrontSide | aniso);
            m_flags = m_components[0];
        } else {
            // Between different indices the transmission's Radiance weight carries the radiance
            // factor (n_wi / n_wo)^2 and its Importance weight does not (see birefringent.cpp).
            uint32_t asym = m_exit_ior != m_ext_ior ? (uint32_t) BSDFFlags::NonSymmetric : 0u;
            m_components.push_back((uint32_t) m_types[0] | sides);
            m_components.push_back((uint32_t) m_types[1] | sides | asym);
            m_flags = m_components[0] | m_components[1];
        }

        bfr_geometry g;
        std::string error;
        if (!geometry(m_thickness->mean(), m_birefringence ? m_birefringence->mean() : 0.0,
                      m_axis_angle ? m_axis_angle->mean() : 0.0, g, error))
            Throw("%s", error);
        const double wi[3] = { 0.0, 0.0, 1.0 };
        bfr_path_lobe out[2];
        char message[bfr::MessageLen] = { 0 };
        int32_t rc = bfr_plate_lobes(m_material.get(), &g, 550.0, m_filter_bandwidth, wi,
                                     BFR_RADIANCE, BFR_WANT_REFLECTION | BFR_WANT_TRANSMISSION,
                                     out, message, sizeof(message));
        if (rc != BFR_OK)
            Throw("%s", bfr::core_error(rc, message));
    }

public:
    std::pair<BSDFSample3f, Spectrum> sample(const BSDFContext &ctx, const SurfaceInteraction3f &si,
                                             Float sample1, const Point2f & /*sample2*/,
                                             Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFSample, active);
        int32_t want = (ctx.is_enabled(m_types[0], 0) ? BFR_WANT_REFLECTION : 0) |
                       (ctx.is_enabled(m_types[1], 1) ? BFR_WANT_TRANSMISSION : 0);
        bfr_path_lobe lobes[Lobes::Channels * 2];
        if (!active || !want || !query(si, ctx.mode, want, lobes))
            return { dr::zeros<BSDFSample3f>(), dr::zeros<Spectrum>() };
        return Lobes::sample(ctx, si, sample1, lobes, 2, m_types, 2);
    }

    Spectrum eval(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
                  Mask) const override {
        return dr::zeros<Spectrum>();  // delta lobes only
    }

    Float pdf(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
              Mask) const override {
        return 0.f;
    }

    /// The transmission matrix for light travelling along si.wi (shadow rays of volpath).
    Spectrum eval_null_transmission(const SurfaceInteraction3f &si, Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFEvaluate, active);
        bfr_path_lobe lobes[Lobes::Channels * 2];
        if (!m_null || !active ||
            !query(si, TransportMode::Radiance, BFR_WANT_TRANSMISSION, lobes))
            return dr::zeros<Spectrum>();
        int pick[Lobes::Channels];
        for (size_t ch = 0; ch < Lobes::Channels; ++ch)
            pick[ch] = lobes[ch * 2 + 1].exists ? 1 : -1;
        return Lobes::spectrum(lobes, 2, pick, 1.0, si.wi, -si.wi, true);
    }

    std::string to_string() const override {
        std::ostringstream oss;
        oss << "ThinBirefringent[" << std::endl
            << "  " << m_params.to_string() << "," << std::endl
            << "  ext_ior = " << m_ext_ior << ", exit_ior = " << m_exit_ior << "," << std::endl
            << "  optic_axis = " << m_optic_axis << "," << std::endl
            << "  thickness = " << string::indent(m_thickness) << " (um)," << std::endl
            << "  thickness_scale = " << m_thickness_scale << "," << std::endl;
        if (m_birefringence)
            oss << "  birefringence = " << string::indent(m_birefringence) << "," << std::endl
                << "  birefringence_scale = " << m_birefringence_scale << "," << std::endl;
        if (m_axis_angle)
            oss << "  axis_angle = " << string::indent(m_axis_angle) << " (degrees)," << std::endl;
        oss << "  filter_bandwidth = " << m_filter_bandwidth << " (nm FWHM, spectral variants)," << std::endl
            << "  absorbing_exit = " << (m_absorbing_exit ? "true" : "false") << std::endl
            << "]";
        return oss.str();
    }

    MI_DECLARE_CLASS(ThinBirefringent)

private:
    /// Geometry from the texture values: thickness (um, before scaling), birefringence (before
    /// scaling), axis angle (degrees). False, with the message in `error`, if the angle is not
    /// a finite number: the core sees only the rotated axis and would name `optic_axis`.
    bool geometry(double thickness_um, double birefringence, double angle_deg, bfr_geometry &g,
                  std::string &error) const {
        if (!std::isfinite(angle_deg)) {
            error = "axis_angle: must be a finite number (degrees), got " + std::to_string(angle_deg);
            return false;
        }
        g = bfr_geometry{};
        g.ext_ior = m_ext_ior;
        g.exit_ior = m_exit_ior;
        const double axis[3] = { m_optic_axis.x(), m_optic_axis.y(), m_optic_axis.z() };
        bfr::rotate_about_normal(axis, angle_deg, g.optic_axis);
        g.thickness_nm = 1000.0 * m_thickness_scale * thickness_um;
        g.birefringence = m_birefringence_scale * birefringence;
        return true;
    }

    /// Core query at si: lobes[ch * 2 + i] for channel ch, lobe i (0 R, 1 T). False (after one
    /// warning) if the core refuses, e.g. a texture gives a negative thickness.
    bool query(const SurfaceInteraction3f &si, TransportMode mode, int32_t want,
               bfr_path_lobe *lobes) const {
        auto refuse = [this](const std::string &error) {
            if (!m_warned.exchange(true))
                Log(Warn, "%s (returning no light; further errors are not reported)", error);
            return false;
        };
        bfr_geometry g;
        std::string error;
        if (!geometry(m_thickness->eval_1(si),
                      m_birefringence ? (double) m_birefringence->eval_1(si) : 0.0,
                      m_axis_angle ? (double) m_axis_angle->eval_1(si) : 0.0, g, error))
            return refuse(error);
        const double wi[3] = { si.wi.x(), si.wi.y(), si.wi.z() };
        int32_t transport = mode == TransportMode::Radiance ? BFR_RADIANCE : BFR_IMPORTANCE;
        int32_t flags = want | (is_polarized_v<Spectrum> ? 0 : BFR_INTENSITY_ONLY) |
                        (m_absorbing_exit ? BFR_ABSORBING_EXIT : 0);
        char message[bfr::MessageLen] = { 0 };
        int32_t rc = BFR_OK;
        if constexpr (is_rgb_v<Spectrum>) {
            bfr_path_lobe rgb[3][2];
            rc = bfr_plate_lobes_rgb(m_material.get(), &g, wi, transport, flags, rgb, message,
                                     sizeof(message));
            for (size_t ch = 0; ch < 3; ++ch)
                for (size_t i = 0; i < 2; ++i)
                    lobes[ch * 2 + i] = rgb[ch][i];
        } else {
            static_assert(Lobes::Channels <= BFR_MAX_BANDS, "one core query per path");
            double waves[Lobes::Channels];
            for (size_t ch = 0; ch < Lobes::Channels; ++ch)
                waves[ch] = (double) si.wavelengths[ch];
            rc = bfr_plate_lobes_n(m_material.get(), &g, waves, Lobes::Channels,
                                   m_filter_bandwidth, wi, transport, flags, lobes, message,
                                   sizeof(message));
        }
        if (rc != BFR_OK)
            return refuse(bfr::core_error(rc, message));
        return true;
    }

    bfr::MaterialParams m_params;
    bfr::MaterialPtr m_material;
    double m_ext_ior, m_exit_ior;
    ScalarVector3f m_optic_axis;
    ref<Texture> m_thickness, m_birefringence, m_axis_angle;
    double m_thickness_scale, m_birefringence_scale, m_filter_bandwidth;
    bool m_null = true, m_absorbing_exit = false;
    BSDFFlags m_types[2];
    mutable std::atomic<bool> m_warned { false };
    bfr::SignedRgbGuard m_signed_rgb { is_rgb_v<Spectrum> };  ///< see signed_rgb.h
    std::unique_ptr<bfr::Snapshot<Float, Spectrum>> m_valid;  ///< last valid state

    MI_TRAVERSE_CB(Base, m_thickness, m_birefringence, m_axis_angle)
};

NAMESPACE_BEGIN(bfr)
void register_thinbirefringent() { register_plugin<ThinBirefringent>("thinbirefringent"); }
NAMESPACE_END(bfr)

NAMESPACE_END(mitsuba)
