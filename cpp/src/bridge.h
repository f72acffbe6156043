/* Moving Mitsuba's per-lane values to the core and its answers back, for every variant.
 *
 * The core answers batches of lanes (structure of arrays, doubles; see the bridge header
 * generated from src/ffi/mod.rs). In the scalar variants a BSDF query is one lane. In the JIT
 * variants (evaluated mode only: the inputs must be real arrays, not symbolic variables) a
 * query holds the lanes of a wavefront that hit this BSDF instance: the inputs are detached,
 * evaluated in one kernel, read from host memory after the thread has synchronised (LLVM
 * arrays live in host memory), converted to doubles and sent to the core in chunks on Dr.Jit's
 * thread pool; the answers are written into arrays allocated for the purpose. A column of one
 * value means "the same for every lane" on both sides of the bridge.
 */
#pragma once

#include <mitsuba/core/logger.h>
#include <mitsuba/render/fwd.h>
#include <drjit/jit.h>
#include <nanothread/nanothread.h>

#include <algorithm>
#include <immintrin.h>
#include <array>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "rust/cxx.h"
#include "birefringent/src/ffi/mod.rs.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// Most channels of a query (wavelengths of the spectral variants), as the core bounds them.
constexpr size_t MaxChannels = (size_t) bfr::Bounds::MaxChannels;

/// Lanes per core call in the JIT variants: bounds the double buffers of a chunk (~3.6 MB);
/// chunks run in parallel on Dr.Jit's thread pool.
constexpr size_t ChunkLanes = 1024;

/// Most Mitsuba inputs a plate or crystal query reads per lane (a stack reads more: its
/// queries set their own bound, the template parameter `Inputs` below).
constexpr size_t MaxInputs = 16;

/// Throws, in a JIT variant, if the call is being recorded (symbolic loops or calls): the
/// core needs the lanes' values, which a symbolic variable does not have.
template <typename Float>
void require_evaluated_mode(const char *ClassName, const char *recorded_where) {
    if constexpr (dr::is_cuda_v<Float>)
        Throw("a query that calls the core on the host cannot run in a CUDA variant (it runs "
              "inside the kernel only for %s)", recorded_where);
    if constexpr (dr::is_jit_v<Float>) {
        if (jit_flag(JitFlag::SymbolicScope))
            Throw("this query of the BSDF computes its lobes outside Dr.Jit (it runs inside "
                  "Mitsuba's kernels only for %s) and works in evaluated mode only, "
                  "but it is being called inside a symbolic loop or call: switch off both "
                  "drjit.JitFlag.SymbolicLoops and drjit.JitFlag.SymbolicCalls, e.g. render inside "
                  "`with mitsuba_birefringent.evaluated_mode():`. While any instance of this BSDF "
                  "exists, symbolic renders of other scenes in this process fail too (Dr.Jit traces "
                  "every registered BSDF): first delete every scene holding one (an exception from "
                  "a failed render holds its scene too) and collect garbage.", recorded_where);
    }
}

/// Throws, in a JIT variant, if any of `inputs` carries derivatives: a query that calls the
/// core on the host (`spectrum`: a band or colour channels) is outside Dr.Jit's graph, and a
/// gradient through it would silently be 0. The core's reason names what to use instead.
template <typename... Ts>
void refuse_gradients(const char *ClassName, const bfr::PlateSpectrum &spectrum,
                      const Ts &...inputs) {
    if constexpr ((dr::is_diff_v<Ts> || ...)) {
        if ((dr::grad_enabled(inputs) || ...)) {
            std::string reason(spectrum.gradients_refused());
            if (!reason.empty())
                Throw("%s", reason);
        }
    }
}

/// True if no lane is active: a scalar variant's inactive query (a JIT variant does not look,
/// which would cost a synchronisation; the core skips inactive lanes).
template <typename Mask> bool none_active(const Mask &active) {
    if constexpr (dr::is_jit_v<Mask>)
        return false;
    else
        return !active;
}

