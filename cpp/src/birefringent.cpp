/**!

.. _bsdf-birefringent:

Bulk birefringent crystal (:monosp:`birefringent`)
--------------------------------------------------

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
   - Extinction coefficients added to the indices (``n + i kappa``, ``0 <= kappa <= 1e3``),
     accepted only for an isotropic material (a metal-like surface): in an absorbing
     birefringent crystal the o and e waves are not power-orthogonal, so the power of each
     refracted ray is undefined (refused at load with that reason; use
     :monosp:`thinbirefringent` for a dichroic plate). An absorbing bulk is opaque, like
     :monosp:`conductor`: what refracts into it is absorbed at the surface, so there is the
     reflection alone from outside and nothing from inside. (Default: 0)
   - |exposed|, |differentiable|

 * - optic_axis
   - |vector|
   - The optic axis, any non-zero length, in the frame that ``optic_axis_space`` names.
     (Default: ``[1, 0, 0]``, said in a warning at load for a birefringent material)
   - |exposed|, |differentiable|

 * - optic_axis_space
   - |string|
   - ``"local"``: ``optic_axis`` is in the shading frame (x = dp/du, z = normal; fine for a flat
     face, e.g. a ``rectangle``); ``"world"``: in world space, converted to each hit's shading
     frame, so that every face of a crystal object (a ``cube``, a mesh) sees the same crystal.
     (Default: ``"local"``, said in a warning at load when a birefringent material's
     ``optic_axis`` is given without it)

 * - ext_ior
   - |float| or |string|
   - Real index of the medium on the side the normal points to, a number or a Mitsuba IOR name.
     (Default: ``"air"``, 1.000277)
   - |exposed|

 * - channel
   - |string|
   - Mono variants only: the colour channel of the render (as :monosp:`thinbirefringent`'s
     ``channel``). A crystal's refraction directions depend on the wavelength, so it cannot be
     integrated over a channel: it is evaluated at the channel's mean wavelength (where the
     channel's weight is positive; ``xyz-d65:Y`` 557 nm). Refused in the other variants.
     (Default: ``"xyz-d65:Y"``)

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
``sample_crystal``, through ``render::crystal::crystal_slots`` (docs/physics.md, sections 2
and 5).

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
#include "plugins.h"
#include "recorded.h"
#include "differentiable.h"
#include "last_valid.h"

NAMESPACE_BEGIN(mitsuba)

template <typename Float, typename Spectrum>
class Birefringent final : public BSDF<Float, Spectrum> {
public:
    MI_IMPORT_BASE(BSDF, m_flags, m_components)
    MI_IMPORT_TYPES()
    using Answers = shim::Answers<Float, Spectrum>;
    using Vec3d = typename Answers::Vec3d;

    /// Wavelength (nm) of the RGB variants, which have none (only isotropic constant indices
    /// are allowed there, so it does not matter). The mono variants evaluate the crystal at
    /// their `channel`'s mean wavelength.
    static constexpr double RgbWavelength = 550.0;

    /// Parameters of other plugins a Mitsuba user is likely to give a bulk crystal, and what to
    /// give.
    static constexpr shim::Foreign Foreign[] = {
        { "int_ior", "the crystal's indices are eta_o and eta_e, or \"material\"; the medium "
                     "outside is ext_ior" },
        { "thickness", "a bulk crystal's surface has no thickness (the crystal fills the shape); "
                       "a plate is \"thinbirefringent\"" },
        { "birefringence", "a stress birefringence is a parameter of \"thinbirefringent\" (a "
                           "plate); a bulk crystal takes its birefringence from eta_o and eta_e, "
                           "or \"material\"" },
        { "axis_angle", "axis_angle is a parameter of \"thinbirefringent\" (a plate); a bulk "
                        "crystal's axis is optic_axis, in the frame optic_axis_space names" },
        { "exit_ior", "the medium behind a bulk crystal's surface is the crystal itself; a plate "
                      "between two media is \"thinbirefringent\"" },
    };

    Birefringent(const Properties &props) : Base(props) {
        shim::refuse_foreign(props, Foreign, ClassName);
        shim::Defaults defaults;
        shim::MaterialParams material = shim::parse_material(props, ClassName, defaults);
        m_ext_ior = shim::parse_ior(props, "ext_ior", "air", ClassName);
        shim::require_vector(props, "optic_axis", ClassName);
        m_diff.set(material, props.get<ScalarVector3f>("optic_axis", ScalarVector3f(1.f, 0.f, 0.f)));
        std::string space = props.get<std::string>("optic_axis_space", "local");
        if (space != "local" && space != "world")
            Throw("\"optic_axis_space\" must be \"local\" (the shading frame) or \"world\", got \"%s\"", space);
        m_axis_in_world = space == "world";
        m_channel = shim::parse_channel<Spectrum>(props, ClassName);
        if constexpr (is_monochromatic_v<Spectrum>)
            m_wavelength = shim::core_call(ClassName, [&] { return bfr::colour_channel_wavelength(m_channel); });
        parameters_changed();
        if (!props.has_property("optic_axis") && !m_material->is_isotropic(0))
            defaults.add("optic_axis = [1, 0, 0] in the shading frame of each hit (give it, and "
                         "optic_axis_space \"world\" for a crystal object such as a cube)");
        else if (!props.has_property("optic_axis_space") && !m_material->is_isotropic(0))
            defaults.add("optic_axis_space = \"local\": optic_axis is in the shading frame of "
                         "each hit, which turns with the surface (every face of a cube, every "
                         "point of a sphere or a mesh sees another crystal); give "
                         "optic_axis_space \"world\" for one crystal filling the shape, or "
                         "\"local\" for an axis that follows the surface");
        defaults.log(props, ClassName);
    }

    /// eta_o, eta_e, kappa_o, kappa_e and optic_axis are differentiable in the JIT variants
    /// (differentiable.h); ext_ior is not.
    void traverse(TraversalCallback *cb) override {
        m_diff.traverse(cb);
        cb->put("ext_ior", m_ext_ior, ParamFlags::NonDifferentiable);
    }

    /// Applies changed parameters; a rejected update leaves the last valid state in force
    /// (shim::update_or_restore).
    void parameters_changed(const std::vector<std::string> & /*keys*/ = {}) override {
        shim::update_or_restore<Float, Spectrum>(this, m_valid, [this] { rebuild(); });
    }

