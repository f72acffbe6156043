/* Registration of the plugins, called by the Python package mitsuba_birefringent after
 * `import mitsuba` (so that libmitsuba and its PluginManager are loaded). */
#include "register.h"
#include "plugins.h"

namespace bfr {

void register_plugins() {
    if (!mitsuba::PluginManager::instance())
        throw std::runtime_error(
            "Mitsuba's PluginManager is not initialised (import mitsuba first)");
    mitsuba::shim::register_thinbirefringent();
    mitsuba::shim::register_birefringent();
    mitsuba::shim::register_birefringentstack();
}

rust::Str supported_variants() { return mitsuba::shim::SupportedVariants; }

}  // namespace bfr