/// The value of a one-lane (or literal) `x` on the host, e.g. a texture's mean.
template <typename T> double scalar(const T &x) {
    if constexpr (dr::is_jit_v<T>)
        return (double) dr::slice(x, 0);
    else
        return (double) x;
}

/// A column of floats on the host: `size` values, or one for every lane.
struct FloatColumn {
    const float *data = nullptr;
    size_t size = 0;
    float at(size_t i) const { return data[size == 1 ? 0 : i]; }
};

/// A column of masks on the host.
struct MaskColumn {
    const bool *data = nullptr;
    size_t size = 0;
    bool at(size_t i) const { return data[size == 1 ? 0 : i]; }
};

/** The Mitsuba inputs of one query, readable on the host after `read()`.
 *
 * Scalar variants: the values themselves. JIT variants: detached copies, evaluated together
 * (one kernel), their memory pointers taken (a literal is materialised on the way), then one
 * `dr::sync_thread()` so that every queued computation has finished before the host reads
 * (without it, most lanes read stale memory). */
template <typename Float, size_t Inputs = MaxInputs> class HostInputs {
public:
    using Mask = dr::mask_t<Float>;
    static constexpr bool Jit = dr::is_jit_v<Float>;

    /// Queues `x`; its column is `floats(k)` after `read()`, k the returned index.
    size_t add(const Float &x) {
        size_t k = m_nf++;
        if constexpr (Jit) {
            m_f[k] = dr::detach<false>(x);
            m_width = std::max(m_width, m_f[k].size());
        } else {
            m_f[k] = x;
            m_width = 1;
        }
        return k;
    }

    /// Queues the mask `m`; its column is `masks(k)` after `read()`.
    size_t add_mask(const Mask &m) {
        size_t k = m_nm++;
        if constexpr (Jit) {
            m_m[k] = dr::detach<false>(m);
            m_width = std::max(m_width, m_m[k].size());
        } else {
            m_m[k] = m;
            m_width = 1;
        }
        return k;
    }

    /// Makes every queued input readable (see the class comment).
    void read() {
        if constexpr (Jit) {
            for (size_t k = 0; k < m_nf; ++k)
                dr::schedule(m_f[k]);
            for (size_t k = 0; k < m_nm; ++k)
                dr::schedule(m_m[k]);
            dr::eval();
            for (size_t k = 0; k < m_nf; ++k)
                m_fc[k] = { m_f[k].data(), m_f[k].size() };
            for (size_t k = 0; k < m_nm; ++k)
                m_mc[k] = { m_m[k].data(), m_m[k].size() };
            dr::sync_thread();
        } else {
            for (size_t k = 0; k < m_nf; ++k)
                m_fc[k] = { &m_f[k], 1 };
            for (size_t k = 0; k < m_nm; ++k)
                m_mc[k] = { &m_m[k], 1 };
        }
    }

    FloatColumn floats(size_t k) const { return m_fc[k]; }
    MaskColumn masks(size_t k) const { return m_mc[k]; }

    /// Lanes of the query: the widest input (known before `read()`).
    size_t width() const { return m_width; }

private:
    using FloatD = std::conditional_t<Jit, dr::detached_t<Float>, float>;
    using MaskD = std::conditional_t<Jit, dr::detached_t<Mask>, bool>;
    std::array<FloatD, Inputs> m_f{};
    std::array<MaskD, 2> m_m{};
    std::array<FloatColumn, Inputs> m_fc{};
    std::array<MaskColumn, 2> m_mc{};
    size_t m_nf = 0, m_nm = 0, m_width = 0;
};

/** Arrays of `n` lanes for the answers: in the JIT variants allocated by Dr.Jit (host memory
 * under LLVM, written through their pointers), in the scalar variants the values themselves.
 * Allocate them before `HostInputs::read()`, whose synchronisation covers the allocation. */
