/* Scene parameters shared by the plugins: the material (a named crystal or constant
 * indices, as the core's material table takes them), indices of refraction by number or by
 * Mitsuba's IOR names. Values are checked by the core (its messages name the parameter), not
 * here.
 */
#pragma once

#include <mitsuba/core/properties.h>
#include <mitsuba/render/ior.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "rust/cxx.h"
#include "birefringent/src/ffi/mod.rs.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/// The material parameters as given in the scene description.
struct MaterialParams {
    bool named = true;     ///< a named crystal (`material`), else constant indices
    std::string material;  ///< the crystal's name as given (the core refuses an unknown one)
    double eta_o = 0, eta_e = 0, kappa_o = 0, kappa_e = 0;

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

/* The functions below take `ClassName` as a parameter so that Mitsuba's Throw/Log macros, which
   refer to a variable of that name, tag their messages with the plugin's class. */

/// What a plugin took by default for parameters that shape the image, said in one warning at
/// load (a default never passes silently: `{"type": "thinbirefringent", "birefringence": 2e-4}`
/// once loaded as 1 um of calcite without a word).
struct Defaults {
    std::vector<std::string> notes;

    void add(std::string note) { notes.push_back(std::move(note)); }

    /// Logs the notes, naming the object by its id where it has one (a dict's key, an XML
    /// id: which layer of a stack, which of several plates). Not if a property was left unread:
    /// Mitsuba's error about it follows the constructor, and a default it caused is no news
    /// (`thicknes` misspelt gets that error alone, not first "thickness = 1 um").
    void log(const Properties &props, const char *ClassName) const {
        if (notes.empty() || !props.unqueried().empty())
            return;
        std::string all;
        for (const std::string &n : notes)
            all += (all.empty() ? "" : "; ") + n;
        std::string id(props.id());
        std::string to = id.empty() ? "" : " to \"" + id + "\"";
        Log(Warn, "not given%s, so by default: %s. Give them to choose (and to silence this "
                  "warning).", to, all);
    }
};

/// `filter_bandwidth` (nm FWHM; default 0, the exact element at each wavelength): the band of
/// the spectral variants. Elsewhere the element is integrated over colour channels in closed
/// form and a band means nothing: a non-zero one is said to be ignored, not silently dropped.
template <typename Spectrum>
double parse_filter_bandwidth(const Properties &props, const char *ClassName) {
    double fwhm = props.get<double>("filter_bandwidth", 0.0);
    if constexpr (!is_spectral_v<Spectrum>)
        if (fwhm != 0.0)
            Log(Warn, "\"filter_bandwidth\" = %g nm is ignored in this variant, where the element "
                      "is integrated over %s in closed form; it is the band around each sampled "
                      "wavelength of the spectral variants (remove it, or render in one)",
                fwhm, is_rgb_v<Spectrum> ? "the sRGB channels" : "its colour channel (\"channel\")");
    return fwhm;
}

/// The isotropic glass of a plate given a stress `birefringence` but no material: Mitsuba's
/// "bk7" (its ior.h), which is also `thindielectric`'s default `int_ior`.
constexpr double DefaultGlassIndex = 1.5046;

/// Throws unless property `name` (if given) is a number: a colour, spectrum or texture gets a
/// message that names the parameter and says `fix`, instead of Mitsuba's `expected float, got
/// rgb`.
inline void require_number(const Properties &props, const char *name, const char *fix,
                           const char *ClassName) {
    if (!props.has_property(name))
        return;
    auto type = props.type(name);
    if (type != Properties::Type::Float && type != Properties::Type::Integer)
        Throw("\"%s\" must be a float, got %s: %s", name, property_type_name(type), fix);
}

/// Throws unless property `name` (if given) is a vector, saying how to write one (instead of
/// Mitsuba's `expected vector, got float`).
inline void require_vector(const Properties &props, const char *name, const char *ClassName) {
    if (props.has_property(name) && props.type(name) != Properties::Type::Vector)
        Throw("\"%s\" must be a vector, got %s: in XML <vector name=\"%s\" x=\"1\" y=\"0\" "
              "z=\"0\"/>, in a dict [1, 0, 0] (any non-zero length)",
              name, property_type_name(props.type(name)), name);
}

/// `material` (string) or `eta_o` + `eta_e` (floats); `kappa_o`, `kappa_e` (floats, default 0).
/// Without either the material is "calcite", or, when `stressed` (a plate given a stress
/// `birefringence`: what a photoelasticity user writes for stressed glass), the isotropic glass
/// DefaultGlassIndex; either default is noted in `defaults`.
inline MaterialParams parse_material(const Properties &props, const char *ClassName,
                                     Defaults &defaults, bool stressed = false) {
    MaterialParams m;
    bool has_o = props.has_property("eta_o"), has_e = props.has_property("eta_e");
    if (props.has_property("material") && (has_o || has_e))
        Throw("give either \"material\" or \"eta_o\" and \"eta_e\", not both");
    if (has_o != has_e)
        Throw("\"%s\" is missing (\"%s\" is given): give both eta_o and eta_e (equal for an "
              "isotropic glass), or \"material\"",
              has_o ? "eta_e" : "eta_o", has_o ? "eta_o" : "eta_e");
    const char *constant_index =
        "a constant real index; for an index that varies with wavelength give \"material\" "
        "instead, a named crystal with its measured dispersion (e.g. \"quartz\"; the catalogue "
        "is in plugin/README.md): spectra, colours and textures are not supported for eta_o "
        "and eta_e";
    require_number(props, "eta_o", constant_index, ClassName);
    require_number(props, "eta_e", constant_index, ClassName);
    const char *constant_kappa = "a constant extinction coefficient (spectra, colours and "
                                 "textures are not supported for kappa_o and kappa_e)";
    require_number(props, "kappa_o", constant_kappa, ClassName);
    require_number(props, "kappa_e", constant_kappa, ClassName);
    if (has_o) {
        m.named = false;
        m.eta_o = props.get<double>("eta_o");
        m.eta_e = props.get<double>("eta_e");
    } else if (props.has_property("material")) {
        m.material = props.get<std::string>("material");
    } else if (stressed) {
        m.named = false;
        m.eta_o = m.eta_e = DefaultGlassIndex;
        std::ostringstream oss;
        oss << "an isotropic glass, eta_o = eta_e = " << DefaultGlassIndex
            << " (Mitsuba's \"bk7\", thindielectric's default), made birefringent by "
               "\"birefringence\" alone (give eta_o = eta_e = your glass's index, or "
               "\"material\" for a crystal)";
        defaults.add(oss.str());
    } else {
        m.material = "calcite";
        defaults.add("material = \"calcite\" (a strongly birefringent crystal; give "
                     "\"material\", or eta_o and eta_e)");
    }
    m.kappa_o = props.get<double>("kappa_o", 0.0);
    m.kappa_e = props.get<double>("kappa_e", 0.0);
    return m;
}

/// Appends the material `p` to the core's table `table` and returns its index; throws the
/// core's message (it names the parameter), prefixed by `what` if not empty (e.g. "layer 2: "),
/// and logs the material's load-time warning.
inline uint32_t add_material(bfr::Materials &table, const MaterialParams &p, const std::string &what,
                             const char *ClassName) {
    uint32_t index = 0;
    try {
        if (p.named)
            index = table.add_named(p.material, p.kappa_o, p.kappa_e);
        else
            index = table.add_constant(p.eta_o, p.eta_e, p.kappa_o, p.kappa_e);
    } catch (const std::exception &e) {  // rust::Error, or a name that is not UTF-8
        Throw("%s%s", what, e.what());
    }
    std::string warning(table.warning(index));
    if (!warning.empty())
        Log(Warn, "%s%s", what, warning);
    return index;
}

/// A parameter of another plugin that a Mitsuba user is likely to give this one, and what to
/// give instead.
struct Foreign {
    const char *name, *fix;
};

/// Throws if a property of `table` is given, saying what to give instead (Mitsuba's own
/// message after the constructor would only say "unreferenced property").
template <size_t N>
void refuse_foreign(const Properties &props, const Foreign (&table)[N], const char *ClassName) {
    for (const Foreign &f : table)
        if (props.has_property(f.name))
            Throw("\"%s\" is not a parameter of this plugin: %s", f.name, f.fix);
}

/// The core's one-material table (index 0); throws the core's message (it names the
/// parameter).
inline rust::Box<bfr::Materials> make_material(const MaterialParams &p, const char *ClassName) {
    rust::Box<bfr::Materials> table = bfr::new_materials();
    add_material(*table, p, "", ClassName);
    return table;
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

/// `f()`, with a core error (`rust::Error`) rethrown as Mitsuba's Throw (the core's message names
/// the parameter).
template <typename F> auto core_call(const char *ClassName, F &&f) -> decltype(f()) {
    try {
        return f();
    } catch (const std::exception &e) {
        Throw("%s", e.what());
    }
}

/// `channel` (string): which colour channel a mono variant renders (the core checks the name).
/// The other variants have their own channels (RGB, or wavelengths), so it is refused there.
template <typename Spectrum>
std::string parse_channel(const Properties &props, const char *ClassName) {
    if constexpr (is_monochromatic_v<Spectrum>) {
        return props.get<std::string>("channel", std::string(bfr::default_channel()));
    } else {
        if (props.has_property("channel"))
            Throw("\"channel\" selects the colour channel of a mono variant's render (e.g. "
                  "\"srgb-d65:R\"; mitsuba_birefringent.render_analytic renders one pass per "
                  "channel in llvm_ad_mono_polarized); in this variant the %s",
                  is_spectral_v<Spectrum> ? "plate is evaluated at each sampled wavelength"
                                          : "plate is integrated over the three sRGB channels");
        return std::string(bfr::default_channel());
    }
}

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
