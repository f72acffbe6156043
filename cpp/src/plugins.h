/* What every plugin includes: the parameters, the bridge to the core, the conversion of its
 * lobes, and their registration with Mitsuba's PluginManager in the supported variants.
 */
#pragma once

#include <mitsuba/core/plugin.h>
#include <mitsuba/core/string.h>
#include <mitsuba/render/bsdf.h>
#include <mitsuba/render/texture.h>

#include <atomic>
#include <optional>
#include <sstream>
#include <string>

#include "bridge.h"
#include "lobes.h"
#include "params.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// The variants the plugins work in, comma-separated. In the CUDA variants what runs is the
/// core's recorded programs (replay.h): a plate or a stack only at exact wavelengths (the
/// spectral variants, filter_bandwidth 0), refused at load otherwise (require_kernel_path).
constexpr const char *SupportedVariants =
    "scalar_rgb, scalar_spectral, scalar_spectral_polarized, llvm_ad_rgb, llvm_ad_mono, "
    "llvm_ad_mono_polarized, llvm_ad_spectral, llvm_ad_spectral_polarized, cuda_ad_rgb, "
    "cuda_ad_mono, cuda_ad_mono_polarized, cuda_ad_spectral, cuda_ad_spectral_polarized";

/// Registers `Plugin<Float, Spectrum>` as `name` in `variant`.
template <template <typename, typename> class Plugin, typename Float, typename Spectrum>
void register_variant(PluginManager *pm, const char *name, const char *variant) {
    pm->register_plugin(name, variant, ObjectType::BSDF,
        [](void *, const Properties &p) -> ref<Object> { return new Plugin<Float, Spectrum>(p); },
        nullptr, nullptr);
}

/// The plugin in the JIT variants of `Backend`.
template <template <typename, typename> class Plugin, JitBackend Backend>
void register_jit(PluginManager *pm, const char *name, const char *prefix) {
    using F = dr::DiffArray<Backend, float>;
    std::string p(prefix);
    register_variant<Plugin, F, Color<F, 3>>(pm, name, (p + "rgb").c_str());
    register_variant<Plugin, F, Color<F, 1>>(pm, name, (p + "mono").c_str());
    register_variant<Plugin, F, MuellerMatrix<Color<F, 1>>>(pm, name, (p + "mono_polarized").c_str());
    register_variant<Plugin, F, Spectrum<F, 4>>(pm, name, (p + "spectral").c_str());
    register_variant<Plugin, F, MuellerMatrix<Spectrum<F, 4>>>(pm, name,
                                                             (p + "spectral_polarized").c_str());
}

/// The plugin in every supported variant.
template <template <typename, typename> class Plugin> void register_plugin(const char *name) {
    PluginManager *pm = PluginManager::instance();
    register_variant<Plugin, float, Color<float, 3>>(pm, name, "scalar_rgb");
    register_variant<Plugin, float, Spectrum<float, 4>>(pm, name, "scalar_spectral");
    register_variant<Plugin, float, MuellerMatrix<Spectrum<float, 4>>>(pm, name,
                                                                       "scalar_spectral_polarized");
    register_jit<Plugin, JitBackend::LLVM>(pm, name, "llvm_ad_");
    register_jit<Plugin, JitBackend::CUDA>(pm, name, "cuda_ad_");
}

/// Refuses, at load in a CUDA variant, a plugin whose queries would call the core on the host:
/// a CUDA kernel's lanes live on the device, so only the recorded programs run there
/// (`recorded`: this plugin's queries are the exact element at each sampled wavelength).
template <typename Float, typename Spectrum>
void require_kernel_path(bool recorded, const char *ClassName) {
    if constexpr (dr::is_cuda_v<Float>) {
        if (!recorded)
            Throw("in the CUDA variants a plate or stack runs inside the kernel at exact "
                  "wavelengths only: use cuda_ad_spectral or cuda_ad_spectral_polarized with "
                  "filter_bandwidth 0 (the closed-form integrals over a band or colour channels "
                  "run on the CPU: use the llvm_ad variant for them)");
    }
}

/// Host columns (indices into HostInputs) of what every query of the plugins reads: the active
/// mask, the lobe-choosing sample, `si.wi` and, in the spectral variants, the `waves` sampled
/// wavelengths from `first_wave` on.
struct PathColumns {
    size_t active = 0, sample = 0, wi[3] = { 0, 0, 0 }, first_wave = 0, waves = 0;
};

