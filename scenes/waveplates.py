"""Waveplates: zero-order quartz quarter- and half-wave plates after a linear polariser, read with
the `stokes` integrator (the gallery shows the Stokes vector as the colour 0.5 + 0.5 (S1, S2, S3)
/ S0: linear at +45 degrees green, right-circular blue, linear at -15 degrees pink).

What it shows: three columns of light polarised linearly at +45 degrees (counter-clockwise from
the image's x axis, seen from the camera) by a polariser: left, nothing else (the reference);
middle, a quarter-wave plate with its optic axis along x (45 degrees to the polarisation); right,
a half-wave plate with its axis at `hwp_axis_deg` (default 15 degrees, i.e. 30 degrees to the
polarisation). The render's channels are RGB, then S0, S1, S2, S3 (each as RGB) in the camera's
frame (x = image right, y = image up, looking back towards the light).

The physics: a plate of thickness d with its axis in the plate delays the extraordinary wave by
delta = 2 pi (n_e - n_o) d / lambda; a quarter-wave plate (delta = pi / 2) turns light polarised
at 45 degrees to its axis into circular light (S3 / S0 = +1 for crystalline quartz, a positive
crystal, with this geometry), a half-wave plate (delta = pi) reflects the plane of polarisation
about its axis: the angle of linear polarisation goes from 45 to 2 x 15 - 45 = -15 degrees. The
thicknesses are d = lambda0 / (4 (n_e - n_o)) and lambda0 / (2 (n_e - n_o)) at lambda0 = 550 nm,
with n_e - n_o of quartz from the core's catalogue (Ghosh 1999, see src/material/crystals.rs), asked of the
`birefringence` calculator (the indices of the o and e waves at normal incidence): 15.01 um and
30.02 um. A real plate is also a thin etalon: its two faces reflect ~4.6 % each, and the multiple
reflections (which `thinbirefringent` includes, coherently with `filter_bandwidth` 0) change each
mode's amplitude and phase a little, so the plate is not exactly an ideal retarder.

The check (tests/python/test_scene_waveplates.py): at 550 nm (monochromatic sensor, exact
plate) S3/S0 of the quarter-wave plate and the angle of linear polarisation after the half-wave
plate agree with the plate's Jones matrix from the calculator and with the Airy formula of each
mode, and with the ideal retarder within the largest deviation multiple reflections can cause.

Variant: scalar_spectral_polarized.
"""

from __future__ import annotations

import functools
import json
import pathlib
import subprocess

from _common import backlight, layer, ortho_sensor

VARIANTS = ("scalar_spectral_polarized",)

CALCULATOR = pathlib.Path(__file__).resolve().parents[1] / "target" / "release" / "birefringence"
DESIGN_WAVELENGTH_NM = 550.0


@functools.lru_cache(maxsize=None)
def indices(material: str, wavelength_nm: float) -> tuple[float, float]:
    """(n_o, n_e) of a named crystal of the core's catalogue, from the calculator: the effective
    indices of the transmitted o and e waves at normal incidence with the axis in the surface."""
    query = {"wavelength_nm": wavelength_nm, "material": material, "optic_axis": [1, 0, 0],
             "theta_deg": 0, "side": "outside"}
    out = subprocess.run([str(CALCULATOR), "interface"], input=json.dumps(query), text=True,
                         capture_output=True, check=True).stdout
    waves = json.loads(out)["waves"]["transmitted"]
    return waves["o"]["effective_index"][0], waves["e"]["effective_index"][0]


def plate_thickness_um(fraction_of_wave: float, wavelength_nm: float = DESIGN_WAVELENGTH_NM,
                       material: str = "quartz") -> float:
    """Zero-order plate thickness (um) giving a retardation of `fraction_of_wave` waves:
    (n_e - n_o)(lambda0) d = fraction * lambda0."""
    n_o, n_e = indices(material, wavelength_nm)
    return fraction_of_wave * wavelength_nm * 1e-3 / abs(n_e - n_o)


def scene(width: int = 384, height: int = 128, spp: int = 16, filter_bandwidth: float = 0.0,
          wavelength_nm: float | None = None, polarizer_deg: float = 45.0,
          hwp_axis_deg: float = 15.0, stokes: bool = True) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `wavelength_nm` makes the sensor monochromatic (an RGB film on a 0.01 nm sensor response;
    read the S channels); `polarizer_deg` is the polariser's transmission axis (counter-clockwise
    from x, seen from the camera); `stokes=False` renders plain RGB (no Stokes channels).
    """
    nested = {"type": "volpath", "max_depth": 8}
    plate = lambda fraction, angle: {
        "type": "thinbirefringent",
        "material": "quartz",
        "optic_axis": [1.0, 0.0, 0.0],
        "axis_angle": angle,
        "thickness": plate_thickness_um(fraction),
        "filter_bandwidth": filter_bandwidth,
    }
    return {
        "type": "scene",
        "integrator": {"type": "stokes", "nested": nested} if stokes else nested,
        "sensor": ortho_sensor(width, height, spp, 1.5, 0.5, wavelength_nm=wavelength_nm,
                               single_channel=False),
        "light": backlight(-3.0, 4.0),
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        "polarizer": layer(-2.0, 2, 2, {"type": "polarizer", "theta": -polarizer_deg}),
        "qwp": layer(0.0, 0.45, 0.45, plate(0.25, 0.0)),
        "hwp": layer(0.0, 0.45, 0.45, plate(0.5, hwp_axis_deg), centre_x=1.0),
    }


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: spectral sampling at 4 spp left 10 % of brightness noise per pixel and a chromaticity noise
#: of 0.039, the speckle of the old gallery), docs/scenes.md.
GALLERY = {"analytic": True, "spp": 16}
