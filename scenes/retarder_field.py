"""A quarter-wave plate under a wide-angle lens: Mitsuba's `retarder` (left) against a quartz plate
(right), between a polariser and an analyser.

What it shows: a camera with a 70 degree lens looks down through an analyser along y, a
quarter-wave plate (fast axis at 22.5 degrees) and a polariser along x onto a light box. Left half of
the view: Mitsuba's ideal `retarder` (delta 90 degrees, its retardance scaled by |cos theta| off
the normal: an ad hoc fall-off); right half: a zero-order quartz plate 15.0 um thick
(`thinbirefringent`, the quarter wave at 550 nm). Between crossed polarisers a retarder at
22.5 degrees passes (1/2) sin^2(45 deg) sin^2(delta / 2) of the light: a quarter of it for the
ideal quarter-wave plate, in every direction. Off the normal both plates differ from that. Mitsuba's
retarder changes its Mueller matrix abruptly where the direction of the light crosses wi.y = 0
in the plate's frame (mitsuba3 issue 1963): a seam along the middle row, the upper and lower
halves mirror images. The quartz plate changes smoothly with the direction, by its physics: the
two waves' paths through the plate and the orientation of their vibrations depend on the angle
and azimuth of incidence (for the plate's axis in its faces, along x, the retardance is
2 pi d / lambda (n_e sqrt(1 - sin^2 i / n_o^2) - sqrt(n_o^2 - sin^2 i)) in the plane of
incidence that holds the axis and 2 pi d / lambda (sqrt(n_e^2 - sin^2 i) - sqrt(n_o^2 - sin^2 i))
in the plane across it: it falls in one and grows in the other, `retardance_deg`).

`plate` chooses "split" (the default), "retarder" or "quartz" over the whole view.

The check (tests/python/test_scene_retarder_field.py): no jump across the middle row of the
quartz plate's image beyond the noise measured from the render (a jump of Mitsuba's retarder
there, by the same test); the quartz plate's retardance along the middle row and column, read
from Stokes images, against the formulas above.

Variant: scalar_spectral_polarized; the gallery renders it by colour channels (one plate on every
path).
"""

from __future__ import annotations

import math

import numpy as np

from _common import backlight, layer, lens_sensor
from waveplates import plate_thickness_um

VARIANTS = ("scalar_spectral_polarized",)

#: Height of the camera over the plate; half-size of the plate, polarisers and light box.
CAMERA_HEIGHT, HALF = 1.0, 10.0


def retardance_deg(incidence_deg, n_o: float, n_e: float, thickness_um: float, across: bool):
    """Retardance (degrees) of a plate with its optic axis in its faces, for light at
    `incidence_deg` in the plane of incidence that holds the axis (`across` False) or is
    perpendicular to it (`across` True): 2 pi d / lambda times the difference of the normal
    components of the e and o wave vectors (units of k0), the e wave's from its wave-vector
    surface k_axis^2 / n_o^2 + k_rest^2 / n_e^2 = 1; at 550 nm."""
    s2 = np.sin(np.radians(incidence_deg)) ** 2
    k_o = np.sqrt(n_o**2 - s2)
    k_e = np.sqrt(n_e**2 - s2) if across else n_e * np.sqrt(1 - s2 / n_o**2)
    return np.degrees(2 * np.pi * thickness_um * 1e3 * (k_e - k_o) / 550.0)


def quartz_plate(fast_axis_deg: float, filter_bandwidth: float) -> dict:
    """The zero-order quartz quarter-wave plate (550 nm); quartz is positive, so its optic axis
    (the slow one) is 90 degrees from the fast axis."""
    return {"type": "thinbirefringent", "material": "quartz", "thickness": plate_thickness_um(0.25),
            "axis_angle": fast_axis_deg + 90.0, "filter_bandwidth": filter_bandwidth}


def mitsuba_retarder(fast_axis_deg: float) -> dict:
    """Mitsuba's quarter-wave `retarder`; its fast axis is at -theta (as its polarizer's axis,
    scenes/_common.py)."""
    return {"type": "retarder", "theta": -fast_axis_deg, "delta": 90.0}


def scene(width: int = 360, height: int = 240, spp: int = 16, filter_bandwidth: float = 0.0,
          plate: str = "split", fov_deg: float = 70.0, polarizer_deg: float = 0.0,
          analyser_deg: float | None = 90.0, fast_axis_deg: float = 22.5,
          wavelength_nm: float | None = None,
          stokes: bool = False, crop: tuple[int, int, int, int] | None = None) -> dict:
    """The scene as a dict for `mi.load_dict` (scalar_spectral_polarized).

    `analyser_deg` None leaves the analyser out (to read the plate's light with `stokes`);
    `wavelength_nm` makes the camera monochromatic (with `stokes` an RGB film on a 0.01 nm
    sensor response, read its S channels; without, a one-channel film); `crop` = (offset_x,
    offset_y, width, height) renders that window of the film.
    """
    if plate not in ("split", "retarder", "quartz"):
        raise ValueError(f"plate must be split, retarder or quartz, got {plate!r}")
    nested = {"type": "volpath", "max_depth": 8}
    d = {
        "type": "scene",
        "integrator": {"type": "stokes", "nested": nested} if stokes else nested,
        "sensor": lens_sensor(width, height, spp, fov_deg, CAMERA_HEIGHT, wavelength_nm,
                              single_channel=not stokes, crop=crop),
        "light": backlight(-1.0, HALF, black=True),
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        "polarizer": layer(-0.5, HALF, HALF, {"type": "polarizer", "theta": -polarizer_deg}),
    }
    if analyser_deg is not None:
        d["analyser"] = layer(0.5, HALF, HALF, {"type": "polarizer", "theta": -analyser_deg})
    ours, theirs = quartz_plate(fast_axis_deg, filter_bandwidth), mitsuba_retarder(fast_axis_deg)
    if plate == "split":
        d["retarder"] = layer(0.0, HALF / 2, HALF, theirs, centre_x=-HALF / 2)
        d["quartz"] = layer(0.0, HALF / 2, HALF, ours, centre_x=HALF / 2)
    else:
        d[plate] = layer(0.0, HALF, HALF, ours if plate == "quartz" else theirs)
    return d