template <typename T> class HostOutput {
public:
    static constexpr bool Jit = dr::is_jit_v<T>;
    using Value = dr::scalar_t<T>;

    void allocate(size_t n) {
        if constexpr (Jit) {
            m_array = dr::empty<dr::detached_t<T>>(n);
            m_data = m_array.data();
        } else {
            m_value = Value(0);
            m_data = &m_value;
        }
    }

    Value *data() { return m_data; }

    /// The answer as Mitsuba's type.
    T get() const {
        if constexpr (Jit)
            return T(m_array);
        else
            return m_value;
    }

private:
    std::conditional_t<Jit, dr::detached_t<T>, Value> m_array{};
    Value m_value{};
    Value *m_data = nullptr;
};

/** The core's floating-point environment for the extent of one chunk, on the thread that runs
 * it, restored at the end. Measured in the llvm variants (Dr.Jit's pool threads after its
 * kernels): MXCSR 0x9fe3 (flush-to-zero and denormals-are-zero on), and the kernels' AVX-512
 * registers left with their upper halves in use, which made the core's SSE code (Rust's
 * baseline x86-64 target: not VEX-encoded) about 20% slower (a 1000 um birefringent plate in
 * llvm_ad_rgb: 2.65 s a render, 2.15 s with vzeroupper). So: IEEE subnormals as in a scalar
 * query (the batch lanes are the scalar queries bit for bit whatever thread runs them) and
 * vzeroupper. */
class CoreFpEnvironment {
public:
    CoreFpEnvironment() : m_csr(_mm_getcsr()) {
        _mm_setcsr(m_csr & ~(_MM_FLUSH_ZERO_ON | _MM_DENORMALS_ZERO_ON));
#if defined(__AVX__)
        _mm256_zeroupper();
#endif
    }
    ~CoreFpEnvironment() { _mm_setcsr(m_csr); }
    CoreFpEnvironment(const CoreFpEnvironment &) = delete;
    CoreFpEnvironment &operator=(const CoreFpEnvironment &) = delete;

private:
    unsigned int m_csr;
};

/** Runs `chunk(begin, end)` over the `n` lanes: at once in the scalar variants (n = 1), in
 * chunks of ChunkLanes on Dr.Jit's thread pool in the JIT variants. Each chunk returns an empty
 * string or the message of its first failure; the first message (in lane order) is returned,
 * so that it is reported from the calling thread. */
template <typename Float, typename Chunk> std::string for_chunks(size_t n, Chunk &&chunk) {
    if constexpr (!dr::is_jit_v<Float>) {
        CoreFpEnvironment fp;
        return chunk(0, n);
    } else {
        size_t count = (n + ChunkLanes - 1) / ChunkLanes;
        std::vector<std::string> messages(count);
        drjit::parallel_for(drjit::blocked_range<size_t>(0, count),
                            [&](drjit::blocked_range<size_t> r) {
                                CoreFpEnvironment fp;
                                for (size_t c = r.begin(); c != r.end(); ++c)
                                    messages[c] = chunk(c * ChunkLanes,
                                                        std::min(n, (c + 1) * ChunkLanes));
                            });
        for (std::string &m : messages)
            if (!m.empty())
                return std::move(m);
        return {};
    }
}

/** Double columns for the lanes of one chunk, and the core's answers for them: fixed-size
 * arrays of `Cap` lanes (1 in the scalar variants: no allocation per query), `Inputs` input
 * columns. */
