/**!

.. _bsdf-birefringentstack:

Birefringent stack (:monosp:`birefringentstack`)
------------------------------------------------

.. pluginparameters::

 * - (Nested plugins)
   - |bsdf|
   - The layers, in order from the exterior (the side the normal points to) down: one to 16
     ``thinbirefringent`` plates, each with its own ``material`` (or ``eta_o``, ``eta_e``),
     ``kappa_o``, ``kappa_e``, ``optic_axis``, ``thickness`` and ``thickness_scale``,
     ``birefringence`` and ``birefringence_scale``, ``axis_angle`` (textures where the plate takes
     them). A layer may not set ``ext_ior``, ``exit_ior``, ``filter_bandwidth``, ``channel`` or
     ``absorbing_exit``: those are the stack's. Exposed as ``layer_0``, ``layer_1``, ...; in the
     JIT variants each layer's parameters that a plate has differentiable are differentiable
     (``layer_1.thickness.value``, ...).
   - |exposed|, |differentiable|

 * - ext_ior
   - |float| or |string|
   - Real index of the medium on the side the normal points to, a number or a Mitsuba IOR name.
     (Default: ``"air"``, 1.000277)
   - |exposed|

 * - exit_ior
   - |float| or |string|
   - Real index of the medium below the stack. (Default: ``ext_ior``)
   - |exposed|

 * - filter_bandwidth
   - |float|
   - Spectral variants: full width at half maximum (nm) of the Gaussian band around each sampled
     wavelength over which the stack is integrated; 0 (or below 1e-12 of the wavelength) is the
     exact stack at the wavelength; at most a quarter of the wavelength. A band costs many exact
     evaluations of the stack (its round trips within the band's coherence length are resolved
     by quadrature). In the RGB and mono variants a non-zero value is ignored with a warning.
     (Default: 0)
   - |exposed|

 * - channel
   - |string|
   - Mono variants only: the colour channel the stack is integrated over (as
     ``thinbirefringent``'s ``channel``). Refused in the other variants. (Default:
     ``"xyz-d65:Y"``, the luminance)

 * - absorbing_exit
   - |bool|
   - The medium below the stack absorbs all light that enters it (as ``thinbirefringent``'s
     ``absorbing_exit``). (Default: |false|)

A stack of plane-parallel uniaxial or isotropic layers on a surface, like ``thinbirefringent``
(no geometric thickness in the scene; component 0 the specular reflection, component 1 the
transmission, ``Null`` when ``exit_ior == ext_ior``): zero-order and achromatic waveplates,
Lyot filters, cellophane tape in layers. Every internal path of every layer is summed (the
core's scattering-matrix recursion, docs/physics.md section 8), with uniaxial/uniaxial
interfaces solved exactly, from either side and in both transport modes. In ``scalar_rgb`` and
the mono variants the stack is integrated over the channels, the round trips of layers thicker
than the channels' coherence length summed incoherently. Textures of the nested plates are
evaluated with ``eval_1`` at the hit point.

.. tabs::
    .. code-tab:: xml
        :name: birefringentstack-zero-order

        <bsdf type="birefringentstack">
            <bsdf type="thinbirefringent">
                <string name="material" value="quartz"/>
                <float name="thickness" value="1015.0"/>
            </bsdf>
            <bsdf type="thinbirefringent">
                <string name="material" value="quartz"/>
                <vector name="optic_axis" value="0, 1, 0"/>
                <float name="thickness" value="1000.0"/>
            </bsdf>
        </bsdf>

    .. code-tab:: python

        'type': 'birefringentstack',
        'tape_1': {'type': 'thinbirefringent', 'eta_o': 1.47, 'eta_e': 1.477, 'thickness': 40.0},
        'tape_2': {'type': 'thinbirefringent', 'eta_o': 1.47, 'eta_e': 1.477, 'thickness': 40.0,
                   'axis_angle': 45.0}
*/
#include "plugins.h"
#include "recorded.h"
#include "last_valid.h"
#include "layer.h"
#include "signed_rgb.h"

