/* Signed sRGB channels of `thinbirefringent` in scalar_rgb, and Mitsuba's film warning about
 * them.
 *
 * In scalar_rgb the plate's lobes are its spectra integrated over the linear sRGB (D65) channel
 * weights (the bridge's sRGB channel set). Where the plate's colour lies outside the sRGB gamut
 * (saturated interference colours) a channel is negative: that is the colour, the same linear
 * sRGB value Mitsuba's spectral variants accumulate for it (ImageBlock::put converts each
 * spectral sample with spectrum_to_srgb, signed and unclamped). The spectral variants' films do not check
 * sample values (hdrfilm creates its blocks with warn_negative only in the non-spectral scalar
 * variants); the RGB variants' films do, because Mitsuba's own RGB BSDFs never go below zero,
 * so ImageBlock::put warns "Invalid sample value" for every such sample.
 *
 * While a scalar_rgb `thinbirefringent` exists, those per-sample warnings are replaced by one
 * warning that gives the reason. Only warnings whose values are all finite, whose negative
 * entries are colour channels (not alpha or weight) are replaced; non-finite samples are still
 * reported one by one. The filter wraps the appenders of Mitsuba's logger (installed once,
 * passive when no such plate exists).
 */
#pragma once

#include <mitsuba/core/appender.h>
#include <mitsuba/core/formatter.h>
#include <mitsuba/core/logger.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <string>
#include <string_view>

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// True if `text` is ImageBlock's warning about a sample whose values are all finite and whose
/// only negative values are among its first three (colour) channels.
inline bool is_signed_colour_warning(std::string_view text) {
    constexpr std::string_view Tag = "[ImageBlock] Invalid sample value: [";
    size_t at = text.find(Tag);
    if (at == std::string_view::npos)
        return false;
    std::string values(text.substr(at + Tag.size()));
    const char *p = values.c_str();
    bool negative_colour = false;
    for (int k = 0;; ++k) {
        char *end = nullptr;
        double x = std::strtod(p, &end);
        if (end == p || !std::isfinite(x))
            return false;
        if (x < -1e-5) {
            if (k >= 3)
                return false;  // a negative alpha or weight is not a colour
            negative_colour = true;
        }
        p = end;
        while (*p == ' ')
            ++p;
        if (*p == ']')
            return negative_colour;
        if (*p != ',')
            return false;
        ++p;
    }
}

/// Process-wide state: how many scalar_rgb plates exist, and whether the notice was given
/// since the first of them appeared.
struct SignedRgbState {
    std::atomic<int> plates { 0 };
    std::atomic<bool> noticed { false };
    std::once_flag installed;

    static SignedRgbState &get() {
        static SignedRgbState s;
        return s;
    }
};

/// An appender of Mitsuba's logger, wrapped: forwards everything but the warnings that
/// is_signed_colour_warning recognises while a scalar_rgb plate exists, of which it forwards
/// one notice instead. Runs under the logger's lock: it must not log itself.
class SignedRgbFilter final : public Appender {
public:
    explicit SignedRgbFilter(Appender *inner) : m_inner(inner) {}

    void append(LogLevel level, std::string_view text) override {
        SignedRgbState &s = SignedRgbState::get();
        if (level == Warn && s.plates.load() > 0 && is_signed_colour_warning(text)) {
            if (!s.noticed.exchange(true))
                m_inner->append(Warn, notice(text));
            return;
        }
        m_inner->append(level, text);
    }

    void log_progress(float progress, std::string_view name, std::string_view formatted,
                      std::string_view eta, const void *ptr) override {
        m_inner->log_progress(progress, name, formatted, eta, ptr);
    }

    MI_DECLARE_CLASS(SignedRgbFilter)

private:
    static std::string notice(std::string_view first) {
        constexpr std::string_view Tag = "Invalid sample value: ";
        std::string msg =
            "Out-of-gamut colours: in scalar_rgb the plate's linear sRGB channel integrals are "
            "negative where its colour lies outside the sRGB gamut (first sample: " +
            std::string(first.substr(first.find(Tag) + Tag.size())) +
            "). They are kept signed, as Mitsuba's spectral variants store the same colours; "
            "the film's per-sample warnings about finite negative colour channels are not "
            "shown while a scalar_rgb thinbirefringent exists.";
        Formatter *f = logger() ? logger()->formatter() : nullptr;
        return f ? f->format(Warn, "ThinBirefringent", __FILE__, __LINE__, msg) : msg;
    }

    ref<Appender> m_inner;
};

/// Held by each scalar_rgb `thinbirefringent`: the first one wraps the logger's appenders (once
/// per process); the notice is given again after every plate was released.
class SignedRgbGuard {
public:
    explicit SignedRgbGuard(bool active) : m_active(active) {
        if (!m_active)
            return;
        SignedRgbState &s = SignedRgbState::get();
        std::call_once(s.installed, [] {
            Logger *l = logger();
            if (!l)
                return;
            std::vector<ref<Appender>> inner;
            for (size_t i = 0; i < l->appender_count(); ++i)
                inner.emplace_back(l->appender(i));
            l->clear_appenders();
            for (auto &a : inner)
                l->add_appender(new SignedRgbFilter(a));
        });
        if (s.plates.fetch_add(1) == 0)
            s.noticed = false;
    }
    ~SignedRgbGuard() {
        if (m_active)
            SignedRgbState::get().plates.fetch_sub(1);
    }
    SignedRgbGuard(const SignedRgbGuard &) = delete;
    SignedRgbGuard &operator=(const SignedRgbGuard &) = delete;

private:
    bool m_active;
};

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
