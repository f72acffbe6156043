"""An independent reference for channel renders: a scene rendered in scalar_spectral_polarized
at fixed wavelengths (a sensor response 0.01 nm wide at each, every plate exact) and integrated
over wavelength with Mitsuba's own CIE 1931 matching functions, D65 spectrum and sRGB matrix,
under the channels of any weight set of render_analytic.

Rendering at fixed wavelengths removes the colour noise of spectral sampling: what noise is left
(each path's lobe choices) averages over the wavelengths, whose renders have independent seeds.
The film's conversion of a narrow band (its `S0..S3` channels are the band's colour times the
radiance) is divided out with a render of a D65 emitter of radiance 1 seen directly at the same
wavelength."""

from __future__ import annotations

import copy
import functools

import mitsuba as mi
import numpy as np

VARIANT = "scalar_spectral_polarized"
#: 380-780 nm every 5 nm (the channel weights beyond hold < 0.1 % of their mass).
WAVELENGTHS = np.arange(380.0, 780.0 + 1e-9, 5.0)
#: Luminance weights of the film's linear sRGB (the combination used to read a narrow band).
LUMA = np.array([0.2126, 0.7152, 0.0722])


def narrow_band(lam: float) -> dict:
    return {"type": "regular", "wavelength_min": lam - 0.005, "wavelength_max": lam + 0.005,
            "values": "1, 1"}


def at_wavelength(scene: dict, lam: float) -> dict:
    """`scene` with a stokes integrator, an RGB hdrfilm and a sensor response at `lam`."""
    d = copy.copy(scene)
    integrator = d["integrator"]
    if integrator.get("type") != "stokes":
        d["integrator"] = {"type": "stokes", "integrator": integrator}
    sensor = dict(d["sensor"])
    sensor["film"] = {**sensor["film"], "pixel_format": "rgb"}
    sensor["srf"] = narrow_band(lam)
    d["sensor"] = sensor
    return d


def stokes_of(image: np.ndarray) -> np.ndarray:
    """S0..S3 of a stokes render's (H, W, 3 + 12) image, read through LUMA: (H, W, 4)."""
    s = image[..., -12:].reshape(*image.shape[:2], 4, 3)
    return s @ LUMA


@functools.lru_cache(maxsize=None)
def unit_d65(lam: float) -> float:
    """The film's reading of a D65 emitter of radiance 1 seen directly at `lam` (a constant: one
    render per wavelength and process)."""
    scene = {"type": "scene", "integrator": {"type": "stokes", "integrator": {"type": "path"}},
             "sensor": {"type": "orthographic",
                        "film": {"type": "hdrfilm", "width": 1, "height": 1, "pixel_format": "rgb",
                                 "rfilter": {"type": "box"}},
                        "sampler": {"type": "independent", "sample_count": 4},
                        "srf": narrow_band(lam)},
             "light": {"type": "constant", "radiance": {"type": "d65", "scale": 1.0}}}
    return float(stokes_of(np.array(mi.render(mi.load_dict(scene)), dtype=np.float64))[0, 0, 0])


def channel_weights(weights: str = "srgb-d65") -> np.ndarray:
    """(wavelengths, 3) weights of the channels of `weights` (the core's names) from Mitsuba's
    tables: linear sRGB of D65 light (srgb-d65), CIE 1931 XYZ of D65 light (xyz-d65) or of
    equal-energy light (xyz-e)."""
    d65 = mi.load_dict({"type": "d65"})
    si = mi.SurfaceInteraction3f()
    rows = []
    for lam in WAVELENGTHS:
        si.wavelengths = [lam] * 4
        illuminant = float(np.array(d65.eval(si))[0]) if weights != "xyz-e" else 1.0
        xyz = mi.cie1931_xyz(float(lam))
        rows.append(np.array(mi.xyz_to_srgb(xyz) if weights == "srgb-d65" else xyz) * illuminant)
    return np.array(rows)


def transfer(scene: dict, spp: int, seed: int = 0) -> np.ndarray:
    """(wavelengths, H, W, 4): S0..S3 of `scene` (a dict for scalar_spectral_polarized, every
    emitter D65-based) at each wavelength per unit of the emitters' spectrum: what the scene does
    to light, the same for any illuminant of the same relative colours."""
    mi.set_variant(VARIANT)
    out = []
    for i, lam in enumerate(WAVELENGTHS):
        img = np.array(mi.render(mi.load_dict(at_wavelength(scene, float(lam))), spp=spp,
                                 seed=seed + 7919 * i), dtype=np.float64)
        out.append(stokes_of(img) / unit_d65(float(lam)))
    return np.array(out)


def combine(t: np.ndarray, weights: str = "srgb-d65") -> np.ndarray:
    """Linear-sRGB Stokes images (H, W, 4, 3) of a `transfer` under the channels of `weights`:
    each channel normalised so that the set's white is 1, the XYZ sets then taken to linear sRGB
    through the white's XYZ (Y = 1) and Mitsuba's matrix."""
    mi.set_variant(VARIANT)
    w = channel_weights(weights)
    total = np.tensordot(t, w / w.sum(axis=0), axes=(0, 0))
    if weights == "srgb-d65":
        return total
    white = w.sum(axis=0) / w.sum(axis=0)[1]
    to_srgb = np.array([np.array(mi.xyz_to_srgb(mi.ScalarColor3f(*e))) for e in np.eye(3)]).T
    return (total * white) @ to_srgb.T


def reference(scene: dict, spp: int, seed: int = 0, weights: str = "srgb-d65") -> np.ndarray:
    """Linear-sRGB Stokes images (H, W, 4, 3) of `scene` (a dict for scalar_spectral_polarized;
    every emitter D65-based) under the channels of `weights`, by the quadrature of the module
    docstring (for xyz-e: the scene's transfer under equal-energy light)."""
    return combine(transfer(scene, spp, seed), weights)
