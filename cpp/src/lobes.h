/* The core's sampled lobes as Mitsuba's BSDFSample3f and sample weight, for one variant.
 *
 * The core chooses the lobe and gives its direction, probability, index ratio and, per
 * channel, the Mueller matrix over the probability in its own Stokes frames (x axes
 * in_stokes_x -> out_stokes_x). Here they are rotated into Mitsuba's implicit frames
 * stokes_basis(-wo_hat) -> stokes_basis(wi_hat), with (wo_hat, wi_hat) = (wo, wi) in Radiance
 * mode and (wi, wo) in Importance mode: the matrix is R_out M R_in^T
 * (mueller::rotate_mueller_basis), in double precision, with the float directions Mitsuba is
 * handed (so the frames are exactly the integrator's). Unpolarised variants take the (0, 0)
 * entry. A query of one channel (the crystal in RGB or mono variants) fills every channel.
 */
#pragma once

#include <mitsuba/render/bsdf.h>
#include <mitsuba/render/mueller.h>

#include <atomic>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "bridge.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// Mitsuba's answers to one query, lane by lane.
template <typename Float, typename Spectrum> class Answers {
public:
    MI_IMPORT_TYPES()

    /// Channels of the variant: 3 (RGB), 4 (sampled wavelengths) or 1 (mono).
    static constexpr size_t Channels = dr::size_v<UnpolarizedSpectrum>;
    static constexpr bool Polarized = is_polarized_v<Spectrum>;
    static constexpr size_t Entries = Polarized ? 16 : 1;
    static_assert(Channels <= MaxChannels, "one core query per path");

    using Vec3d = mitsuba::Vector<double, 3>;
    using Mueller4d = mitsuba::MuellerMatrix<double>;

    /// Allocates the answers of `n` lanes (before the inputs are read).
    void allocate(size_t n) {
        for (auto *o : { &m_pdf, &m_eta, &m_wo[0], &m_wo[1], &m_wo[2] })
            o->allocate(n);
        m_component.allocate(n);
        m_type.allocate(n);
        for (auto &row : m_value)
            for (auto &o : row)
                o.allocate(n);
    }

    /** Writes lane `j` of a chunk of `n` lanes with `core_channels` channels as lane `i`. `wi`:
     * Mitsuba's si.wi; `straight`: the direction for the frames of a straight-through lobe
     * (eval_null_transmission: -wi), else the sampled wo; `types[k]`: the lobe type of
     * component k. */
    template <size_t Cap, size_t In>
    void write(const ChunkBuffers<Cap, In> &b, size_t n, size_t j, size_t core_channels,
               const Vec3d &wi, bool radiance, const std::optional<Vec3d> &straight,
               const BSDFFlags *types, size_t i) {
        double pdf = b.pdf[j];
        if (!(pdf > 0.0))
            return zero(i);
        float wo[3];
        for (size_t k = 0; k < 3; ++k) {
            wo[k] = (float) b.wo[k][j];
            m_wo[k].data()[i] = wo[k];
        }
        m_pdf.data()[i] = (float) pdf;
        m_eta.data()[i] = (float) b.eta[j];
        m_component.data()[i] = b.component[j];
        m_type.data()[i] = (uint32_t) types[b.component[j]];
        Vec3d wo_d = straight ? *straight : Vec3d(wo[0], wo[1], wo[2]);
        std::optional<Frames> frames;
        for (size_t ch = 0; ch < Channels; ++ch) {
            size_t src = (core_channels == 1 ? 0 : ch) * n + j;
            if constexpr (Polarized) {
                if (!frames || !frames->fits(b, src))
                    frames.emplace(b, src, wi, wo_d, radiance);
                Mueller4d M = frames->apply(b, src);
                for (size_t k = 0; k < 16; ++k)
                    m_value[k][ch].data()[i] = (float) M(k / 4, k % 4);
            } else {
                m_value[0][ch].data()[i] = (float) b.value[0][src];
            }
        }
    }

    /// The sampled lobes as Mitsuba's sample and weight.
    std::pair<BSDFSample3f, Spectrum> sample() const {
        BSDFSample3f bs = dr::zeros<BSDFSample3f>();
        for (size_t c = 0; c < 3; ++c)
            bs.wo[c] = m_wo[c].get();
        bs.pdf = m_pdf.get();
        bs.eta = m_eta.get();
        bs.sampled_component = m_component.get();
        bs.sampled_type = m_type.get();
        return { bs, spectrum() };
    }

    /// The sample weight alone.
    Spectrum spectrum() const {
        if constexpr (Polarized) {
            Spectrum s;
            for (size_t e = 0; e < 16; ++e)
                for (size_t ch = 0; ch < Channels; ++ch)
                    s(e / 4, e % 4)[ch] = value(e, ch);
            return s;
        } else {
            UnpolarizedSpectrum s;
            for (size_t ch = 0; ch < Channels; ++ch)
                s[ch] = value(0, ch);
            return s;
        }
    }

private:
    /// Entry `e` of channel `ch` of the weight.
    Float value(size_t e, size_t ch) const { return m_value[e][ch].get(); }

    /// Lane `i` samples nothing.
    void zero(size_t i) {
        for (auto *o : { &m_pdf, &m_eta, &m_wo[0], &m_wo[1], &m_wo[2] })
            o->data()[i] = 0.f;
        m_component.data()[i] = 0;
        m_type.data()[i] = 0;
        for (auto &row : m_value)
            for (auto &o : row)
                o.data()[i] = 0.f;
    }

    /// The rotations of one channel's lobe into Mitsuba's frames (see the file comment); lobes
    /// with the same core frames share them.
    struct Frames {
        double in_x[3], out_x[3];
        Mueller4d r_out, r_in_t;

        template <size_t Cap, size_t In>
        Frames(const ChunkBuffers<Cap, In> &b, size_t src, const Vec3d &wi, const Vec3d &wo,
               bool radiance) {
            for (size_t k = 0; k < 3; ++k) {
                in_x[k] = b.in_x[k][src];
                out_x[k] = b.out_x[k][src];
            }
            Vec3d wo_hat = radiance ? wo : wi, wi_hat = radiance ? wi : wo;
            Vec3d k_in = -wo_hat;
            r_in_t = dr::transpose(mueller::rotate_stokes_basis(
                k_in, Vec3d(in_x[0], in_x[1], in_x[2]), mueller::stokes_basis(k_in)));
            r_out = mueller::rotate_stokes_basis(wi_hat, Vec3d(out_x[0], out_x[1], out_x[2]),
                                                 mueller::stokes_basis(wi_hat));
        }

        template <size_t Cap, size_t In> bool fits(const ChunkBuffers<Cap, In> &b, size_t src) const {
            for (size_t k = 0; k < 3; ++k)
                if (in_x[k] != b.in_x[k][src] || out_x[k] != b.out_x[k][src])
                    return false;
            return true;
        }

        template <size_t Cap, size_t In> Mueller4d apply(const ChunkBuffers<Cap, In> &b, size_t src) const {
            Mueller4d M;
            for (size_t k = 0; k < 16; ++k)
                M(k / 4, k % 4) = b.value[k][src];
            return r_out * M * r_in_t;
        }
    };

    HostOutput<Float> m_pdf, m_eta, m_wo[3];
    HostOutput<UInt32> m_component, m_type;
    HostOutput<Float> m_value[Entries][Channels];
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