NAMESPACE_BEGIN(mitsuba)

template <typename Float, typename Spectrum>
class BirefringentStack final : public BSDF<Float, Spectrum> {
public:
    MI_IMPORT_BASE(BSDF, m_flags, m_components)
    MI_IMPORT_TYPES(Texture)
    using Answers = shim::Answers<Float, Spectrum>;
    using Vec3d = typename Answers::Vec3d;
    using Layer = shim::PlateLayer<Float, Spectrum>;
    using Source = shim::LayerSource<Float, Spectrum>;

    /// Most layers of one stack.
    static constexpr size_t MaxLayers = 16;

    BirefringentStack(const Properties &props) : Base(props) {
        for (const auto &prop : props.objects()) {
            Base *bsdf = prop.template try_get<Base>();
            Source *source = dynamic_cast<Source *>(bsdf);
            if (!source)
                Throw("the nested object \"%s\" is not a thinbirefringent plate: the layers of a "
                      "stack are thinbirefringent BSDFs, nested in order from the exterior (the "
                      "side the normal points to) down", prop.name());
            if (m_layers.size() == MaxLayers)
                Throw("a stack holds at most %d layers (thinbirefringent plates)", MaxLayers);
            source->nest();
            m_layers.push_back(bsdf);
            m_sources.push_back(source);
            m_names.push_back("layer_" + std::to_string(m_names.size()));
        }
        if (m_layers.empty())
            Throw("a stack needs at least one layer: nest thinbirefringent plates in it, in "
                  "order from the exterior down");
        m_ext_ior = shim::parse_ior(props, "ext_ior", "air", ClassName);
        m_exit_ior = props.has_property("exit_ior")
                         ? shim::parse_ior(props, "exit_ior", "air", ClassName)
                         : m_ext_ior;
        m_filter_bandwidth = shim::parse_filter_bandwidth<Spectrum>(props, ClassName);
        m_absorbing_exit = props.get<bool>("absorbing_exit", false);
        m_channel = shim::parse_channel<Spectrum>(props, ClassName);
        parameters_changed();
    }

    void traverse(TraversalCallback *cb) override {
        cb->put("ext_ior", m_ext_ior, ParamFlags::NonDifferentiable);
        cb->put("exit_ior", m_exit_ior, ParamFlags::NonDifferentiable);
        cb->put("filter_bandwidth", m_filter_bandwidth, ParamFlags::NonDifferentiable);
        // The layers' own parameters (differentiable as a plate's: the JIT spectral variants
        // replay the stack's program with Dr.Jit's derivatives).
        for (size_t k = 0; k < m_layers.size(); ++k)
            cb->put(m_names[k], m_layers[k], shim::texture_flags<Float>());
    }

