/* Shared helpers of the two Mitsuba 3 BSDF plugins (thinbirefringent.cpp, birefringent.cpp).
 *
 * The shim only converts: Mitsuba properties -> the core's parameters, Mitsuba queries -> core
 * queries, and the core's lobes -> Mitsuba's BSDFSample3f/Spectrum (lobe selection by weight,
 * Stokes-frame rotation into Mitsuba's implicit frames). All optics is in the Rust core behind
 * cpp/include/birefringent.h. Only the scalar variants are instantiated (see register.cpp).
 */
#pragma once

#include <optional>
#include <mitsuba/core/plugin.h>
#include <mitsuba/core/properties.h>
#include <mitsuba/core/string.h>
#include <mitsuba/render/bsdf.h>
#include <mitsuba/render/ior.h>
#include <mitsuba/render/mueller.h>
#include <mitsuba/render/texture.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "birefringent.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(bfr)

/// Size of the buffers receiving the core's error messages.
constexpr size_t MessageLen = 1024;

/// Variants the plugins are compiled for.
constexpr const char *SupportedVariants = "scalar_rgb, scalar_spectral, scalar_spectral_polarized";

/// Lobes of the same component at two wavelengths whose directions (unit vectors) are closer
/// than this (|a - b|, ~radians) can be the same lobe shifted by dispersion (see Lobes::sample).
constexpr double MatchDistance = 0.2;

/// Owning handle of the core's immutable material.
using MaterialPtr = std::shared_ptr<const bfr_material>;

/// The material parameters as given in the scene description.
struct MaterialParams {
    bool named = true;     ///< a named crystal (`material`), else constant indices
    std::string material;  ///< the crystal's name as given (the core refuses an unknown one)
    double eta_o = 0, eta_e = 0, kappa_o = 0, kappa_e = 0;

    /// Constant, equal principal indices: the medium is isotropic (the core then returns the
    /// refracted light as one s/p lobe, component 1).
    bool isotropic() const {
        return !named && eta_o == eta_e && kappa_o == kappa_e;
    }

    std::string to_string() const {
        std::ostringstream oss;
        if (named)
            oss << "material = \"" << material << "\", ";
        else
            oss << "eta_o = " << eta_o << ", eta_e = " << eta_e << ", ";
        oss << "kappa_o = " << kappa_o << ", kappa_e = " << kappa_e;
        return oss.str();
    }
};

/// The core's error message, or its code when the message is empty.
inline std::string core_error(int32_t rc, const char *message) {
    if (message && message[0])
        return message;
    return "error code " + std::to_string(rc) + " from the birefringent core";
}

/* The functions below take `ClassName` as a parameter so that Mitsuba's Throw/Log macros, which
   refer to a variable of that name, tag their messages with the plugin's class. */

/// `material` (string) or `eta_o` + `eta_e` (floats); `kappa_o`, `kappa_e` (floats, default 0).
/// Without either, the material is "calcite". Values are checked by the core, not here.
inline MaterialParams parse_material(const Properties &props, const char *ClassName) {
    MaterialParams m;
    bool has_o = props.has_property("eta_o"), has_e = props.has_property("eta_e");
    if (props.has_property("material") && (has_o || has_e))
        Throw("give either \"material\" or \"eta_o\" and \"eta_e\", not both");
    if (has_o != has_e)
        Throw("\"%s\" is missing (\"%s\" is given): give both eta_o and eta_e, or \"material\"",
              has_o ? "eta_e" : "eta_o", has_o ? "eta_o" : "eta_e");
    if (has_o) {
        m.named = false;
        m.eta_o = props.get<double>("eta_o");
        m.eta_e = props.get<double>("eta_e");
    } else {
        m.material = props.get<std::string>("material", "calcite");
    }
    m.kappa_o = props.get<double>("kappa_o", 0.0);
    m.kappa_e = props.get<double>("kappa_e", 0.0);
    return m;
}

/// Builds the core's material; throws the core's message (it names the parameter).
inline MaterialPtr make_material(const MaterialParams &p, const char *ClassName) {
    bfr_material_desc desc{};
    desc.material = p.named ? p.material.c_str() : nullptr;
    desc.eta_o = { p.eta_o, 0.0 };
    desc.eta_e = { p.eta_e, 0.0 };
    desc.kappa_o = p.kappa_o;
    desc.kappa_e = p.kappa_e;
    char message[MessageLen] = { 0 };
    bfr_material *m = bfr_material_new(&desc, message, sizeof(message));
    if (!m)
        Throw("%s", core_error(BFR_INVALID, message));
    if (message[0])
        Log(Warn, "%s", message);
    return MaterialPtr(m, [](const bfr_material *x) { bfr_material_free(const_cast<bfr_material *>(x)); });
}

