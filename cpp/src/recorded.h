/* The JIT variants' path of a query whose physics the core records as a program (replay.h): the
 * programs of one plugin instance, recorded on first use per setting and kept until its
 * parameters change, and a replayed sample as Mitsuba's BSDFSample3f and weight.
 *
 * The program gives, per channel, the Mueller matrix over the pdf in the core's Stokes frames
 * (x axes in_x -> out_x, bridge enum SampleOutput). Here they are rotated into Mitsuba's implicit
 * frames stokes_basis(-wo_hat) -> stokes_basis(wi_hat), (wo_hat, wi_hat) = (wo, wi) in Radiance
 * mode and (wi, wo) in Importance mode (mueller::rotate_mueller_basis's convention, as lobes.h
 * does on the host). Unpolarised variants take the (0, 0) entry: Dr.Jit never computes the rest.
 */
#pragma once

#include <mitsuba/render/bsdf.h>
#include <mitsuba/render/mueller.h>

#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include "bridge.h"
#include "replay.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// The programs of one plugin instance, by the key of their setting (transport mode, enabled
/// components, which parameters carry derivatives). Cleared when the instance's parameters
/// change; recording runs the core, whose errors become Mitsuba exceptions.
template <typename Key> class Programs {
public:
    template <typename Record> const bfr::Program &get(const Key &key, Record &&record) {
        std::lock_guard<std::mutex> lock(m_mutex);
        auto it = m_programs.find(key);
        if (it == m_programs.end())
            it = m_programs.emplace(key, record()).first;
        return *it->second;
    }

    void clear() {
        std::lock_guard<std::mutex> lock(m_mutex);
        m_programs.clear();
    }

private:
    std::mutex m_mutex;
    std::map<Key, rust::Box<bfr::Program>> m_programs;
};

/// A program's sample as Mitsuba's (see the file comment).
template <typename Float, typename Spectrum> struct Replayed {
    MI_IMPORT_TYPES()
    static constexpr size_t Channels = dr::size_v<UnpolarizedSpectrum>;
    static constexpr bool Polarized = is_polarized_v<Spectrum>;
    using Out = bfr::SampleOutput;

    /** The sample of `r`, with Mitsuba's component types `types`; `wi` is si.wi, `radiance`
     * the transport mode, `straight` a straight-through lobe's frames (eval_null_transmission:
     * wo = -wi). Lanes that are inactive, sample nothing or could not be computed get zeros. */
    static std::pair<BSDFSample3f, Spectrum> sample(const Replay<Float> &r, const Vector3f &wi,
                                                    bool radiance, bool straight,
                                                    const BSDFFlags *types, uint32_t count,
                                                    Mask active) {
        Mask valid = active && r.mask((size_t) Out::Valid) && !r.mask((size_t) Out::Count);
        BSDFSample3f bs = dr::zeros<BSDFSample3f>();
        Vector3f wo(r.number((size_t) Out::WoX), r.number((size_t) Out::WoY),
                    r.number((size_t) Out::WoZ));
        bs.wo = dr::select(valid, wo, Vector3f(0.f));
        bs.pdf = dr::select(valid, r.number((size_t) Out::Pdf), 0.f);
        bs.eta = dr::select(valid, r.number((size_t) Out::Eta), 0.f);
        UInt32 component = UInt32(r.number((size_t) Out::Component));
        bs.sampled_component = dr::select(valid, component, 0u);
        UInt32 type = UInt32((uint32_t) types[0]);
        for (uint32_t k = 1; k < count; ++k)
            type = dr::select(component == k, UInt32((uint32_t) types[k]), type);
        bs.sampled_type = dr::select(valid, type, 0u);
        Vector3f towards = straight ? -wi : wo;
        return { bs, weight(r, wi, towards, radiance, valid) };
    }

    /// The weight alone (rotated into Mitsuba's frames, zero where `valid` does not hold).
    static Spectrum weight(const Replay<Float> &r, const Vector3f &wi, const Vector3f &wo,
                           bool radiance, const Mask &valid) {
        Spectrum s = dr::zeros<Spectrum>();
        for (size_t ch = 0; ch < Channels; ++ch) {
            size_t base = (size_t) Out::Channel0 + (size_t) Out::PerChannel * ch;
            auto at = [&](size_t k) { return dr::select(valid, r.number(base + k), 0.f); };
            if constexpr (Polarized) {
                dr::Matrix<Float, 4> M;
                for (size_t e = 0; e < 16; ++e)
                    M(e / 4, e % 4) = at(6 + e);
                Vector3f wo_hat = radiance ? wo : wi, wi_hat = radiance ? wi : wo;
                Vector3f k_in = -wo_hat;
                // Lanes without a lobe rotate nothing (their frames are Mitsuba's own).
                auto frame = [&](size_t k, const Vector3f &own) {
                    return dr::select(valid, Vector3f(r.number(base + k), r.number(base + k + 1),
                                                      r.number(base + k + 2)), own);
                };
                Vector3f in_x = frame(0, mueller::stokes_basis(k_in)),
                         out_x = frame(3, mueller::stokes_basis(wi_hat));
                auto r_in = mueller::rotate_stokes_basis(k_in, in_x, mueller::stokes_basis(k_in));
                auto r_out = mueller::rotate_stokes_basis(wi_hat, out_x,
                                                          mueller::stokes_basis(wi_hat));
                M = r_out * M * dr::transpose(r_in);
                for (size_t e = 0; e < 16; ++e)
                    s(e / 4, e % 4)[ch] = M(e / 4, e % 4);
            } else {
                s[ch] = at(6);
            }
        }
        return s;
    }
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