    /// Applies changed parameters (the stack's or its layers'); a rejected update leaves the last
    /// valid state in force (shim::update_or_restore, the layers' values included).
    void parameters_changed(const std::vector<std::string> & /*keys*/ = {}) override {
        shim::update_or_restore<Float, Spectrum>(this, m_valid, [this] { rebuild(); });
    }

private:
    /// Rebuilds the core's material table (one material per layer), the spectrum and the flags
    /// from the layers' current parameters, and checks everything with one core query (textures
    /// at their mean, normal incidence, 550 nm, the filter band).
    void rebuild() {
        m_material = bfr::new_materials();
        m_axes.clear();
        bool isotropic = true;
        for (size_t k = 0; k < m_sources.size(); ++k) {
            Layer l = m_sources[k]->layer();
            if (!l.surroundings->empty())
                Throw("layer %d (%s) sets \"%s\": the media around a stack and how it is "
                      "integrated are the stack's parameters; set it on the birefringentstack",
                      k, m_names[k], l.surroundings->front());
            std::string what = "layer " + std::to_string(k) + ": ";
            uint32_t index = shim::add_material(*m_material, *l.material, what, ClassName);
            isotropic &= m_material->is_isotropic(index) && !l.birefringence;
            m_axes.push_back({ (double) l.optic_axis.x(), (double) l.optic_axis.y(),
                               (double) l.optic_axis.z() });
        }
        m_material_index.resize(m_sources.size());
        for (size_t k = 0; k < m_sources.size(); ++k)
            m_material_index[k] = (uint32_t) k;
        m_band = bfr::band_spectrum(m_filter_bandwidth);
        shim::require_kernel_path<Float, Spectrum>(is_spectral_v<Spectrum> && m_filter_bandwidth == 0.0,
                                                   ClassName);
        m_spectrum = shim::thin_spectrum<Spectrum>(m_filter_bandwidth, m_channel, ClassName);
        m_null = m_exit_ior == m_ext_ior && !m_absorbing_exit;
        shim::thin_flags(isotropic, m_null, m_absorbing_exit, m_exit_ior != m_ext_ior, m_types,
                         m_components, m_flags);
        check_at_load();
        m_programs.clear();
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

    std::string to_string() const override {
        std::ostringstream oss;
        oss << "BirefringentStack[" << std::endl
            << "  ext_ior = " << m_ext_ior << ", exit_ior = " << m_exit_ior << "," << std::endl
            << "  filter_bandwidth = " << m_filter_bandwidth << " (nm FWHM, spectral variants),"
            << std::endl
            << "  absorbing_exit = " << (m_absorbing_exit ? "true" : "false") << "," << std::endl;
        if constexpr (is_monochromatic_v<Spectrum>)
            oss << "  channel = \"" << m_channel << "\"," << std::endl;
        for (size_t k = 0; k < m_layers.size(); ++k)
            oss << "  " << m_names[k] << " = " << string::indent(m_layers[k]) << ","
                << std::endl;
        oss << "]";
        return oss.str();
    }

    MI_DECLARE_CLASS(BirefringentStack)

private:
    /// Input columns of a core query (indices into shim::ChunkBuffers::in): the path's, then
    /// three per layer from PerLayer on (thickness, birefringence, axis angle).
    enum Column : size_t { WiX, WiY, WiZ, Sample, ExtIor, ExitIor, Wavelength0, PerLayer = 10 };
    static_assert(WiY == WiX + 1 && WiZ == WiX + 2 && Sample == WiX + 3, "shim::fill_path_lanes");
    static_assert(PerLayer >= Wavelength0 + shim::MaxChannels, "wavelength columns");
    /// Most inputs: the path's (mask aside: sample, wi, 4 wavelengths) and three per layer.
    static constexpr size_t Inputs = PerLayer + 3 * MaxLayers;

    /// One layer's scalar: input column `input` of the host inputs (a texture that varies over
    /// the surface), or the same `value` for every lane.
    struct Scalar {
        bool varying = false;
        size_t input = 0;
        double value = 0.0;
    };

    /// `texture` (none: `fallback`) as a Scalar: queued on `in` if it varies over the surface.
    template <typename In>
    Scalar scalar(In &in, const Texture *texture, double fallback, const SurfaceInteraction3f &si,
                  const Mask &active) const {
        Scalar s;
        if (!texture) {
            s.value = fallback;
        } else if (texture->is_spatially_varying()) {
            s.varying = true;
            s.input = in.add(texture->eval_1(si, active));
        } else {
            s.value = shim::scalar(texture->mean());
        }
        return s;
    }

    /// The core's per-call settings.
    bfr::PlateCall call(uint32_t components) const {
        return { components, !is_polarized_v<Spectrum>, m_absorbing_exit };
    }

    /// The optic axes of the layers as three columns of one value per layer.
    std::array<rust::Slice<const double>, 3> axes(std::array<std::vector<double>, 3> &storage) const {
        for (size_t c = 0; c < 3; ++c) {
            storage[c].resize(m_axes.size());
            for (size_t k = 0; k < m_axes.size(); ++k)
                storage[c][k] = m_axes[k][c];
        }
        return { rust::Slice<const double>(storage[0].data(), storage[0].size()),
                 rust::Slice<const double>(storage[1].data(), storage[1].size()),
                 rust::Slice<const double>(storage[2].data(), storage[2].size()) };
    }

    /// One core query at normal incidence with every texture at its mean and the filter band
    /// at 550 nm; throws its message.
    void check_at_load() const {
        shim::ChunkBuffers<1, Inputs> b;
        const uint8_t one = 1;
        const bfr::Transport radiance = bfr::Transport::Radiance;
        const double u = 0.5, lambda = 550.0;
        rust::Slice<const double> wave(&lambda, 1);
        bfr::StackLanes lanes{};
        lanes.count = 1;
        lanes.active = { &one, 1 };
        lanes.transport = { &radiance, 1 };
        lanes.sample = { &u, 1 };
        lanes.wi = { b.constant(WiX, 0.0).slice(), b.constant(WiY, 0.0).slice(),
                     b.constant(WiZ, 1.0).slice() };
        lanes.wavelengths_nm = { &wave, 1 };
        lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
        lanes.exit_ior = b.constant(ExitIor, m_exit_ior).slice();
        std::array<std::vector<double>, 3> axis_storage;
        lanes.optic_axis = axes(axis_storage);
        lanes.material = { m_material_index.data(), m_material_index.size() };
        std::array<rust::Slice<const double>, MaxLayers> thick, biref, angle;
        auto mean = [](const Texture *t) { return t ? shim::scalar(t->mean()) : 0.0; };
        for (size_t k = 0; k < m_sources.size(); ++k) {
            Layer l = m_sources[k]->layer();
            size_t col = PerLayer + 3 * k;
            thick[k] = b.constant(col, 1000.0 * l.thickness_scale * mean(l.thickness)).slice();
            biref[k] = b.constant(col + 1, l.birefringence_scale * mean(l.birefringence)).slice();
            angle[k] = b.constant(col + 2, mean(l.axis_angle)).slice();
        }
        size_t n = m_sources.size();
        lanes.thickness_nm = { thick.data(), n };
        lanes.birefringence = { biref.data(), n };
        lanes.axis_angle_deg = { angle.data(), n };
        bfr::Samples s = b.samples(1, 1, true);
        bfr::Status rc = bfr::sample_stack(*m_material, *m_band, call(3u), lanes, s);
        if (rc != bfr::Status::Ok)
            Throw("%s", shim::core_message(rc, s.message));
    }

    /** The core's lobe for every lane of `si` (see thinbirefringent.cpp's `query`). */
    Answers query(const SurfaceInteraction3f &si, TransportMode mode, uint32_t components,
                  const Float &sample1, const Mask &active, bool straight) const {
        shim::require_evaluated_mode<Float>(ClassName, "filter_bandwidth = 0 in a spectral variant");
        shim::HostInputs<Float, Inputs> in;
        const shim::PathColumns path = shim::add_path_inputs<Float, Spectrum>(in, si, sample1, active);
        const size_t n_layers = m_sources.size();
        std::array<std::array<Scalar, 3>, MaxLayers> scalars;
        std::array<std::array<double, 3>, MaxLayers> scales;
        for (size_t k = 0; k < n_layers; ++k) {
            Layer l = m_sources[k]->layer();
            auto value = [&](const Texture *t) { return t ? t->eval_1(si, active) : Float(0.f); };
            shim::refuse_gradients(ClassName, *m_spectrum, si.wi, value(l.thickness),
                                   value(l.birefringence), value(l.axis_angle), l.diff->eta_o(),
                                   l.diff->eta_e(), l.diff->kappa_o(), l.diff->kappa_e(),
                                   l.diff->optic_axis());
            scalars[k] = { scalar(in, l.thickness, 0.0, si, active),
                           scalar(in, l.birefringence, 0.0, si, active),
                           scalar(in, l.axis_angle, 0.0, si, active) };
            scales[k] = { 1000.0 * l.thickness_scale, l.birefringence_scale, 1.0 };
        }
        const size_t waves = path.waves;
        Answers answers;
        size_t n = in.width();
        answers.allocate(n);
        in.read();

        bool radiance = mode == TransportMode::Radiance;
        bfr::Transport transport = radiance ? bfr::Transport::Radiance : bfr::Transport::Importance;
        bfr::PlateCall settings = call(components);
        size_t channels = m_spectrum->channels(waves);
        std::array<std::vector<double>, 3> axis_storage;
        const std::array<rust::Slice<const double>, 3> optic_axis = axes(axis_storage);
        std::string failure = shim::for_chunks<Float>(n, [&](size_t begin, size_t end) {
            shim::ChunkStorage<Float, Inputs> storage;
            auto &b = *storage;
            bfr::StackLanes lanes{};
            shim::fill_path_lanes(lanes, b, in, path, begin, end, WiX, Wavelength0);
            lanes.transport = { &transport, 1 };
            lanes.wavelengths_nm = b.wavelength_columns(Wavelength0, waves);
            lanes.ext_ior = b.constant(ExtIor, m_ext_ior).slice();
            lanes.exit_ior = b.constant(ExitIor, m_exit_ior).slice();
            lanes.material = { m_material_index.data(), n_layers };
            lanes.optic_axis = optic_axis;
            std::array<std::array<rust::Slice<const double>, MaxLayers>, 3> columns;
            for (size_t k = 0; k < n_layers; ++k)
                for (size_t q = 0; q < 3; ++q) {
                    const Scalar &s = scalars[k][q];
                    size_t col = PerLayer + 3 * k + q;
                    double scale = scales[k][q];
                    columns[q][k] =
                        s.varying
                            ? b.convert(col, in.floats(s.input), begin, end,
                                        [scale](double x) { return scale * x; }).slice()
                            : b.constant(col, scale * s.value).slice();
                }
            lanes.thickness_nm = { columns[0].data(), n_layers };
            lanes.birefringence = { columns[1].data(), n_layers };
            lanes.axis_angle_deg = { columns[2].data(), n_layers };
            bfr::Samples s = b.samples(lanes.count, channels, is_polarized_v<Spectrum>);
            bfr::Status rc = bfr::sample_stack(*m_material, *m_spectrum, settings, lanes, s);
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

    /// The variants where a query can be the exact stack at each sampled wavelength, recorded
    /// by the core as a program replayed inside Mitsuba's kernels (the JIT spectral variants,
    /// with filter_bandwidth 0); the other JIT queries call the core on the host.
    static constexpr bool Recordable = dr::is_jit_v<Float> && is_spectral_v<Spectrum>;

    /// The key of a program: the transport mode, the enabled components and, per layer, which
    /// of its parameters carry derivatives (bits: axis, indices, extinctions).
    using ProgramKey = std::tuple<bool, uint32_t, std::vector<uint8_t>>;

    /// The sample of the program of this setting, replayed on the lanes of `si` (recorded.h).
    std::pair<BSDFSample3f, Spectrum> replayed(const SurfaceInteraction3f &si,
                                               TransportMode mode, uint32_t components,
                                               const Float &sample1, const Mask &active,
                                               bool straight) const {
        using In = bfr::StackInput;
        using LayerIn = bfr::StackLayerInput;
        using Answer = shim::Replayed<Float, Spectrum>;
        constexpr size_t Channels = Answer::Channels;
        const size_t n_layers = m_sources.size();
        bool radiance = mode == TransportMode::Radiance;
        std::vector<Layer> layers;
        std::vector<uint8_t> inputs;
        for (size_t k = 0; k < n_layers; ++k) {
            Layer l = m_sources[k]->layer();
            auto [axis, indices, kappas] = l.diff->program_inputs();
            inputs.push_back((axis ? 1 : 0) | (indices ? 2 : 0) | (kappas ? 4 : 0));
            layers.push_back(l);
        }
        ProgramKey key{ radiance, components, inputs };
        const bfr::Program &program = m_programs.get(key, [&] {
            bfr::StackRecipe recipe{ radiance ? bfr::Transport::Radiance
                                              : bfr::Transport::Importance,
                                     components,
                                     (uint32_t) Channels,
                                     !is_polarized_v<Spectrum>,
                                     m_absorbing_exit,
                                     m_ext_ior,
                                     m_exit_ior,
                                     {} };
            for (size_t k = 0; k < n_layers; ++k) {
                const Layer &l = layers[k];
                const auto &a = l.optic_axis;
                recipe.layers.push_back(bfr::StackLayerRecipe{
                    m_material_index[k], l.thickness_scale, l.birefringence != nullptr,
                    l.birefringence_scale, l.axis_angle != nullptr,
                    { (double) a.x(), (double) a.y(), (double) a.z() }, (inputs[k] & 1) != 0,
                    (inputs[k] & 2) != 0, (inputs[k] & 4) != 0 });
            }
            return shim::core_call(ClassName, [&] { return bfr::record_stack(*m_material, recipe); });
        });
        const size_t stride = (size_t) LayerIn::Stride, first = (size_t) In::Layer0;
        std::vector<Float> x(first + stride * n_layers, Float(0.f));
        x[(size_t) In::WiX] = si.wi.x();
        x[(size_t) In::WiY] = si.wi.y();
        x[(size_t) In::WiZ] = si.wi.z();
        x[(size_t) In::Sample] = sample1;
        if constexpr (is_spectral_v<Spectrum>)
            for (size_t c = 0; c < Channels; ++c)
                x[(size_t) In::Wavelength0 + c] = si.wavelengths[c];
        for (size_t k = 0; k < n_layers; ++k) {
            const Layer &l = layers[k];
            auto set = [&](LayerIn i, const Float &v) { x[first + stride * k + (size_t) i] = v; };
            set(LayerIn::Thickness, l.thickness->eval_1(si, active));
            if (l.birefringence)
                set(LayerIn::Birefringence, l.birefringence->eval_1(si, active));
            if (l.axis_angle)
                set(LayerIn::AxisAngle, l.axis_angle->eval_1(si, active));
            Vector3f axis = l.diff->optic_axis();
            set(LayerIn::AxisX, axis.x());
            set(LayerIn::AxisY, axis.y());
            set(LayerIn::AxisZ, axis.z());
            set(LayerIn::EtaO, l.diff->eta_o());
            set(LayerIn::EtaE, l.diff->eta_e());
            set(LayerIn::KappaO, l.diff->kappa_o());
            set(LayerIn::KappaE, l.diff->kappa_e());
        }
        shim::Replay<Float> r(program, x);
        return Answer::sample(r, si.wi, radiance, straight, m_types, 2, active);
    }

    std::vector<ref<Base>> m_layers;
    std::vector<Source *> m_sources;  ///< the layers as LayerSource (the same objects)
    std::vector<std::string> m_names;  ///< layer_0, layer_1, ...
    std::vector<std::array<double, 3>> m_axes;
    std::vector<uint32_t> m_material_index;
    rust::Box<bfr::Materials> m_material = bfr::new_materials();
    rust::Box<bfr::PlateSpectrum> m_spectrum = bfr::exact_spectrum(), m_band = bfr::exact_spectrum();
    double m_ext_ior, m_exit_ior, m_filter_bandwidth;
    std::string m_channel;
    bool m_null = true, m_absorbing_exit = false;
    BSDFFlags m_types[(size_t) bfr::Bounds::PlateComponents];
    mutable std::atomic<bool> m_warned { false };
    shim::SignedRgbGuard m_signed_rgb { is_rgb_v<Spectrum> && !dr::is_jit_v<Float> };
    std::unique_ptr<shim::Snapshot<Float, Spectrum>> m_valid;
    /// The programs of the JIT spectral variants (Recordable), by ProgramKey.
    mutable shim::Programs<ProgramKey> m_programs;
};

NAMESPACE_BEGIN(shim)
void register_birefringentstack() { register_plugin<BirefringentStack>("birefringentstack"); }
NAMESPACE_END(shim)

NAMESPACE_END(mitsuba)