/// An index of refraction: a number, or one of Mitsuba's IOR names (`lookup_ior`).
inline double parse_ior(const Properties &props, const std::string &name,
                        const std::string &default_name, const char *ClassName) {
    if (props.has_property(name)) {
        auto type = props.type(name);
        if (type == Properties::Type::Float || type == Properties::Type::Integer)
            return props.get<double>(name);
        if (type != Properties::Type::String)
            Throw("\"%s\" must be a float (a real index) or one of Mitsuba's IOR names (e.g. "
                  "\"water\"), got %s", name, property_type_name(type));
    }
    try {
        return (double) lookup_ior(props, name, default_name);
    } catch (const std::exception &e) {
        Throw("\"%s\": %s", name, e.what());
    }
}

/// Rotates `v` about the local normal (z) by `degrees`, counter-clockwise seen from +z
/// (from the tangent s towards t).
inline void rotate_about_normal(const double v[3], double degrees, double out[3]) {
    double a = degrees * (M_PI / 180.0), c = std::cos(a), s = std::sin(a);
    out[0] = c * v[0] - s * v[1];
    out[1] = s * v[0] + c * v[1];
    out[2] = v[2];
}

/// Conversion of the core's lobes into Mitsuba samples and spectra, for one variant.
template <typename Float, typename Spectrum> struct Lobes {
    MI_IMPORT_TYPES()
    static_assert(!dr::is_jit_v<Float>, "only the scalar variants are supported");

    /// Number of channels per query: 3 (RGB) or 4 (sampled wavelengths).
    static constexpr size_t Channels = dr::size_v<UnpolarizedSpectrum>;

    using Vec3d = mitsuba::Vector<double, 3>;
    using Mueller4d = mitsuba::MuellerMatrix<double>;

    static Vec3d v3(const double *v) { return Vec3d(v[0], v[1], v[2]); }
    static Vec3d v3(const Vector3f &v) { return Vec3d(v.x(), v.y(), v.z()); }

    /// The rotations that express a lobe's physical Mueller matrix (core frames in_stokes_x ->
    /// out_stokes_x) in Mitsuba's implicit frames stokes_basis(-wo_hat) -> stokes_basis(wi_hat),
    /// where (wo_hat, wi_hat) = (wo, wi) in Radiance mode and (wi, wo) in Importance mode: the
    /// matrix is R_out M R_in^T (mueller::rotate_mueller_basis). `wo` is the direction handed
    /// to Mitsuba (float), so the frames are exactly the integrator's.
    struct Frames {
        double in_x[3], out_x[3];
        Mueller4d r_out, r_in_t;

        Frames(const bfr_path_lobe &l, const Vector3f &wi, const Vector3f &wo, bool radiance) {
            for (int k = 0; k < 3; ++k) {
                in_x[k] = l.in_stokes_x[k];
                out_x[k] = l.out_stokes_x[k];
            }
            Vec3d wo_hat = v3(radiance ? wo : wi), wi_hat = v3(radiance ? wi : wo);
            Vec3d k_in = -wo_hat;
            r_in_t = dr::transpose(mueller::rotate_stokes_basis(k_in, v3(l.in_stokes_x),
                                                                mueller::stokes_basis(k_in)));
            r_out = mueller::rotate_stokes_basis(wi_hat, v3(l.out_stokes_x),
                                                 mueller::stokes_basis(wi_hat));
        }

        /// True if lobe `l` has the same core frames (then the same rotations apply).
        bool fits(const bfr_path_lobe &l) const {
            for (int k = 0; k < 3; ++k)
                if (in_x[k] != l.in_stokes_x[k] || out_x[k] != l.out_stokes_x[k])
                    return false;
            return true;
        }

        Mueller4d apply(const bfr_path_lobe &l) const {
            Mueller4d M;
            for (size_t r = 0; r < 4; ++r)
                for (size_t c = 0; c < 4; ++c)
                    M(r, c) = l.mueller[4 * r + c];
            return r_out * M * r_in_t;
        }
    };

    /// Spectrum of one lobe: channel ch takes lobes[ch * n_lobes + pick[ch]] times `scale`, or 0
    /// where pick[ch] < 0. Unpolarised variants use the weight (M00) only. Polarised variants
    /// rotate each channel's Mueller matrix into Mitsuba's frames; channels whose lobes share
    /// the core frames (all of them unless a crystal's o/e frames differ per wavelength) share
    /// the rotations.
    static Spectrum spectrum(const bfr_path_lobe *lobes, size_t n_lobes, const int *pick,
                             double scale, const Vector3f &wi, const Vector3f &wo, bool radiance) {
        if constexpr (is_polarized_v<Spectrum>) {
            Spectrum out = dr::zeros<Spectrum>();
            std::optional<Frames> frames;
            for (size_t ch = 0; ch < Channels; ++ch) {
                if (pick[ch] < 0)
                    continue;
                const bfr_path_lobe &l = lobes[ch * n_lobes + pick[ch]];
                if (!frames || !frames->fits(l))
                    frames.emplace(l, wi, wo, radiance);
                Mueller4d M = frames->apply(l);
                for (size_t r = 0; r < 4; ++r)
                    for (size_t c = 0; c < 4; ++c)
                        out(r, c)[ch] = (ScalarFloat) (M(r, c) * scale);
            }
            return out;
        } else {
            UnpolarizedSpectrum out = dr::zeros<UnpolarizedSpectrum>();
            for (size_t ch = 0; ch < Channels; ++ch)
                if (pick[ch] >= 0)
                    out[ch] = (ScalarFloat) (lobes[ch * n_lobes + pick[ch]].weight * scale);
            return out;
        }
    }

    static double distance(const bfr_path_lobe &a, const bfr_path_lobe &b) {
        double d2 = 0.0;
        for (int k = 0; k < 3; ++k)
            d2 += (a.wo[k] - b.wo[k]) * (a.wo[k] - b.wo[k]);
        return std::sqrt(d2);
    }

    /** Picks one lobe among those the context enables and returns Mitsuba's sample.
     *
     * lobes[ch * n_lobes + j]: lobe j of channel ch (a sampled wavelength, or an RGB channel;
     * unused slots have exists = 0); `types[k]` is the BSDFFlags lobe type of component k.
     *
     * The channels' lobes are first grouped into candidates: the same lobe at different
     * wavelengths, i.e. the same component and the nearest direction (one-to-one, closer than
     * MatchDistance). Without dispersion they have identical directions. A candidate is
     * picked with probability proportional to its weight (M00) summed over the channels; the
     * ray follows the direction of the candidate's first channel (the hero wavelength), and
     * every channel carries its own lobe's Mueller matrix divided by the probability, so that
     * each channel's expectation is the sum of its lobes, exactly.
     *
     * Dispersion: when a lobe's direction depends on the wavelength (refraction into a named
     * crystal), the other wavelengths are propagated along the hero's direction: their
     * Fresnel, polarisation, o/e split and radiance factor are exact, their angular dispersion
     * (~0.5 degrees over the visible for calcite) is neglected. Following each wavelength's own
     * direction would need the integrator to drop the other wavelengths from the path once
     * (hero-wavelength termination); a BSDF that zeroes and rescales them itself over-counts
     * every further dispersive event of the path.
     *
     * Returns a zero spectrum when nothing can be sampled. */
    static std::pair<BSDFSample3f, Spectrum>
    sample(const BSDFContext &ctx, const SurfaceInteraction3f &si, Float sample1,
           const bfr_path_lobe *lobes, size_t n_lobes, const BSDFFlags *types,
           size_t n_components) {
        BSDFSample3f bs = dr::zeros<BSDFSample3f>();
        constexpr size_t MaxLobes = 8, MaxCandidates = MaxLobes * Channels;
        struct Candidate {
            size_t anchor;         // index into lobes[] of the lobe giving the direction
            int idx[Channels];     // lobe slot per channel, or -1
            double weight;
        };
        Candidate cand[MaxCandidates];
        size_t n_cand = 0;
        n_lobes = std::min(n_lobes, MaxLobes);

        auto usable = [&](const bfr_path_lobe &l) {
            return l.exists && l.component >= 0 && (size_t) l.component < n_components &&
                   ctx.is_enabled(types[l.component], (uint32_t) l.component);
        };
        for (size_t ch = 0; ch < Channels; ++ch) {
            const bfr_path_lobe *lc = lobes + ch * n_lobes;
            bool taken[MaxLobes] = { false };
            // Match the existing candidates, closest pairs first (one-to-one).
            for (;;) {
                double best = MatchDistance;
                size_t bk = MaxCandidates, bj = MaxLobes;
                for (size_t k = 0; k < n_cand; ++k) {
                    if (cand[k].idx[ch] >= 0)
                        continue;
                    const bfr_path_lobe &a = lobes[cand[k].anchor];
                    for (size_t j = 0; j < n_lobes; ++j) {
                        if (taken[j] || !usable(lc[j]) || lc[j].component != a.component)
                            continue;
                        double d = distance(a, lc[j]);
                        if (d < best) {
                            best = d;
                            bk = k;
                            bj = j;
                        }
                    }
                }
                if (bk == MaxCandidates)
                    break;
                cand[bk].idx[ch] = (int) bj;
                taken[bj] = true;
            }
            // The remaining lobes start new candidates.
            for (size_t j = 0; j < n_lobes; ++j) {
                if (taken[j] || !usable(lc[j]) || n_cand == MaxCandidates)
                    continue;
                Candidate &c = cand[n_cand++];
                c.anchor = ch * n_lobes + j;
                for (size_t x = 0; x < Channels; ++x)
                    c.idx[x] = -1;
                c.idx[ch] = (int) j;
            }
        }

        double total = 0.0;
        for (size_t k = 0; k < n_cand; ++k) {
            cand[k].weight = 0.0;
            for (size_t ch = 0; ch < Channels; ++ch)
                if (cand[k].idx[ch] >= 0)
                    cand[k].weight += std::max(lobes[ch * n_lobes + cand[k].idx[ch]].weight, 0.0);
            total += cand[k].weight;
        }
        if (!(total > 0.0))
            return { bs, dr::zeros<Spectrum>() };

        // Discrete choice by the CDF of the weights.
        double u = (double) sample1 * total, acc = 0.0;
        size_t pick = 0;
        for (size_t k = 0; k < n_cand; ++k) {
            if (!(cand[k].weight > 0.0))
                continue;
            pick = k;  // the last candidate with weight catches u == total (rounding)
            acc += cand[k].weight;
            if (u < acc)
                break;
        }
        double p = cand[pick].weight / total;

        const bfr_path_lobe &hero = lobes[cand[pick].anchor];
        bs.wo = Vector3f((ScalarFloat) hero.wo[0], (ScalarFloat) hero.wo[1], (ScalarFloat) hero.wo[2]);
        bs.pdf = (Float) p;
        bs.eta = (Float) hero.eta;
        bs.sampled_component = (UInt32) (uint32_t) hero.component;
        bs.sampled_type = (UInt32) (uint32_t) types[hero.component];
        bool radiance = ctx.mode == TransportMode::Radiance;
        return { bs, spectrum(lobes, n_lobes, cand[pick].idx, 1.0 / p, si.wi, bs.wo, radiance) };
    }
};