template <size_t Cap, size_t Inputs = MaxInputs> struct ChunkBuffers {
    /// A column of doubles: `size` values (1 = the same for every lane of the chunk).
    struct Column {
        std::array<double, Cap> v;
        size_t size = 0;
        rust::Slice<const double> slice() const { return { v.data(), size }; }
    };

    /// Input columns (filled by the plugin).
    std::array<Column, Inputs> in;
    std::array<rust::Slice<const double>, MaxChannels> wavelengths;
    std::array<uint8_t, Cap> active;
    size_t active_size = 0;

    /// Output columns.
    std::array<bfr::Status, Cap> status;
    std::array<uint32_t, Cap> component;
    std::array<double, Cap> pdf, eta;
    std::array<std::array<double, Cap>, 3> wo;
    std::array<std::array<double, Cap * MaxChannels>, 3> in_x, out_x;
    std::array<std::array<double, Cap * MaxChannels>, 16> value;

    /// Copies `c` for lanes [begin, end) into input column `k` (one value if `c` has one),
    /// applying `f` to each value.
    template <typename F = double (*)(double)>
    const Column &convert(size_t k, const FloatColumn &c, size_t begin, size_t end,
                          F f = [](double x) { return x; }) {
        Column &d = in[k];
        d.size = c.size == 1 ? 1 : end - begin;
        for (size_t j = 0; j < d.size; ++j)
            d.v[j] = f((double) c.at(begin + j));
        return d;
    }

    /// The `active` column for lanes [begin, end).
    rust::Slice<const uint8_t> convert_mask(const MaskColumn &c, size_t begin, size_t end) {
        active_size = c.size == 1 ? 1 : end - begin;
        for (size_t j = 0; j < active_size; ++j)
            active[j] = c.at(begin + j) ? 1 : 0;
        return { active.data(), active_size };
    }

    /// `count` wavelength columns: input columns first, first + 1, ...
    rust::Slice<const rust::Slice<const double>> wavelength_columns(size_t first, size_t count) {
        for (size_t c = 0; c < count; ++c)
            wavelengths[c] = in[first + c].slice();
        return { wavelengths.data(), count };
    }

    /// Input column `k` as the single value `x`.
    const Column &constant(size_t k, double x) {
        in[k].size = 1;
        in[k].v[0] = x;
        return in[k];
    }

    /// The core's output view for `n` lanes of `channels` channels; `polarized`: frames and
    /// the whole Mueller matrix, else only its (0, 0) entry.
    bfr::Samples samples(size_t n, size_t channels, bool polarized) {
        bfr::Samples s{};
        size_t per = n * channels;
        std::fill(pdf.begin(), pdf.begin() + n, 0.0);  // a refused call leaves zeros
        std::fill(value[0].begin(), value[0].begin() + per, 0.0);
        s.status = { status.data(), n };
        s.component = { component.data(), n };
        s.pdf = { pdf.data(), n };
        s.eta = { eta.data(), n };
        for (size_t k = 0; k < 3; ++k) {
            s.wo[k] = { wo[k].data(), n };
            if (polarized) {
                s.in_stokes_x[k] = { in_x[k].data(), per };
                s.out_stokes_x[k] = { out_x[k].data(), per };
            }
        }
        for (size_t k = 0; k < (polarized ? 16 : 1); ++k)
            s.value[k] = { value[k].data(), per };
        return s;
    }
};

/** Buffers for one chunk: on the stack in the scalar variants; in the JIT ones, one set per
 * thread of Dr.Jit's pool, allocated on its first chunk and reused by every later one (a chunk
 * sets each column it passes before passing it, so nothing of an earlier chunk is read; a chunk
 * runs to its end on its thread without waiting on other tasks, so no two chunks share them).
 * Allocating them per chunk cost a 2.9 MB zero-fill and fresh pages each time: measured 5% of an
 * llvm_ad_spectral render. */
template <typename Float, size_t Inputs = MaxInputs> struct ChunkStorage {
    static constexpr size_t Cap = dr::is_jit_v<Float> ? ChunkLanes : 1;
    using Buffers = ChunkBuffers<Cap, Inputs>;

    Buffers &operator*() {
        if constexpr (dr::is_jit_v<Float>) {
            thread_local std::unique_ptr<Buffers> buffers;
            if (!buffers)
                buffers.reset(new Buffers);  // default-initialised: not zero-filled
            return *buffers;
        } else {
            return m_local;
        }
    }

private:
    std::conditional_t<dr::is_jit_v<Float>, char, Buffers> m_local;
};

/// The core's message for a failed call.
inline std::string core_message(bfr::Status rc, const rust::String &message) {
    std::string m(message);
    if (m.empty())
        m = "status " + std::to_string((int) rc) + " from the birefringent core";
    if (rc == bfr::Status::Internal)
        m += " (an internal error of the birefringent core: please report the scene)";
    return m;
}

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