private:
    /// Rebuilds the core material and the flags, and checks every parameter with one core query.
    void rebuild() {
        auto [material, axis] = m_diff.updated();
        m_material = shim::make_material(material, ClassName);
        bool isotropic = m_material->is_isotropic(0);
        if (!is_polarized_v<Spectrum> && !isotropic)
            Throw("double refraction (eta_o != eta_e, or a named crystal: %s) needs a polarized "
                  "variant, which carries whether a ray in the crystal is ordinary or "
                  "extraordinary: use scalar_spectral_polarized, llvm_ad_spectral_polarized or "
                  "llvm_ad_mono_polarized. In this variant only an isotropic material "
                  "(eta_o == eta_e, kappa_o == kappa_e) works.", material.to_string());
        uint32_t aniso = isotropic ? 0u : (uint32_t) BSDFFlags::Anisotropic;
        uint32_t sides = (uint32_t) (BSDFFlags::FrontSide | BSDFFlags::BackSide) | aniso;
        m_types[0] = BSDFFlags::DeltaReflection;
        m_types[1] = m_types[2] = BSDFFlags::DeltaTransmission;
        m_components.clear();
        // A lobe between different ray indices (a refraction; inside a birefringent crystal
        // also a reflection that converts o into e) carries the radiance factor
        // (n_wi / n_wo)^2 in its Radiance weight and not in its Importance weight:
        // non-symmetric, as Mitsuba's `dielectric` declares its refraction.
        for (size_t k = 0; k < 3; ++k) {
            bool asym = k > 0 || !isotropic;
            m_components.push_back((uint32_t) m_types[k] | sides |
                                   (asym ? (uint32_t) BSDFFlags::NonSymmetric : 0u));
        }
        m_flags = m_components[0] | m_components[1] | m_components[2];
        check_at_load(axis);
        m_diff.commit(material, axis);
        m_programs.clear();
    }

