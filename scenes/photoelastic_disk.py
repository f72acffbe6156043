"""Photoelasticity: a disk under diametral compression between crossed circular polarisers.

What it shows: the isochromatic fringes of a transparent disk squeezed by two opposite point
loads along its vertical diameter, in white light (the coloured fringe orders of a photoelastic
model) or, with `wavelength_nm`, monochromatic (dark fringes on a bright field).

The physics: the disk (diameter D, thickness t, load P, plane stress) has the classic closed-form
stress field of Hertz and Michell, the standard calibration specimen of photoelasticity (M. M.
Frocht, "Photoelasticity", Wiley; S. Timoshenko and J. N. Goodier, "Theory of Elasticity", 3rd
ed. 1970, the chapter on two-dimensional problems in polar coordinates): with the loads at
(0, +-R), r1^2 = x^2 + (R - y)^2, r2^2 = x^2 + (R + y)^2,

    sigma_x = -(2P / pi t) [ (R - y) x^2 / r1^4 + (R + y) x^2 / r2^4 - 1 / D ]
    sigma_y = -(2P / pi t) [ (R - y)^3 / r1^4 + (R + y)^3 / r2^4 - 1 / D ]
    tau_xy  =  (2P / pi t) [ (R - y)^2 x / r1^4 - (R + y)^2 x / r2^4 ]

(the superposition of two radial Flamant fields and a uniform tension 2P / (pi D t)). By the
stress-optic law the loaded disk is a uniaxial plate whose axis lies along the larger principal
stress sigma_1 and whose birefringence is n_e - n_o = C (sigma_1 - sigma_2); `thinbirefringent`
takes sigma_1 - sigma_2 (MPa) as its `birefringence` texture with `birefringence_scale` = C
(per MPa) and the principal direction as its `axis_angle` texture. A circular polariscope
(linear polariser at 0 deg, quarter-wave retarder at 45 deg, the disk, quarter-wave retarder at
-45 deg, analyser at 90 deg; Mitsuba's ideal achromatic `retarder`) transmits (1/2) sin^2(pi N)
of unpolarised light independently of the principal directions, N = C t (sigma_1 - sigma_2) /
lambda the fringe order: dark fringes where N is an integer.

The check (tests/python/test_scene_photoelastic_disk.py): in a monochromatic render the dark
fringes measured along the horizontal and vertical diameters lie where the closed-form N along
those diameters is an integer, within one pixel at 512 x 512.

Default parameters: a 50 mm disk, 6 mm thick, C = 8e-11 / Pa (80 brewster, the order of a
polycarbonate photoelastic sheet), 500 N: N = 8 P C / (pi D lambda) = 3.70 at the centre at
550 nm. Variant: scalar_spectral_polarized (polarisers need the Stokes vector).
"""

from __future__ import annotations

import pathlib

import numpy as np

from _common import backlight, layer, ortho_sensor, stressed_plate

VARIANTS = ("scalar_spectral_polarized",)

#: Half-width of the camera's view in scene units; the disk has radius 1.
VIEW_HALF = 1.05
#: Where `write_data` puts the textures that scenes/photoelastic_disk.xml reads.
DATA = pathlib.Path(__file__).resolve().parent / "data"


def stress_field(x, y, load_n: float, diameter_m: float, thickness_m: float):
    """(sigma_x, sigma_y, tau_xy) in Pa at (x, y) in metres (disk centre at the origin, loads at
    (0, +-D/2) along y), from the closed form of the module docstring."""
    r = diameter_m / 2
    r1 = x**2 + (r - y) ** 2
    r2 = x**2 + (r + y) ** 2
    k = 2 * load_n / (np.pi * thickness_m)
    sx = -k * ((r - y) * x**2 / r1**2 + (r + y) * x**2 / r2**2 - 1 / diameter_m)
    sy = -k * ((r - y) ** 3 / r1**2 + (r + y) ** 3 / r2**2 - 1 / diameter_m)
    txy = k * ((r - y) ** 2 * x / r1**2 - (r + y) ** 2 * x / r2**2)
    return sx, sy, txy


