"""The train window: a tempered glass pane in front of glare reflected near Brewster's angle, seen
half through a polarising filter (sunglasses) and half without.

What it shows: behind the pane, a water surface reflects a bright overcast sky (a D65 area light)
at `incidence_deg` (60 degrees; Brewster's angle of water is 53.1 degrees) towards the camera.
The left half of the image is seen through a linear polarising filter with its transmission axis
vertical (as polarised sunglasses), the right half directly. Through the filter the stress
pattern of the tempered pane lights up in interference colours on a dark background; without it
the pane shows almost no colour.

The physics: reflection off water at 60 degrees keeps R_s = 0.115 of s-polarised light
(perpendicular to the plane of incidence: horizontal in the image) and only R_p = 0.0042 of p, so
the glare is partially polarised, degree of polarisation (R_s - R_p) / (R_s + R_p) = 0.93
(Fresnel's equations). A vertical analyser blocks most of it, unless the pane has turned its
polarisation. The pane (5 mm soda-lime glass, index 1.52, stress-optic coefficient C = 2.7e-12 /
Pa, about 2.7 brewster) carries the in-plane residual stress of its quench: a model, not a
measured field, of the membrane stress left by a square grid of air nozzles of pitch
`nozzle_pitch` (0.5 units), taken from the Airy stress function Phi = A cos(k x) cos(k y),
k = 2 pi / pitch (sigma_xx = d2Phi/dy2, sigma_yy = d2Phi/dx2, tau_xy = -d2Phi/dxdy: in
equilibrium identically, self-balanced over every cell), whose principal stress difference is
sigma_1 - sigma_2 = 2 A k^2 |sin k x sin k y| at +-45 degrees to the grid. Its peak
`peak_stress_mpa` (45 MPa) is chosen to give a retardation C t (sigma_1 - sigma_2) of 600 nm,
the first-order colours; real tempered panes show their spot pattern at lower orders too.
Between a (partial) polariser and an analyser a retardation R transmits sin^2(pi R / lambda)
sin^2(2 theta) of the polarised part, a different fraction of every wavelength (the colours);
without the analyser the transmitted intensity does not depend on the retardation (the pane's
Fresnel losses are nearly the same for every polarisation).

The check (tests/python/test_scene_train_window.py): the colourfulness (luminance-weighted
distance of the chromaticity from white) of the filtered half is many times that of the other.

Variant: scalar_spectral_polarized.
"""

from __future__ import annotations

import math
import pathlib

import numpy as np

from _common import T, layer, ortho_sensor, stressed_plate

VARIANTS = ("scalar_spectral_polarized",)

VIEW_X, VIEW_Y = 1.5, 1.0
#: Where `write_data` puts the textures that scenes/train_window.xml reads.
DATA = pathlib.Path(__file__).resolve().parent / "data"


def quench_maps(n_x: int, n_y: int, pitch: float, peak_mpa: float):
    """(sigma_1 - sigma_2 in MPa, angle of sigma_1 in degrees) on an n_y x n_x grid over the
    view (row index growing with y), from the Airy stress function of the module docstring."""
    x = -VIEW_X + (np.arange(n_x) + 0.5) * (2 * VIEW_X / n_x)
    y = -VIEW_Y + (np.arange(n_y) + 0.5) * (2 * VIEW_Y / n_y)
    xs, ys = np.meshgrid(x, y)
    k = 2 * math.pi / pitch
    a = 1.0 / k**2  # amplitude A with 2 A k^2 = 2 (scaled to peak_mpa below)
    sxx = -a * k**2 * np.cos(k * xs) * np.cos(k * ys)
    syy = -a * k**2 * np.cos(k * xs) * np.cos(k * ys)
    txy = -a * k**2 * np.sin(k * xs) * np.sin(k * ys)
    diff = np.sqrt((sxx - syy) ** 2 + 4 * txy**2)
    angle = 0.5 * np.degrees(np.arctan2(2 * txy, sxx - syy))
    return diff * (peak_mpa / 2.0), angle


def write_data(directory: pathlib.Path = DATA) -> list[pathlib.Path]:
    """Writes the default stress textures as float EXRs for the XML version of the scene."""
    import mitsuba as mi

    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for suffix, values in zip(("dsigma", "angle"), quench_maps(384, 256, 0.5, 45.0)):
        path = directory / f"train_window_{suffix}.exr"
        mi.Bitmap(np.ascontiguousarray(values, dtype=np.float32)).write(str(path))
        paths.append(path)
    return paths


def scene(width: int = 360, height: int = 240, spp: int = 32, filter_bandwidth: float = 0.0,
          polarising_filter: str = "half", incidence_deg: float = 60.0,
          reflector_ior: float = 1.333, peak_stress_mpa: float = 45.0,
          nozzle_pitch: float = 0.5, thickness_mm: float = 5.0, index: float = 1.52,
          stress_optic_per_pa: float = 2.7e-12, texture_size: int = 384) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `polarising_filter`: "half" (left half of the view), "full" or "none".
    """
    if polarising_filter not in ("half", "full", "none"):
        raise ValueError(f"polarising_filter: 'half', 'full' or 'none', not {polarising_filter!r}")
    diff, angle = quench_maps(texture_size, int(texture_size * VIEW_Y / VIEW_X), nozzle_pitch,
                              peak_stress_mpa)
    # The water surface: normal tilted by the incidence angle about x, so that the camera's rays
    # (straight down -z) meet it at incidence_deg and leave along r = (0, sin 2i, cos 2i).
    i = math.radians(incidence_deg)
    r = np.array([0.0, math.sin(2 * i), math.cos(2 * i)])
    centre = np.array([0.0, 0.0, -3.0])
    sky = centre + 8.0 * r
    d = {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 16},
        "sensor": ortho_sensor(width, height, spp, VIEW_X, VIEW_Y),
        "pane": layer(0.0, VIEW_X, VIEW_Y, stressed_plate(index, thickness_mm, diff, angle,
                                                          stress_optic_per_pa, filter_bandwidth,
                                                          angle_filter="nearest")),
        "water": {
            "type": "rectangle",
            "to_world": T().translate(centre.tolist()).rotate([1, 0, 0], -incidence_deg)
            .scale([2 * VIEW_X, 2 * VIEW_Y / math.cos(i), 1.0]),
            # Mitsuba's `conductor` with a real index (k = 0) is the dielectric Fresnel
            # reflection of that index with its polarisation, and nothing else: the light refracted
            # into the water is never seen here, and a `dielectric` would spend ~94 % of its
            # samples on it (noise).
            "bsdf": {"type": "conductor", "eta": reflector_ior, "k": 0.0},
        },
        "sky": {
            "type": "rectangle",
            "to_world": T().look_at(origin=sky.tolist(), target=centre.tolist(), up=[1, 0, 0])
            .scale([6.0, 6.0, 1.0]),
            "emitter": {"type": "area", "radiance": {"type": "d65", "scale": 4.0}},
        },
    }
    if polarising_filter != "none":
        half = polarising_filter == "half"
        # theta 90: transmits along -y, i.e. vertically in the image (scenes/_common.py).
        d["filter"] = layer(1.0, VIEW_X / 2 if half else VIEW_X, VIEW_Y,
                            {"type": "polarizer", "theta": 90.0},
                            centre_x=-VIEW_X / 2 if half else 0.0)
    return d


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: spectral sampling at 16 spp left 3.6 % of brightness noise per pixel and a chromaticity
#: noise of 0.011), docs/scenes.md.
GALLERY = {"analytic": True, "spp": 16}