public:

    std::pair<BSDFSample3f, Spectrum> sample(const BSDFContext &ctx, const SurfaceInteraction3f &si,
                                             Float sample1, const Point2f & /*sample2*/,
                                             Mask active) const override {
        MI_MASKED_FUNCTION(ProfilerPhase::BSDFSample, active);
        uint32_t components = 0;
        for (uint32_t k = 0; k < 3; ++k)
            if (ctx.is_enabled(m_types[k], k))
                components |= 1u << k;
        if (!components || shim::none_active(active))
            return { dr::zeros<BSDFSample3f>(), dr::zeros<Spectrum>() };
        if constexpr (dr::is_jit_v<Float>)
            return replayed(si, ctx.mode, components, sample1, active);
        else
            return query(si, ctx.mode, components, sample1, active);
    }

    Spectrum eval(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
                  Mask) const override {
        return dr::zeros<Spectrum>();  // delta lobes only
    }

    Float pdf(const BSDFContext &, const SurfaceInteraction3f &, const Vector3f &,
              Mask) const override {
        return dr::zeros<Float>();
    }

    std::string to_string() const override {
        std::ostringstream oss;
        oss << "Birefringent[" << std::endl
            << "  " << m_diff.material.to_string() << "," << std::endl
            << "  ext_ior = " << m_ext_ior << "," << std::endl
            << "  optic_axis = " << m_diff.axis << " (" << (m_axis_in_world ? "world" : "local")
            << " frame)";
        if constexpr (is_monochromatic_v<Spectrum>)
            oss << "," << std::endl << "  channel = \"" << m_channel << "\" (at " << m_wavelength << " nm)";
        oss << std::endl << "]";
        return oss.str();
    }

    MI_DECLARE_CLASS(Birefringent)

