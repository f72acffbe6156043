/* Reading a physical scalar of a plugin (`thickness`, `birefringence`, `axis_angle` of
 * `thinbirefringent`) from Mitsuba's properties: a number, whichever way the scene writes it, or
 * a clear refusal at load.
 */
#pragma once

#include "plugins.h"

NAMESPACE_BEGIN(mitsuba)
NAMESPACE_BEGIN(shim)

/** A physical scalar that may vary over the surface (`thickness`, `birefringence`,
 * `axis_angle`), read with `eval_1` at each hit: a float, a uniform spectrum, a grey rgb (equal
 * channels: that value, exactly), or a texture of data values (a bitmap with raw="true", a
 * checkerboard of floats, ...). Refused at load, with `unit` and how to give the value: an rgb
 * with unequal channels, a spectrum varying with wavelength, and a colour texture (srgb,
 * spectra, or a bitmap that Mitsuba upsamples to spectra): Mitsuba reads those for a scalar
 * parameter as a colour, not as the number (in the spectral variants an rgb becomes a smooth
 * reflectance spectrum bounded to [0, 1], so rgb 30 would read as ~1). */
template <typename Float, typename Spectrum>
ref<Texture<Float, Spectrum>> scalar_texture(const Properties &props, const std::string &name,
                                             double def, const char *unit,
                                             const char *ClassName) {
    using Tex = Texture<Float, Spectrum>;
    const char *how = "give a float, or a texture of data values such as a bitmap with "
                      "raw=\"true\"";
    auto uniform = [&](double value) {
        props.mark_queried(name);
        Properties p("uniform");
        p.set("value", value);
        return ref<Tex>(PluginManager::instance()->create_object<Tex>(p));
    };
    if (!props.has_property(name))
        return uniform(def);
    switch (props.type(name)) {
        case Properties::Type::Color: {
            auto c = props.get<Color<double, 3>>(name);
            if (c.r() != c.g() || c.r() != c.b())
                Throw("\"%s\" is a number (%s), not a colour: got rgb %s; %s", name, unit,
                      c, how);
            return uniform(c.r());
        }
        case Properties::Type::Spectrum: {
            const auto &s = props.get<Properties::Spectrum>(name);
            if (!s.is_uniform())
                Throw("\"%s\" is a number (%s), not a spectrum varying with wavelength; %s",
                      name, unit, how);
            return uniform(s.values[0]);
        }
        case Properties::Type::Float:
        case Properties::Type::Integer:
        case Properties::Type::Object:
            break;
        default:
            Throw("\"%s\" must be a float (%s) or a texture, got %s; %s", name, unit,
                  property_type_name(props.type(name)), how);
    }
    ref<Tex> tex = props.get_unbounded_texture<Tex>(name);
    static const char *colour_classes[] = { "SRGBReflectanceSpectrum", "RegularSpectrum",
                                            "IrregularSpectrum", "D65Spectrum",
                                            "BlackBodySpectrum" };
    for (const char *c : colour_classes)
        if (tex->class_name() == c)
            Throw("\"%s\" is a number (%s), not a colour or a spectrum (got a %s texture); %s",
                  name, unit, c, how);
    // A bitmap Mitsuba converts into spectra (3 channels, raw="false", spectral variants)
    // refuses eval_1: find out now rather than at the first hit.
    try {
        SurfaceInteraction<Float, Spectrum> si = dr::zeros<SurfaceInteraction<Float, Spectrum>>();
        si.uv = Point<Float, 2>(0.5f, 0.5f);
        (void) tex->eval_1(si);
    } catch (const std::exception &) {
        Throw("\"%s\" is a number (%s), but its texture holds colours (a bitmap without "
              "raw=\"true\" is converted into spectra in this variant); %s", name, unit, how);
    }
    return tex;
}

NAMESPACE_END(shim)
NAMESPACE_END(mitsuba)
