"""The conoscopic figure: a calcite plate cut across its optic axis, between crossed polarisers, in
convergent light.

What it shows: a wide-angle camera close above a 1 mm plate of calcite whose optic axis is its
normal (a "c-cut" plate: `thinbirefringent`, `optic_axis` [0, 0, 1]), between a polariser along
x under it and an analyser along y over it, on a diffuse light box; each pixel looks through the
plate in its own direction, as the eyepiece of a polarising microscope in conoscopic mode shows
the directions of a convergent beam. The figure: the dark cross of the isogyres along the
polariser and analyser, and the isochromes, rings of equal retardation around the axis, coloured
in white light (first orders, fading to the white of high orders), dark where the path
difference is a whole number of wavelengths in monochromatic light (`wavelength_nm`). With
`axis_tilt_deg` 20 the axis leans towards `axis_azimuth_deg` and the cross leaves the centre: its
centre, the melatope, is the direction in which the light travels along the axis inside the
plate, sin i = n_o sin 20 degrees (outside the view for a 40 degree lens: `fov_deg` 90 shows it).

The physics: a wave entering at i from the normal has the tangential wave vector sin i (in units
of k0), which both waves keep; inside, the o wave's normal component is sqrt(n_o^2 - sin^2 i)
and the e wave's, for the axis along the normal, (n_o / n_e) sqrt(n_e^2 - sin^2 i) (its wave
vector surface k_t^2 / n_e^2 + k_z^2 / n_o^2 = 1). Leaving the plate the two waves differ by the
path d ((n_o / n_e) sqrt(n_e^2 - sin^2 i) - sqrt(n_o^2 - sin^2 i)) (`path_difference_nm`; zero
along the axis, growing as sin^2 i at first). Their vibrations are radial and tangential
around the axis, so along the polariser and analyser one wave alone is excited (the isogyres);
elsewhere crossed polarisers transmit sin^2(2 phi) sin^2(pi Delta / lambda), phi the azimuth.

The check (tests/python/test_scene_conoscope.py): in monochromatic light (589 nm, a 1 nm band
that averages out the plate's multiple-reflection fringes) the dark rings lie at the radii where
Delta / lambda is a whole number, with the crystal's own indices at that wavelength from the
core's catalogue; with the axis tilted by 20 degrees the cross's centre lies where
sin i = n_o sin 20 degrees says.

Variant: scalar_spectral_polarized; the gallery renders it by colour channels (the plate is the
one plate on every path). scenes/conoscope.xml is the same scene at its defaults.
"""

from __future__ import annotations

import math

import numpy as np

from _common import backlight, layer, lens_sensor

VARIANTS = ("scalar_spectral_polarized",)

#: Height of the camera's pinhole over the plate, and the half-size of the plate, the polarisers
#: and the light box (large enough to fill a 120 degree view).
CAMERA_HEIGHT, HALF = 1.0, 10.0


def axis(tilt_deg: float, azimuth_deg: float) -> list[float]:
    """The optic axis tilted from the normal by `tilt_deg` towards the azimuth `azimuth_deg`."""
    t, a = math.radians(tilt_deg), math.radians(azimuth_deg)
    return [math.sin(t) * math.cos(a), math.sin(t) * math.sin(a), math.cos(t)]


def path_difference_nm(incidence_deg, n_o: float, n_e: float, thickness_um: float):
    """Delta(i) = d ((n_o / n_e) sqrt(n_e^2 - sin^2 i) - sqrt(n_o^2 - sin^2 i)) in nm, the path
    difference of the e and o waves through a plate cut across its axis (module docstring);
    negative for calcite (n_e < n_o)."""
    s2 = np.sin(np.radians(incidence_deg)) ** 2
    return thickness_um * 1e3 * ((n_o / n_e) * np.sqrt(n_e**2 - s2) - np.sqrt(n_o**2 - s2))


def melatope_deg(n_o: float, tilt_deg: float) -> float:
    """External angle of the direction that travels along a tilted axis inside the plate:
    sin i = n_o sin(tilt) (along the axis both waves have the index n_o)."""
    return math.degrees(math.asin(n_o * math.sin(math.radians(tilt_deg))))


def pixel_tangents(n: int, fov_deg: float) -> np.ndarray:
    """tan of the angle from the view axis of the centres of `n` pixels across a perspective
    camera's `fov_deg` (Mitsuba's fov along x; along y the same scale)."""
    return (2 * (np.arange(n) + 0.5) / n - 1) * math.tan(math.radians(fov_deg / 2))


def scene(width: int = 320, height: int = 320, spp: int = 16, filter_bandwidth: float = 0.0,
          thickness_um: float = 1000.0, axis_tilt_deg: float = 0.0, axis_azimuth_deg: float = 0.0,
          fov_deg: float = 40.0, polarizer_deg: float = 0.0, analyser_deg: float = 90.0,
          wavelength_nm: float | None = None, crop: tuple[int, int, int, int] | None = None) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `wavelength_nm` makes the camera monochromatic (one channel, a 0.01 nm band); there give the
    plate a `filter_bandwidth` of about 1 nm, or its multiple reflections add their own dense
    rings (a 1 mm etalon's). `crop` = (offset_x, offset_y, width, height) renders only that
    window of the film.
    """
    return {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 8},
        "sensor": lens_sensor(width, height, spp, fov_deg, CAMERA_HEIGHT, wavelength_nm, crop=crop),
        "light": backlight(-1.0, HALF, black=True),
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        "polarizer": layer(-0.5, HALF, HALF, {"type": "polarizer", "theta": -polarizer_deg}),
        "plate": layer(0.0, HALF, HALF, {
            "type": "thinbirefringent", "material": "calcite", "thickness": thickness_um,
            "optic_axis": axis(axis_tilt_deg, axis_azimuth_deg), "filter_bandwidth": filter_bandwidth}),
        "analyser": layer(0.5, HALF, HALF, {"type": "polarizer", "theta": -analyser_deg}),
    }


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: 3.2 % of brightness noise per pixel at 8 spp). A 1 mm calcite plate integrated over a colour
#: channel off the normal is one of the plugin's costliest queries (about 0.18 ms per sample and
#: pass on 2 loaded cores), hence 256 px and 8 spp; docs/scenes.md.
GALLERY = {"analytic": True, "spp": 8, "width": 256, "height": 256}
