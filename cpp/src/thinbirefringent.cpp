/**!

.. _bsdf-thinbirefringent:

Birefringent plate (:monosp:`thinbirefringent`)
-----------------------------------------------

.. pluginparameters::

 * - material
   - |string|
   - A named uniaxial crystal of the core's catalogue: ``calcite``, ``quartz``, ``sapphire``,
     ``rutile``, ``mgf2``, ``linbo3``, ``bbo``, ``kdp`` (the names the calculator uses too; the
     full names, e.g. "crystalline quartz", "lithium niobate", and any case are accepted);
     dispersive. Each uses one cited dispersion fit over its range; Mitsuba samples 360-830 nm,
     and where a fit's data stop short (rutile: DeVore 1951, 430-1530 nm; linbo3: Zelmon et al.
     1997, 400-5000 nm) the fit is extrapolated down to 360 nm (finite and of normal dispersion
     there, but without rutile's absorption below about 410 nm) and loading logs one warning
     saying so; the calculator applies the same rule. (Default: ``calcite``, said in a warning
     at load; a plate given ``birefringence`` alone is a glass instead, see there)

 * - eta_o, eta_e
   - |float|
   - Constant ordinary / extraordinary indices instead of ``material`` (give both, equal for
     an isotropic glass; not together with ``material``), within [1e-3, 1e3] (as is every
     index). Floats only: an index that varies with wavelength is a ``material``. Exposed only
     when given (or when a plate's glass default stands for them).
   - |exposed|, |differentiable|

 * - kappa_o, kappa_e
   - |float|
   - Extinction coefficients added to the indices (``n + i kappa``, ``0 <= kappa <= 1e3``;
     dichroism when they differ). (Default: 0)
   - |exposed|, |differentiable|

 * - optic_axis
   - |vector|
   - The optic axis in the local shading frame (x = dp/du, z = normal), any non-zero length; at
     each point rotated about the normal by ``axis_angle``. (Default: ``[1, 0, 0]``, said in a
     warning at load for a birefringent plate given neither this nor ``axis_angle``: between
     polarisers along x or y it changes nothing)
   - |exposed|, |differentiable|

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
   - Thickness in micrometres, um (times ``thickness_scale``): a 3 mm plate is 3000. Within
     [0, 1e6] um (1 m); where a texture gives a value outside, that point returns no light (one
     warning). A plate thinner than 0.01 um (a thickness in metres would give it), or a
     birefringent plate whose retardance is below 1 nm (a photoelastic plate's millimetres given
     as micrometres) loads with a warning. (Default: 1 um, said in a warning at load)
   - |exposed|, |differentiable|

 * - thickness_scale
   - |float|
   - Multiplies ``thickness`` (e.g. a bitmap in [0, 1] times a maximum thickness). (Default: 1)
   - |exposed|

 * - birefringence
   - |float| or |texture|
   - Added to Re ``eta_e`` (times ``birefringence_scale``): the stress-induced birefringence
     ``C (sigma_1 - sigma_2)`` of a photoelastic plate. Given without ``material``, ``eta_o`` and
     ``eta_e``, the plate is an isotropic glass of index 1.5046 (Mitsuba's ``bk7``, which is
     also :monosp:`thindielectric`'s default) made birefringent by this alone, and loading says
     so in a warning; give ``eta_o`` = ``eta_e`` = your glass's index to choose it. Exposed only
     when given. (Default: none)
   - |exposed|, |differentiable|

 * - birefringence_scale
   - |float|
   - Multiplies ``birefringence``. (Default: 1)
   - |exposed|

 * - axis_angle
   - |float| or |texture|
   - Degrees; rotates ``optic_axis`` about the normal, counter-clockwise seen from the exterior
     (from x towards y): the principal stress direction of a photoelastic plate. A uniform value
     that is a round angle in radians (0.785 = pi/4, 1.571 = pi/2, ...) loads with a warning.
     Exposed only when given. (Default: 0)
   - |exposed|, |differentiable|

 * - filter_bandwidth
   - |float|
   - Spectral variants: full width at half maximum (nm) of the Gaussian band around each sampled
     wavelength over which the plate is integrated in closed form; 0 (or below 1e-12 of the
     wavelength) is the exact plate at the wavelength (the default: a band never paid at equal
     error in the scene benchmark); at most a quarter of the wavelength. Gradients (llvm_ad
     variants) need 0: the band's closed form has no derivatives yet (docs/gradients.md). In the
     RGB and mono variants, which integrate over channels, a non-zero value is ignored with a
     warning. (Default: 0)
   - |exposed|

 * - channel
   - |string|
   - Mono variants only: the colour channel the plate is integrated over in closed form,
     ``"<weights>:<channel>"`` with weights ``srgb-d65`` (channels ``R``, ``G``, ``B``: linear
     sRGB under D65, signed), ``xyz-d65`` or ``xyz-e`` (``X``, ``Y``, ``Z``: CIE 1931 under D65
     or the equal-energy illuminant), each normalised so that a spectrally flat plate gives 1.
     A render per channel (``mitsuba_birefringent.render_analytic`` does this) gives the
     plate's colours without colour noise. Refused in the other variants. (Default:
     ``"xyz-d65:Y"``, the luminance)

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
physics is the core's ``sample_plate``, through ``render::plate::plate_lobes``; see
docs/physics.md, sections 3 and 4). Lobes are sampled in proportion to their unpolarised
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
#include "plugins.h"
#include "differentiable.h"
#include "recorded.h"
#include "last_valid.h"
#include "layer.h"
#include "scalar_texture.h"
#include "signed_rgb.h"

NAMESPACE_BEGIN(mitsuba)

template <typename Float, typename Spectrum>
class ThinBirefringent final : public BSDF<Float, Spectrum>,
                               public shim::LayerSource<Float, Spectrum> {
public:
    MI_IMPORT_BASE(BSDF, m_flags, m_components)
    MI_IMPORT_TYPES(Texture)
    using Answers = shim::Answers<Float, Spectrum>;
    using Vec3d = typename Answers::Vec3d;

    /// Parameters of other plugins a Mitsuba user is likely to give a plate, and what to give.
    static constexpr shim::Foreign Foreign[] = {
        { "int_ior", "the plate's own index is eta_o and eta_e (equal for a glass plate) or "
                     "\"material\"; the media on its two sides are ext_ior and exit_ior" },
        { "optic_axis_space", "a plate's optic_axis is in its shading frame (x = dp/du, z = the "
                              "normal), rotated by axis_angle; a world-space axis is a parameter "
                              "of \"birefringent\", the bulk crystal" },
        { "specular_reflectance", "the plate's reflection and transmission follow from its "
                                  "indices and thickness; they have no scale factors" },
        { "specular_transmittance", "the plate's reflection and transmission follow from its "
                                    "indices and thickness; they have no scale factors" },
    };

    ThinBirefringent(const Properties &props) : Base(props) {
        shim::refuse_foreign(props, Foreign, ClassName);
        for (const char *name : { "ext_ior", "exit_ior", "filter_bandwidth", "channel", "absorbing_exit" })
            if (props.has_property(name))
                m_surroundings.push_back(name);
        shim::Defaults defaults;
        shim::MaterialParams material = shim::parse_material(props, ClassName, defaults,
                                                             props.has_property("birefringence"));
        m_ext_ior = shim::parse_ior(props, "ext_ior", "air", ClassName);
        m_exit_ior = props.has_property("exit_ior")
                         ? shim::parse_ior(props, "exit_ior", "air", ClassName)
                         : m_ext_ior;
        shim::require_vector(props, "optic_axis", ClassName);
        m_diff.set(material, props.get<ScalarVector3f>("optic_axis", ScalarVector3f(1.f, 0.f, 0.f)));
        m_thickness = shim::scalar_texture<Float, Spectrum>(props, "thickness", 1.0,
                                                            "micrometres", ClassName);
        m_thickness_scale = props.get<double>("thickness_scale", 1.0);
        if (props.has_property("birefringence"))
            m_birefringence = shim::scalar_texture<Float, Spectrum>(
                props, "birefringence", 0.0, "added to eta_e", ClassName);
        m_birefringence_scale = props.get<double>("birefringence_scale", 1.0);
        if (props.has_property("axis_angle"))
            m_axis_angle = shim::scalar_texture<Float, Spectrum>(props, "axis_angle", 0.0,
                                                                 "degrees", ClassName);
        m_filter_bandwidth = shim::parse_filter_bandwidth<Spectrum>(props, ClassName);
        m_absorbing_exit = props.get<bool>("absorbing_exit", false);
        m_channel = shim::parse_channel<Spectrum>(props, ClassName);
        if (!props.has_property("thickness"))
            defaults.add("thickness = 1 um (thickness is in micrometres: a 3 mm plate is 3000)");
        parameters_changed();
        if (!props.has_property("optic_axis") && !props.has_property("axis_angle") &&
            !(m_material->is_isotropic(0) && !m_birefringence))
            defaults.add("optic_axis = [1, 0, 0] in the shading frame (x = dp/du: on a "
                         "rectangle the world's x), where between polarisers along x or y the "
                         "plate changes nothing (crossed ones stay black); give optic_axis, "
                         "e.g. [1, 1, 0] at 45 degrees, or axis_angle");
        defaults.log(props, ClassName);
    }

    /// eta_o, eta_e, kappa_o, kappa_e, optic_axis and the textures' values are differentiable
    /// in the JIT variants (differentiable.h); the media, scales and band are not.
    void traverse(TraversalCallback *cb) override {
        // (A stack's layer: the stack exposes it as not differentiable, birefringentstack.cpp.)
        m_diff.traverse(cb);
        const ParamFlags textures = shim::texture_flags<Float>();
        if (!m_nested) {
            cb->put("ext_ior", m_ext_ior, ParamFlags::NonDifferentiable);
            cb->put("exit_ior", m_exit_ior, ParamFlags::NonDifferentiable);
        }
        cb->put("thickness", m_thickness, textures);
        cb->put("thickness_scale", m_thickness_scale, ParamFlags::NonDifferentiable);
        if (m_birefringence)
            cb->put("birefringence", m_birefringence, textures);
        cb->put("birefringence_scale", m_birefringence_scale, ParamFlags::NonDifferentiable);
        if (m_axis_angle)
            cb->put("axis_angle", m_axis_angle, textures);
        if (!m_nested)
            cb->put("filter_bandwidth", m_filter_bandwidth, ParamFlags::NonDifferentiable);
    }

    /// Applies changed parameters; a rejected update leaves the last valid state in force
    /// (shim::update_or_restore).
    void parameters_changed(const std::vector<std::string> & /*keys*/ = {}) override {
        shim::update_or_restore<Float, Spectrum>(this, m_valid, [this] { rebuild(); });
    }