def principal_maps(n: int, load_n: float, diameter_mm: float, thickness_mm: float,
                   max_mpa: float):
    """(sigma_1 - sigma_2 in MPa, angle of sigma_1 in degrees) on an n x n grid over the
    rectangle [-1, 1]^2 (row index growing with y; zero outside the disk); the difference is
    clipped at `max_mpa` next to the load points, where it diverges."""
    u = (np.arange(n) + 0.5) / n * 2 - 1
    xs, ys = np.meshgrid(u, u)
    scale = diameter_mm * 1e-3 / 2
    with np.errstate(divide="ignore", invalid="ignore"):
        sx, sy, txy = stress_field(xs * scale, ys * scale, load_n, diameter_mm * 1e-3,
                                   thickness_mm * 1e-3)
        diff = np.sqrt((sx - sy) ** 2 + 4 * txy**2) / 1e6
        angle = 0.5 * np.degrees(np.arctan2(2 * txy, sx - sy))
    inside = xs**2 + ys**2 < 1.0
    diff = np.where(inside & np.isfinite(diff), np.minimum(diff, max_mpa), 0.0)
    angle = np.where(inside & np.isfinite(angle), angle, 0.0)
    return diff, angle


def textures(load_n: float = 500.0, diameter_mm: float = 50.0, thickness_mm: float = 6.0,
             stress_optic_per_pa: float = 8e-11, texture_size: int = 1024,
             max_fringe_order: float = 60.0):
    """(sigma_1 - sigma_2 in MPa, angle of sigma_1 in degrees) maps of the disk; the difference
    is clipped where the fringe order at 550 nm would exceed `max_fringe_order` (next to the
    loads, where it diverges)."""
    max_mpa = max_fringe_order * 550e-9 / (stress_optic_per_pa * thickness_mm * 1e-3) / 1e6
    return principal_maps(texture_size, load_n, diameter_mm, thickness_mm, max_mpa)


def write_data(directory: pathlib.Path = DATA) -> list[pathlib.Path]:
    """Writes the default textures as float EXRs for the XML version of the scene."""
    import mitsuba as mi

    directory.mkdir(parents=True, exist_ok=True)
    paths = []
    for suffix, values in zip(("dsigma", "angle"), textures()):
        path = directory / f"photoelastic_disk_{suffix}.exr"
        mi.Bitmap(np.ascontiguousarray(values, dtype=np.float32)).write(str(path))
        paths.append(path)
    return paths


def scene(width: int = 512, height: int = 512, spp: int = 16, filter_bandwidth: float = 0.0,
          load_n: float = 500.0, diameter_mm: float = 50.0, thickness_mm: float = 6.0,
          stress_optic_per_pa: float = 8e-11, index: float = 1.585,
          wavelength_nm: float | None = None, texture_size: int = 1024,
          max_fringe_order: float = 60.0, crop: tuple[int, int, int, int] | None = None) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `wavelength_nm` makes the camera monochromatic (one channel: the radiance in a 0.01 nm band);
    `max_fringe_order` (at 550 nm) clips the stress next to the loads; `crop` = (offset_x,
    offset_y, width, height) renders only that window of the width x height image.
    """
    diff, angle = textures(load_n, diameter_mm, thickness_mm, stress_optic_per_pa, texture_size,
                           max_fringe_order)
    half = VIEW_HALF
    return {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 16},
        "sensor": ortho_sensor(width, height, spp, half * width / height, half,
                               wavelength_nm=wavelength_nm, crop=crop),
        "light": backlight(-3.0, 4.0),
        "polarizer": layer(-2.0, 2, 2, {"type": "polarizer", "theta": 0.0}),
        "qwp_in": layer(-1.5, 2, 2, {"type": "retarder", "theta": 45.0, "delta": 90.0}),
        "disk": layer(0.0, 1.0, 1.0, stressed_plate(index, thickness_mm, diff, angle,
                                                    stress_optic_per_pa, filter_bandwidth)),
        "qwp_out": layer(1.5, 2, 2, {"type": "retarder", "theta": -45.0, "delta": 90.0}),
        "analyser": layer(2.0, 2, 2, {"type": "polarizer", "theta": 90.0}),
    }


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: spectral sampling at 16 spp left 5.0 % of brightness noise per pixel and a chromaticity
#: noise of 0.029), docs/scenes.md.
GALLERY = {"analytic": True, "spp": 16}
