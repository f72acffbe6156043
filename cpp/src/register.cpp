/* Entry points of the plugin library, called by the Python package mitsuba_birefringent after
 * `import mitsuba` (so that libmitsuba and its PluginManager are loaded). */
#include "common.h"

#include <cstring>

using namespace mitsuba;

static void copy_message(const char *text, char *message, size_t message_len) {
    if (!message || message_len == 0)
        return;
    size_t n = std::min(std::strlen(text), message_len - 1);
    std::memcpy(message, text, n);
    message[n] = 0;
}

/// Registers `thinbirefringent` and `birefringent` with Mitsuba's PluginManager in the variants
/// scalar_rgb, scalar_spectral and scalar_spectral_polarized (the llvm/cuda variants are
/// registered too, with a constructor that throws a clear error). Idempotent: registering again
/// replaces the previous registration. Returns 0, or 1 with a message.
extern "C" MI_EXPORT int bfr_mitsuba_register(char *message, size_t message_len) {
    try {
        if (!PluginManager::instance()) {
            copy_message("Mitsuba's PluginManager is not initialised (import mitsuba first)",
                         message, message_len);
            return 1;
        }
        bfr::register_thinbirefringent();
        bfr::register_birefringent();
    } catch (const std::exception &e) {
        copy_message(e.what(), message, message_len);
        return 1;
    }
    return 0;
}

/// The core's version string (static).
extern "C" MI_EXPORT const char *bfr_mitsuba_version() { return bfr_version(); }

/// Comma-separated variants in which the plugins work (static).
extern "C" MI_EXPORT const char *bfr_mitsuba_variants() { return bfr::SupportedVariants; }
