/* The plugin library's entry points called from Rust (cpp/src/lib.rs). */
#pragma once

#include "rust/cxx.h"

namespace bfr {

/// Registers `thinbirefringent`, `birefringent` and `birefringentstack` with Mitsuba's PluginManager (again, if
/// they were: the new registration replaces the old); throws a message on failure.
void register_plugins();

/// The variants the plugins work in, comma-separated.
rust::Str supported_variants();

}  // namespace bfr