private:
    /// Rebuilds the core material, the spectrum and the flags, and checks every parameter with
    /// one core query (textures at their mean, 550 nm, the filter band), so that invalid input
    /// fails here, with the core's message.
    void rebuild() {
        auto [material, axis] = m_diff.updated();
        m_material = shim::make_material(material, ClassName);
        m_band = bfr::band_spectrum(m_filter_bandwidth);
        shim::require_kernel_path<Float, Spectrum>(is_spectral_v<Spectrum> && m_filter_bandwidth == 0.0,
                                                   ClassName);
        m_spectrum = shim::thin_spectrum<Spectrum>(m_filter_bandwidth, m_channel, ClassName);
        m_null = m_exit_ior == m_ext_ior && !m_absorbing_exit;
        bool isotropic = m_material->is_isotropic(0) && !m_birefringence;
        shim::thin_flags(isotropic, m_null, m_absorbing_exit, m_exit_ior != m_ext_ior, m_types,
                         m_components, m_flags);
        check_at_load(axis);
        m_diff.commit(material, axis);
        m_programs.clear();
        warn_of_units();
    }

public:

    std::pair<BSDFSample3f, Spectrum> sample(const BSDFContext &ctx, const SurfaceInteraction3f &si,
                                             Float sample1, const Point2f & /*sample2*/,
                                             Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFSample, active);
        uint32_t components = (ctx.is_enabled(m_types[0], 0) ? 1u : 0u) |
                              (ctx.is_enabled(m_types[1], 1) ? 2u : 0u);
        if (!components || shim::none_active(active))
            return { dr::zeros<BSDFSample3f>(), dr::zeros<Spectrum>() };
        if constexpr (Recordable)
            if (m_filter_bandwidth == 0.0)
                return replayed(si, ctx.mode, components, sample1, active, false);
        return query(si, ctx.mode, components, sample1, active, false).sample();
    }

    Spectrum eval(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
                  Mask) const override {
        return dr::zeros<Spectrum>();  // delta lobes only
    }

    Float pdf(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
              Mask) const override {
        return dr::zeros<Float>();
    }

    /// The transmission matrix for light travelling along si.wi (shadow rays of volpath).
    Spectrum eval_null_transmission(const SurfaceInteraction3f &si, Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFEvaluate, active);
        if (!m_null || shim::none_active(active))
            return dr::zeros<Spectrum>();
        if constexpr (Recordable)
            if (m_filter_bandwidth == 0.0)
                return replayed(si, TransportMode::Radiance, 2u, Float(0.5f), active, true).second;
        return query(si, TransportMode::Radiance, 2u, Float(0.5f), active, true).spectrum();
    }

    void nest() override { m_nested = true; }

    /// The plate as a layer of a stack (birefringentstack).
    shim::PlateLayer<Float, Spectrum> layer() const override {
        shim::PlateLayer<Float, Spectrum> l;
        l.material = &m_diff.material;
        l.optic_axis = m_diff.axis;
        l.diff = &m_diff;
        l.thickness = m_thickness.get();
        l.thickness_scale = m_thickness_scale;
        l.birefringence = m_birefringence.get();
        l.birefringence_scale = m_birefringence_scale;
        l.axis_angle = m_axis_angle.get();
        l.surroundings = &m_surroundings;
        return l;
    }

    std::string to_string() const override {
        std::ostringstream oss;
        oss << "ThinBirefringent[" << std::endl
            << "  " << m_diff.material.to_string() << "," << std::endl
            << "  ext_ior = " << m_ext_ior << ", exit_ior = " << m_exit_ior << "," << std::endl
            << "  optic_axis = " << m_diff.axis << "," << std::endl
            << "  thickness = " << string::indent(m_thickness) << " (um)," << std::endl
            << "  thickness_scale = " << m_thickness_scale << "," << std::endl;
        if (m_birefringence)
            oss << "  birefringence = " << string::indent(m_birefringence) << "," << std::endl
                << "  birefringence_scale = " << m_birefringence_scale << "," << std::endl;
        if (m_axis_angle)
            oss << "  axis_angle = " << string::indent(m_axis_angle) << " (degrees)," << std::endl;
        oss << "  filter_bandwidth = " << m_filter_bandwidth << " (nm FWHM, spectral variants)," << std::endl
            << "  absorbing_exit = " << (m_absorbing_exit ? "true" : "false");
        if constexpr (is_monochromatic_v<Spectrum>)
            oss << "," << std::endl << "  channel = \"" << m_channel << "\"";
        oss << std::endl << "]";
        return oss.str();
    }

    MI_DECLARE_CLASS(ThinBirefringent)

