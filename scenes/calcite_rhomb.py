"""Double refraction: a calcite block over printed text, seen from above, optionally through a
linear polariser.

What it shows: a sheet of text on a light box (the text is `scenes/data/calcite_text.png`,
rendered with matplotlib by `write_text_bitmap`), and on it a calcite block (`birefringent`,
`optic_axis_space` world, a `cube` scaled to `thickness` x 1.6 x 1.1 units) through which every
letter appears twice; a linear polariser laid on the block (`polarizer_deg`) extinguishes one
of the two images.

The physics: at normal incidence the ordinary ray goes straight through, while the extraordinary
ray's energy (Poynting vector) leaves its wave normal by the walk-off angle rho,
tan rho = (n_o^2 - n_e^2) sin t cos t / (n_e^2 cos^2 t + n_o^2 sin^2 t) for a wave normal at t to
the optic axis (Born & Wolf, sect. 15.3); calcite (negative, n_o > n_e) walks the ray away from
the axis, so with the axis tilted by `axis_tilt_deg` (44.6 degrees, as to the face of a cleavage
rhomb) towards the azimuth `axis_azimuth_deg` the e ray walks by thickness x tan rho (6.2 degrees:
0.109 x thickness) towards that azimuth and the e image appears displaced the opposite way. The
o wave is polarised perpendicular to the principal plane (the plane of the normal and the axis),
the e wave in it, so a polariser transmitting along the axis azimuth passes the e image and
extinguishes the o image, and one at 90 degrees to it does the reverse.

The check (tests/python/test_scene_calcite_rhomb.py): in a monochromatic render the offset
between the two images, measured by cross-correlation with the text, against the closed form;
each polariser angle extinguishes the right image.

Variant: scalar_spectral_polarized (the Stokes vector tells o from e rays in the crystal). The
light box is equal-energy white (the text bitmap is a raw grey-level radiance).
"""

from __future__ import annotations

import math
import pathlib

from _common import T, layer, ortho_sensor

VARIANTS = ("scalar_spectral_polarized",)

DATA = pathlib.Path(__file__).resolve().parent / "data"
TEXT_BITMAP = DATA / "calcite_text.png"
TEXT_LINES = ("Iceland spar, CaCO3", "DOUBLE REFRACTION", "o and e rays,", "walk-off 6.2 deg")
#: The view (and the text sheet) spans [-VIEW_X, VIEW_X] x [-VIEW_Y, VIEW_Y].
VIEW_X, VIEW_Y = 1.5, 1.0
#: Half-sizes of the block's footprint.
BLOCK_X, BLOCK_Y = 0.8, 0.55


def write_text_bitmap(path: pathlib.Path = TEXT_BITMAP, width: int = 960, height: int = 640) -> None:
    """Renders TEXT_LINES in black on white with matplotlib (Agg) into an 8-bit grey PNG of
    width x height pixels covering the sheet (the texture of the light box)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import mitsuba as mi
    import numpy as np

    dpi = 100
    fig = plt.figure(figsize=(width / dpi, height / dpi), dpi=dpi)
    fig.patch.set_facecolor("white")
    for i, line in enumerate(TEXT_LINES):
        fig.text(0.5, 0.8 - 0.2 * i, line, ha="center", va="center", fontsize=40,
                 family="DejaVu Sans", weight="bold", color="black")
    fig.canvas.draw()
    rgba = np.asarray(fig.canvas.buffer_rgba())
    plt.close(fig)
    grey = np.ascontiguousarray(rgba[..., 0])
    path.parent.mkdir(parents=True, exist_ok=True)
    mi.Bitmap(grey, mi.Bitmap.PixelFormat.Y).write(str(path))


def walk_off_deg(n_o: float, n_e: float, tilt_deg: float) -> float:
    """Walk-off angle rho (degrees, positive for calcite) for a wave normal at tilt_deg to the
    axis (Born & Wolf sect. 15.3)."""
    t = math.radians(tilt_deg)
    return math.degrees(math.atan((n_o**2 - n_e**2) * math.sin(t) * math.cos(t)
                                  / (n_e**2 * math.cos(t) ** 2 + n_o**2 * math.sin(t) ** 2)))


def scene(width: int = 360, height: int = 240, spp: int = 32, filter_bandwidth: float = 0.0,
          thickness: float = 1.2, axis_tilt_deg: float = 44.6, axis_azimuth_deg: float = 30.0,
          polarizer_deg: float | None = None, wavelength_nm: float | None = None) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `polarizer_deg`: None = no polariser; otherwise the transmission axis of a polariser on the
    block (counter-clockwise from x, seen from the camera). `wavelength_nm` makes the camera
    monochromatic (one channel, a 0.01 nm band): no dispersion of the walk-off.
    `filter_bandwidth` is unused (there is no thin plate), accepted for the common interface.
    """
    del filter_bandwidth
    if not TEXT_BITMAP.exists():
        write_text_bitmap()
    tilt, az = math.radians(axis_tilt_deg), math.radians(axis_azimuth_deg)
    axis = [math.sin(tilt) * math.cos(az), math.sin(tilt) * math.sin(az), math.cos(tilt)]
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 12},
        "sensor": ortho_sensor(width, height, spp, VIEW_X, VIEW_Y, wavelength_nm=wavelength_nm),
        # The PNG's top row is the sheet's top edge: to_uv flips v (a bitmap's row 0 is at v = 0,
        # the rectangle's bottom edge).
        "sheet": {
            "type": "rectangle",
            "to_world": T().scale([VIEW_X, VIEW_Y, 1.0]),
            "emitter": {"type": "area", "radiance": {
                "type": "bitmap", "filename": str(TEXT_BITMAP), "raw": True,
                "to_uv": T().translate([0, 1, 0]).scale([1, -1, 1])}},
        },
        "block": {
            "type": "cube",
            "to_world": T().translate([0, 0, 0.01 + thickness / 2])
            .scale([BLOCK_X, BLOCK_Y, thickness / 2]),
            "bsdf": {"type": "birefringent", "material": "calcite", "optic_axis": axis,
                     "optic_axis_space": "world"},
        },
    }
    if polarizer_deg is not None:
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        d["polarizer"] = layer(0.02 + thickness, BLOCK_X, BLOCK_Y,
                               {"type": "polarizer", "theta": -polarizer_deg})
    return d


#: Gallery options (scenes/gallery.py). Each time a path leaves the crystal the plugin must pick
#: the ray's mode (o or e) without knowing its polarisation (a BSDF is not given the Stokes
#: vector), half the time wrongly (that sample then carries no light), so a sample's value in
#: the block is 0 or twice the pixel's: 31 % of noise per pixel of the block at 16 spp of
#: multijitter (20 % over all the lit pixels, the sheet around the block included). The
#: `orthogonal` sampler (orthogonal arrays, Jarosz et al. 2019: every pair of sample dimensions
#: stratified jointly, so the entry's and the exit's choices are stratified together) does with
#: 25 spp what multijitter does with 64; at 121 spp (11^2) 3.0 % over the lit pixels,
#: docs/scenes.md.
GALLERY = {"sampler": "orthogonal", "spp": 121}