def pixel_incidence_deg(n: int, fov_deg: float) -> np.ndarray:
    """Angle from the view axis of the centres of `n` pixels across the lens's `fov_deg`."""
    return np.degrees(np.arctan((2 * (np.arange(n) + 0.5) / n - 1) * math.tan(math.radians(fov_deg / 2))))


def retardance_profile(line: str, plate: str = "quartz", size: int = 65, fov_deg: float = 70.0,
                       spp: int = 8, band_nm: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    """The retardance (degrees) read from a Stokes render along the middle `line` ("row": the
    plane of incidence holds the plate's axis; "column": across it) of a `size` x `size` image
    (odd: the middle pixel's footprint is symmetric about the plane), against the angle of
    incidence (degrees, signed). Light polarised at 45 degrees to the axis, along x, leaves the
    plate with S2 = cos delta and S3 = +-sin delta in the (s, p) frame of each plane, which is
    the stokes integrator's frame on these lines: delta = |atan2(S3, S2)|. At 550 nm, the plate
    through a Gaussian band of `band_nm` (20 nm: its multiple reflections, 46 um of path, add
    incoherently; the retardation keeps its phase to 0.02 degrees)."""
    import mitsuba as mi

    mi.set_variant(VARIANTS[0])
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)

    crop = (0, size // 2, size, 1) if line == "row" else (size // 2, 0, 1, size)
    d = scene(width=size, height=size, spp=spp, filter_bandwidth=band_nm, plate=plate,
              fov_deg=fov_deg, polarizer_deg=45.0, analyser_deg=None, fast_axis_deg=90.0,
              wavelength_nm=550.0, stokes=True, crop=crop)
    d["sensor"]["sampler"]["type"] = "multijitter"
    image = np.array(mi.render(mi.load_dict(d), seed=1), dtype=np.float64).reshape(size, -1)
    # S0..S3 as RGB triplets after the RGB channels; at one wavelength, sum each triplet.
    s = [image[:, 3 + 3 * i: 6 + 3 * i].sum(axis=-1) for i in range(4)]
    return pixel_incidence_deg(size, fov_deg), np.degrees(np.abs(np.arctan2(s[3], s[2])))


def figure(path, size: int = 65) -> None:
    """Retardance against the angle of incidence along both lines: the quartz plate's rendered
    points on the formulas, and Mitsuba's retarder read the same way, with its 90 |cos i|."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from waveplates import indices

    n_o, n_e = indices("quartz", 550.0)
    d = plate_thickness_um(0.25)
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=100)
    for line, colour, across in (("row", "C0", False), ("column", "C1", True)):
        i, quartz = retardance_profile(line, size=size)
        _, theirs = retardance_profile(line, plate="retarder", size=size)
        what = "across the axis" if across else "holding the axis"
        ax.plot(i, retardance_deg(np.abs(i), n_o, n_e, d, across), color=colour, lw=1.2,
                label=f"quartz, plane {what}: formula")
        ax.plot(i, quartz, "o", color=colour, ms=3, mfc="none", label="rendered")
        ax.plot(i, theirs, "x", color=colour, ms=3, alpha=0.6, label=f"Mitsuba's retarder, plane {what}")
    ax.plot(i, 90 * np.cos(np.radians(i)), color="0.5", ls=":", lw=1, label="90 |cos i|")
    ax.set_xlabel("angle of incidence (degrees)")
    ax.set_ylabel("retardance at 550 nm (degrees)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(str(path))
    plt.close(fig)


def main() -> None:
    import argparse
    import pathlib

    p = argparse.ArgumentParser(description="Plots the retardance of the quartz plate and of "
                                "Mitsuba's retarder against the angle of incidence (`figure`).")
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/plots"))
    a = p.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    figure(a.out / "retarder_field_retardance.png")
    print(a.out / "retarder_field_retardance.png")


#: Gallery options (scenes/gallery.py): a channel render (`render_analytic`: no colour noise;
#: 4.7 % of brightness noise per pixel at 8 spp); the quartz plate integrated over a colour
#: channel off the normal costs about 0.07 ms per sample and pass on 2 loaded cores, hence
#: 8 spp; docs/scenes.md.
GALLERY = {"analytic": True, "spp": 8}


if __name__ == "__main__":
    main()