/// Queues the inputs of PathColumns on `in`.
template <typename Float, typename Spectrum, size_t Inputs, typename Interaction, typename Mask>
PathColumns add_path_inputs(HostInputs<Float, Inputs> &in, const Interaction &si, const Float &sample1,
                            const Mask &active) {
    PathColumns c;
    c.active = in.add_mask(active);
    c.sample = in.add(sample1);
    for (size_t i = 0; i < 3; ++i)
        c.wi[i] = in.add(si.wi[i]);
    if constexpr (is_spectral_v<Spectrum>) {
        c.waves = Answers<Float, Spectrum>::Channels;
        for (size_t w = 0; w < c.waves; ++w) {
            size_t k = in.add(si.wavelengths[w]);
            c.first_wave = w == 0 ? k : c.first_wave;
        }
    }
    return c;
}

/// Lanes [begin, end) of PathColumns into `lanes` (a PlateLanes, StackLanes or CrystalLanes): `count`,
/// `active`, `wi` in input columns `wi_x`, `wi_x + 1`, `wi_x + 2`, `sample` in `wi_x + 3`, and
/// the sampled wavelengths in columns `wave0`, `wave0 + 1`, ... (the caller sets
/// `wavelengths_nm`).
template <typename Lanes, size_t Cap, size_t In, typename Float, size_t Inputs>
void fill_path_lanes(Lanes &lanes, ChunkBuffers<Cap, In> &b, const HostInputs<Float, Inputs> &in,
                     const PathColumns &c, size_t begin, size_t end, size_t wi_x, size_t wave0) {
    lanes.count = end - begin;
    lanes.active = b.convert_mask(in.masks(c.active), begin, end);
    lanes.wi = { b.convert(wi_x, in.floats(c.wi[0]), begin, end).slice(),
                 b.convert(wi_x + 1, in.floats(c.wi[1]), begin, end).slice(),
                 b.convert(wi_x + 2, in.floats(c.wi[2]), begin, end).slice() };
    lanes.sample = b.convert(wi_x + 3, in.floats(c.sample), begin, end).slice();
    for (size_t w = 0; w < c.waves; ++w)
        b.convert(wave0 + w, in.floats(c.first_wave + w), begin, end);
}

/// The spectrum a thin element (a plate or a stack) is queried over in the variant of
/// `Spectrum`: a band of `filter_bandwidth` around each sampled wavelength, the sRGB channels,
/// or the mono variants' `channel` (refused by the core with its reason if unknown).
template <typename Spectrum>
rust::Box<bfr::PlateSpectrum> thin_spectrum(double filter_bandwidth, const std::string &channel,
                                            const char *ClassName) {
    if constexpr (is_spectral_v<Spectrum>)
        return bfr::band_spectrum(filter_bandwidth);
    else if constexpr (is_rgb_v<Spectrum>)
        return bfr::srgb_spectrum();
    else
        return core_call(ClassName, [&] { return bfr::colour_channel_spectrum(channel); });
}

/// The lobe types and BSDF flags of a thin element: delta reflection, and delta transmission
/// (null between equal non-absorbing media, `null`) unless the exit medium absorbs, when only
/// the front side reflects. Between different indices the transmission's Radiance weight
/// carries the radiance factor (n_wi / n_wo)^2 and its Importance weight does not
/// (NonSymmetric; see birefringent.cpp).
inline void thin_flags(bool isotropic, bool null, bool absorbing_exit, bool asymmetric,
                       BSDFFlags (&types)[2], std::vector<uint32_t> &components, uint32_t &flags) {
    uint32_t aniso = isotropic ? 0u : (uint32_t) BSDFFlags::Anisotropic;
    uint32_t sides = (uint32_t) (BSDFFlags::FrontSide | BSDFFlags::BackSide) | aniso;
    types[0] = BSDFFlags::DeltaReflection;
    types[1] = null ? BSDFFlags::Null : BSDFFlags::DeltaTransmission;
    components.clear();
    if (absorbing_exit) {
        components.push_back((uint32_t) types[0] | (uint32_t) BSDFFlags::FrontSide | aniso);
        flags = components[0];
    } else {
        uint32_t asym = asymmetric ? (uint32_t) BSDFFlags::NonSymmetric : 0u;
        components.push_back((uint32_t) types[0] | sides);
        components.push_back((uint32_t) types[1] | sides | asym);
        flags = components[0] | components[1];
    }
}

/// Defined in thinbirefringent.cpp, birefringent.cpp and birefringentstack.cpp.
void register_thinbirefringent();
void register_birefringent();
void register_birefringentstack();

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