private:
    /// Input columns of a core query (indices into shim::ChunkBuffers::in).
    enum Column : size_t { Thickness, Birefringence, AxisX, AxisY, AxisZ, AxisAngle, WiX, WiY,
                           WiZ, Sample, ExtIor, ExitIor, Wavelength0 };
    static_assert(WiY == WiX + 1 && WiZ == WiX + 2 && Sample == WiX + 3, "shim::fill_path_lanes");

    /// The core's per-call settings.
    bfr::PlateCall call(uint32_t components) const {
        return { components, !is_polarized_v<Spectrum>, m_absorbing_exit };
    }

    /// One core query at normal incidence with the textures at their mean, the filter band at
    /// 550 nm and the optic axis `optic_axis`; throws its message.
    void check_at_load(const ScalarVector3f &optic_axis) const {
        shim::ChunkBuffers<1> b;
        const uint8_t one = 1;
        const uint32_t material = 0;
        const bfr::Transport radiance = bfr::Transport::Radiance;
        const double u = 0.5, lambda = 550.0;
        rust::Slice<const double> wave(&lambda, 1);
        bfr::PlateLanes lanes{};
        lanes.count = 1;
        lanes.active = { &one, 1 };
        lanes.material = { &material, 1 };
        lanes.transport = { &radiance, 1 };
        lanes.sample = { &u, 1 };
        lanes.wi = { b.constant(WiX, 0.0).slice(), b.constant(WiY, 0.0).slice(),
                     b.constant(WiZ, 1.0).slice() };
        lanes.wavelengths_nm = { &wave, 1 };
        lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
        lanes.exit_ior = b.constant(ExitIor, m_exit_ior).slice();
        lanes.optic_axis = axis(b, optic_axis);
        double angle = m_axis_angle ? shim::scalar(m_axis_angle->mean()) : 0.0;
        lanes.axis_angle_deg = b.constant(AxisAngle, angle).slice();
        double thickness = thickness_nm(shim::scalar(m_thickness->mean()));
        lanes.thickness_nm = b.constant(Thickness, thickness).slice();
        double dn = m_birefringence ? shim::scalar(m_birefringence->mean()) : 0.0;
        lanes.birefringence = b.constant(Birefringence, m_birefringence_scale * dn).slice();
        bfr::Samples s = b.samples(1, 1, true);
        bfr::Status rc = bfr::sample_plate(*m_material, *m_band, call(3u), lanes, s);
        if (rc != bfr::Status::Ok)
            Throw("%s", shim::core_message(rc, s.message));
    }

    /// The core's warning for a thickness probably in the wrong unit (textures at their mean)
    /// or an `axis_angle` probably in radians (a uniform one), logged when it differs from the
    /// last one logged (not again on every update).
    void warn_of_units() {
        double thickness = thickness_nm(shim::scalar(m_thickness->mean()));
        double dn = m_birefringence ? shim::scalar(m_birefringence->mean()) : 0.0;
        double angle = m_axis_angle && !m_axis_angle->is_spatially_varying()
                           ? shim::scalar(m_axis_angle->mean())
                           : std::nan("");
        std::string warning(
            m_material->plate_warning(0, thickness, m_birefringence_scale * dn, angle));
        if (!warning.empty() && warning != m_unit_warning)
            Log(Warn, "%s", warning);
        m_unit_warning = warning;
    }

    /// Thickness (nm) from the texture value (um, before scaling).
    double thickness_nm(double thickness_um) const {
        return 1000.0 * m_thickness_scale * thickness_um;
    }

    /** The core's lobe for every lane of `si`, with the components in the bits of `components`
     * enabled. `straight`: the frames of a straight-through lobe (eval_null_transmission).
     * Lanes the core refuses (e.g. a texture giving a negative thickness) carry no light and
     * are reported once. */
    Answers query(const SurfaceInteraction3f &si, TransportMode mode, uint32_t components,
                  const Float &sample1, const Mask &active, bool straight) const {
        shim::require_evaluated_mode<Float>(ClassName, "filter_bandwidth = 0 in a spectral variant");
        shim::HostInputs<Float> in;
        const shim::PathColumns path = shim::add_path_inputs<Float, Spectrum>(in, si, sample1, active);
        Float thickness = m_thickness->eval_1(si, active);
        Float birefringence = m_birefringence ? m_birefringence->eval_1(si, active) : Float(0.f);
        Float angle_deg = m_axis_angle ? m_axis_angle->eval_1(si, active) : Float(0.f);
        size_t k_thick = in.add(thickness);
        size_t k_biref = m_birefringence ? in.add(birefringence) : 0;
        size_t k_angle = m_axis_angle ? in.add(angle_deg) : 0;
        const size_t waves = path.waves;
        shim::refuse_gradients(ClassName, *m_spectrum, si.wi, thickness, birefringence, angle_deg,
                               m_diff.eta_o(), m_diff.eta_e(), m_diff.kappa_o(),
                               m_diff.kappa_e(), m_diff.optic_axis());
        Answers answers;
        size_t n = in.width();
        answers.allocate(n);
        in.read();

        bool radiance = mode == TransportMode::Radiance;
        bfr::Transport transport = radiance ? bfr::Transport::Radiance : bfr::Transport::Importance;
        bfr::PlateCall settings = call(components);
        size_t channels = m_spectrum->channels(waves);
        const shim::FloatColumn angle = m_axis_angle ? in.floats(k_angle) : shim::FloatColumn{};
        std::string failure = shim::for_chunks<Float>(n, [&](size_t begin, size_t end) {
            shim::ChunkStorage<Float> storage;
            auto &b = *storage;
            const uint32_t material = 0;
            bfr::PlateLanes lanes{};
            shim::fill_path_lanes(lanes, b, in, path, begin, end, WiX, Wavelength0);
            lanes.material = { &material, 1 };
            lanes.transport = { &transport, 1 };
            lanes.wavelengths_nm = b.wavelength_columns(Wavelength0, waves);
            lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
            lanes.exit_ior = b.constant(ExitIor, m_exit_ior).slice();
            lanes.optic_axis = axis(b, m_diff.axis);
            lanes.axis_angle_deg = m_axis_angle
                                       ? b.convert(AxisAngle, angle, begin, end).slice()
                                       : b.constant(AxisAngle, 0.0).slice();
            lanes.thickness_nm = b.convert(Thickness, in.floats(k_thick), begin, end,
                                           [this](double t) { return thickness_nm(t); }).slice();
            lanes.birefringence =
                m_birefringence
                    ? b.convert(Birefringence, in.floats(k_biref), begin, end,
                                [this](double x) { return m_birefringence_scale * x; }).slice()
                    : b.constant(Birefringence, 0.0).slice();
            bfr::Samples s = b.samples(lanes.count, channels, is_polarized_v<Spectrum>);
            bfr::Status rc = bfr::sample_plate(*m_material, *m_spectrum, settings, lanes, s);
            for (size_t j = 0; j < lanes.count; ++j) {
                size_t i = begin + j;
                Vec3d wi(in.floats(path.wi[0]).at(i), in.floats(path.wi[1]).at(i),
                         in.floats(path.wi[2]).at(i));
                std::optional<Vec3d> through;
                if (straight)
                    through = -wi;
                answers.write(b, lanes.count, j, channels, wi, radiance, through, m_types, i);
            }
            return rc == bfr::Status::Ok ? std::string() : shim::core_message(rc, s.message);
        });
        if (!failure.empty() && !m_warned.exchange(true))
            Log(Warn, "%s (returning no light; further errors are not reported)", failure);
        return answers;
    }

    /// The variants where a query can be the exact plate at each sampled wavelength, which the
    /// core records as a program replayed inside Mitsuba's kernels (the JIT spectral variants,
    /// with filter_bandwidth 0); the other JIT queries (a band, colour channels) call the core
    /// on the host in evaluated mode.
    static constexpr bool Recordable = dr::is_jit_v<Float> && is_spectral_v<Spectrum>;

    /// Which parameters are inputs of a program (they carry derivatives: their values may
    /// change without a new program), the key of a program with the transport mode and the
    /// enabled components.
    using ProgramKey = std::tuple<bool, uint32_t, bool, bool, bool>;

    /// The sample of the program of this setting, replayed on the lanes of `si` (recorded.h).
    std::pair<BSDFSample3f, Spectrum> replayed(const SurfaceInteraction3f &si,
                                               TransportMode mode, uint32_t components,
                                               const Float &sample1, const Mask &active,
                                               bool straight) const {
        using In = bfr::PlateInput;
        using Answer = shim::Replayed<Float, Spectrum>;
        constexpr size_t Channels = Answer::Channels;
        bool radiance = mode == TransportMode::Radiance;
        Float eta_o = m_diff.eta_o(), eta_e = m_diff.eta_e(), kappa_o = m_diff.kappa_o(),
              kappa_e = m_diff.kappa_e();
        Vector3f axis = m_diff.optic_axis();
        auto [axis_input, indices_input, kappas_input] = m_diff.program_inputs();
        ProgramKey key{ radiance, components, axis_input, indices_input, kappas_input };
        const bfr::Program &program = m_programs.get(key, [&] {
            const ScalarVector3f &a = m_diff.axis;
            bfr::PlateRecipe recipe{ 0,
                                     radiance ? bfr::Transport::Radiance
                                              : bfr::Transport::Importance,
                                     components,
                                     (uint32_t) Channels,
                                     !is_polarized_v<Spectrum>,
                                     m_absorbing_exit,
                                     m_ext_ior,
                                     m_exit_ior,
                                     m_thickness_scale,
                                     (bool) m_birefringence,
                                     m_birefringence_scale,
                                     (bool) m_axis_angle,
                                     { a.x(), a.y(), a.z() },
                                     axis_input,
                                     indices_input,
                                     kappas_input };
            return shim::core_call(ClassName, [&] { return bfr::record_plate(*m_material, recipe); });
        });
        std::vector<Float> x((size_t) In::Wavelength0 + Channels, Float(0.f));
        auto set = [&](In k, const Float &v) { x[(size_t) k] = v; };
        set(In::WiX, si.wi.x());
        set(In::WiY, si.wi.y());
        set(In::WiZ, si.wi.z());
        set(In::Sample, sample1);
        set(In::Thickness, m_thickness->eval_1(si, active));
        if (m_birefringence)
            set(In::Birefringence, m_birefringence->eval_1(si, active));
        if (m_axis_angle)
            set(In::AxisAngle, m_axis_angle->eval_1(si, active));
        set(In::AxisX, axis.x());
        set(In::AxisY, axis.y());
        set(In::AxisZ, axis.z());
        set(In::EtaO, eta_o);
        set(In::EtaE, eta_e);
        set(In::KappaO, kappa_o);
        set(In::KappaE, kappa_e);
        if constexpr (is_spectral_v<Spectrum>)
            for (size_t c = 0; c < Channels; ++c)
                x[(size_t) In::Wavelength0 + c] = si.wavelengths[c];
        shim::Replay<Float> r(program, x);
        return Answer::sample(r, si.wi, radiance, straight, m_types, 2, active);
    }

    /// The optic axis `a` (the core rotates it by `axis_angle`).
    template <size_t Cap>
    static std::array<rust::Slice<const double>, 3> axis(shim::ChunkBuffers<Cap> &b,
                                                         const ScalarVector3f &a) {
        return { b.constant(AxisX, a.x()).slice(), b.constant(AxisY, a.y()).slice(),
                 b.constant(AxisZ, a.z()).slice() };
    }

    /// eta_o, eta_e, kappa_o, kappa_e and optic_axis (differentiable in the JIT variants).
    shim::Differentiable<Float> m_diff;
    rust::Box<bfr::Materials> m_material = bfr::new_materials();
    rust::Box<bfr::PlateSpectrum> m_spectrum = bfr::exact_spectrum(), m_band = bfr::exact_spectrum();
    double m_ext_ior, m_exit_ior;
    ref<Texture> m_thickness, m_birefringence, m_axis_angle;
    double m_thickness_scale, m_birefringence_scale, m_filter_bandwidth;
    std::string m_channel;  ///< the colour channel of a mono variant's render
    std::vector<std::string> m_surroundings;  ///< see shim::PlateLayer::surroundings
    bool m_nested = false;  ///< a stack's layer (shim::LayerSource::nest)
    bool m_null = true, m_absorbing_exit = false;
    BSDFFlags m_types[(size_t) bfr::Bounds::PlateComponents];
    mutable std::atomic<bool> m_warned { false };
    std::string m_unit_warning;  ///< the last warn_of_units message
    /// See signed_rgb.h (the JIT variants' films do not warn of negative values).
    shim::SignedRgbGuard m_signed_rgb { is_rgb_v<Spectrum> && !dr::is_jit_v<Float> };
    std::unique_ptr<shim::Snapshot<Float, Spectrum>> m_valid;  ///< last valid state
    /// The programs of the JIT spectral variants (recorded()), by ProgramKey.
    mutable shim::Programs<ProgramKey> m_programs;

    MI_TRAVERSE_CB(Base, m_thickness, m_birefringence, m_axis_angle)
};

NAMESPACE_BEGIN(shim)
void register_thinbirefringent() { register_plugin<ThinBirefringent>("thinbirefringent"); }
NAMESPACE_END(shim)

NAMESPACE_END(mitsuba)