/// Instantiation of a plugin in the scalar variants; JIT variants get a clear error.
template <template <typename, typename> class Plugin>
void register_plugin(const char *name) {
    PluginManager *pm = PluginManager::instance();
    pm->register_plugin(name, "scalar_rgb", ObjectType::BSDF,
        [](void *, const Properties &p) -> ref<Object> { return new Plugin<float, Color<float, 3>>(p); },
        nullptr, nullptr);
    pm->register_plugin(name, "scalar_spectral", ObjectType::BSDF,
        [](void *, const Properties &p) -> ref<Object> { return new Plugin<float, Spectrum<float, 4>>(p); },
        nullptr, nullptr);
    pm->register_plugin(name, "scalar_spectral_polarized", ObjectType::BSDF,
        [](void *, const Properties &p) -> ref<Object> {
            return new Plugin<float, MuellerMatrix<Spectrum<float, 4>>>(p);
        },
        nullptr, nullptr);
    static const char *jit_variants[] = {
        "llvm_ad_rgb", "llvm_ad_mono", "llvm_ad_mono_polarized", "llvm_ad_spectral",
        "llvm_ad_spectral_polarized", "cuda_ad_rgb", "cuda_ad_mono", "cuda_ad_mono_polarized",
        "cuda_ad_spectral", "cuda_ad_spectral_polarized"
    };
    for (const char *v : jit_variants)
        pm->register_plugin(name, v, ObjectType::BSDF,
            [](void *payload, const Properties &p) -> ref<Object> {
                throw std::runtime_error(
                    std::string(p.plugin_name()) + ": variant \"" + (const char *) payload +
                    "\" is not supported; mitsuba_birefringent works in " + SupportedVariants);
            },
            nullptr, (void *) v);
}

/// Defined in thinbirefringent.cpp and birefringent.cpp.
void register_thinbirefringent();
void register_birefringent();

NAMESPACE_END(bfr)
NAMESPACE_END(mitsuba)