private:
    /// Input columns of a core query (indices into shim::ChunkBuffers::in).
    enum Column : size_t { AxisX, AxisY, AxisZ, WiX, WiY, WiZ, Sample, ExtIor, Wavelength0 };
    static_assert(WiY == WiX + 1 && WiZ == WiX + 2 && Sample == WiX + 3, "shim::fill_path_lanes");

    /// One core query at normal incidence, at the variant's wavelength (550 nm in the spectral
    /// ones), with the axis `optic_axis` as given; throws its message.
    void check_at_load(const ScalarVector3f &optic_axis) const {
        shim::ChunkBuffers<1> b;
        const uint8_t one = 1;
        const uint32_t material = 0;
        const bfr::Transport radiance = bfr::Transport::Radiance;
        const double u = 0.5;
        bfr::CrystalLanes lanes{};
        lanes.count = 1;
        lanes.active = { &one, 1 };
        lanes.material = { &material, 1 };
        lanes.transport = { &radiance, 1 };
        lanes.sample = { &u, 1 };
        lanes.wi = { b.constant(WiX, 0.0).slice(), b.constant(WiY, 0.0).slice(),
                     b.constant(WiZ, 1.0).slice() };
        b.constant(Wavelength0, m_wavelength);
        lanes.wavelengths_nm = b.wavelength_columns(Wavelength0, 1);
        lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
        lanes.optic_axis = { b.constant(AxisX, optic_axis.x()).slice(),
                             b.constant(AxisY, optic_axis.y()).slice(),
                             b.constant(AxisZ, optic_axis.z()).slice() };
        bfr::Samples s = b.samples(1, 1, true);
        bfr::Status rc = bfr::sample_crystal(*m_material, 7u, lanes, s);
        if (rc != bfr::Status::Ok)
            Throw("%s", shim::core_message(rc, s.message));
    }

    /** The core's lobe for every lane of `si`, with the components in the bits of `components`
     * enabled; lanes the core refuses carry no light and are reported once. */
    std::pair<BSDFSample3f, Spectrum> query(const SurfaceInteraction3f &si, TransportMode mode,
                                            uint32_t components, const Float &sample1,
                                            const Mask &active) const {
        shim::require_evaluated_mode<Float>(ClassName, "every query");
        shim::HostInputs<Float> in;
        const shim::PathColumns path = shim::add_path_inputs<Float, Spectrum>(in, si, sample1, active);
        size_t k_axis = 0;
        // The axis in the shading frame: in world space, it moves with the frame.
        Vector3f axis = m_diff.optic_axis();
        if (m_axis_in_world) {
            axis = si.to_local(axis);
            k_axis = in.add(axis.x());
            in.add(axis.y());
            in.add(axis.z());
        }
        // One wavelength column in the RGB and mono variants (m_wavelength).
        const size_t waves = is_spectral_v<Spectrum> ? path.waves : 1;
        Answers answers;
        size_t n = in.width();
        answers.allocate(n);
        in.read();

        bool radiance = mode == TransportMode::Radiance;
        bfr::Transport transport = radiance ? bfr::Transport::Radiance : bfr::Transport::Importance;
        std::string failure = shim::for_chunks<Float>(n, [&](size_t begin, size_t end) {
            shim::ChunkStorage<Float> storage;
            auto &b = *storage;
            const uint32_t material = 0;
            bfr::CrystalLanes lanes{};
            shim::fill_path_lanes(lanes, b, in, path, begin, end, WiX, Wavelength0);
            lanes.material = { &material, 1 };
            lanes.transport = { &transport, 1 };
            if constexpr (!is_spectral_v<Spectrum>)
                b.constant(Wavelength0, m_wavelength);
            lanes.wavelengths_nm = b.wavelength_columns(Wavelength0, waves);
            lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
            if (m_axis_in_world)
                lanes.optic_axis = { b.convert(AxisX, in.floats(k_axis), begin, end).slice(),
                                     b.convert(AxisY, in.floats(k_axis + 1), begin, end).slice(),
                                     b.convert(AxisZ, in.floats(k_axis + 2), begin, end).slice() };
            else
                lanes.optic_axis = { b.constant(AxisX, m_diff.axis.x()).slice(),
                                     b.constant(AxisY, m_diff.axis.y()).slice(),
                                     b.constant(AxisZ, m_diff.axis.z()).slice() };
            bfr::Samples s = b.samples(lanes.count, waves, is_polarized_v<Spectrum>);
            bfr::Status rc = bfr::sample_crystal(*m_material, components, lanes, s);
            for (size_t j = 0; j < lanes.count; ++j) {
                size_t i = begin + j;
                Vec3d wi(in.floats(path.wi[0]).at(i), in.floats(path.wi[1]).at(i),
                         in.floats(path.wi[2]).at(i));
                answers.write(b, lanes.count, j, waves, wi, radiance, std::nullopt, m_types, i);
            }
            return rc == bfr::Status::Ok ? std::string() : shim::core_message(rc, s.message);
        });
        if (!failure.empty() && !m_warned.exchange(true))
            Log(Warn, "%s (returning no light; further errors are not reported)", failure);
        return answers.sample();
    }

    /// The key of a program: the transport mode, the enabled components, and which parameters
    /// are inputs (the axis: carrying derivatives or given in world space; the indices; the
    /// extinctions).
    using ProgramKey = std::tuple<bool, uint32_t, bool, bool, bool>;

    /// The sample of the program of this setting, replayed on the lanes of `si` (recorded.h):
    /// every query of the JIT variants, at each sampled wavelength (spectral variants) or at the
    /// variant's wavelength (RGB, mono).
    std::pair<BSDFSample3f, Spectrum> replayed(const SurfaceInteraction3f &si,
                                               TransportMode mode, uint32_t components,
                                               const Float &sample1, const Mask &active) const {
        using In = bfr::CrystalInput;
        using Answer = shim::Replayed<Float, Spectrum>;
        constexpr size_t Channels = is_spectral_v<Spectrum> ? Answer::Channels : 1;
        bool radiance = mode == TransportMode::Radiance;
        Float eta_o = m_diff.eta_o(), eta_e = m_diff.eta_e(), kappa_o = m_diff.kappa_o(),
              kappa_e = m_diff.kappa_e();
        // The axis in the shading frame: in world space, it moves with the frame.
        Vector3f axis = m_diff.optic_axis();
        if (m_axis_in_world)
            axis = si.to_local(axis);
        auto [axis_grad, indices_input, kappas_input] = m_diff.program_inputs();
        bool axis_input = m_axis_in_world || axis_grad;
        ProgramKey key{ radiance, components, axis_input, indices_input, kappas_input };
        const bfr::Program &program = m_programs.get(key, [&] {
            const ScalarVector3f &a = m_diff.axis;
            bfr::CrystalRecipe recipe{ 0,
                                       radiance ? bfr::Transport::Radiance
                                                : bfr::Transport::Importance,
                                       components,
                                       (uint32_t) Channels,
                                       !is_polarized_v<Spectrum>,
                                       m_ext_ior,
                                       { a.x(), a.y(), a.z() },
                                       axis_input,
                                       indices_input,
                                       kappas_input };
            return shim::core_call(ClassName, [&] { return bfr::record_crystal(*m_material, recipe); });
        });
        std::vector<Float> x((size_t) In::Wavelength0 + Channels, Float(0.f));
        auto set = [&](In k, const Float &v) { x[(size_t) k] = v; };
        set(In::WiX, si.wi.x());
        set(In::WiY, si.wi.y());
        set(In::WiZ, si.wi.z());
        set(In::Sample, sample1);
        set(In::AxisX, axis.x());
        set(In::AxisY, axis.y());
        set(In::AxisZ, axis.z());
        set(In::EtaO, eta_o);
        set(In::EtaE, eta_e);
        set(In::KappaO, kappa_o);
        set(In::KappaE, kappa_e);
        for (size_t c = 0; c < Channels; ++c) {
            if constexpr (is_spectral_v<Spectrum>)
                x[(size_t) In::Wavelength0 + c] = si.wavelengths[c];
            else
                x[(size_t) In::Wavelength0 + c] = Float((float) m_wavelength);
        }
        shim::Replay<Float> r(program, x);
        return Answer::sample(r, si.wi, radiance, false, m_types, 3, active);
    }

    /// eta_o, eta_e, kappa_o, kappa_e and optic_axis (differentiable in the JIT variants).
    shim::Differentiable<Float> m_diff;
    rust::Box<bfr::Materials> m_material = bfr::new_materials();
    double m_ext_ior;
    bool m_axis_in_world = false;
    std::string m_channel;                ///< the colour channel of a mono variant's render
    double m_wavelength = RgbWavelength;  ///< where the RGB and mono variants evaluate it
    BSDFFlags m_types[(size_t) bfr::Bounds::CrystalComponents];
    mutable std::atomic<bool> m_warned { false };
    std::unique_ptr<shim::Snapshot<Float, Spectrum>> m_valid;  ///< last valid state
    /// The programs of the JIT variants, by ProgramKey.
    mutable shim::Programs<ProgramKey> m_programs;

    MI_TRAVERSE_CB(Base)
};

NAMESPACE_BEGIN(shim)
void register_birefringent() { register_plugin<Birefringent>("birefringent"); }
NAMESPACE_END(shim)

NAMESPACE_END(mitsuba)
