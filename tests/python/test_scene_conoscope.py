"""scenes/conoscope.py: the conoscopic figure of a c-cut calcite plate (1 mm) between crossed
polarisers, in monochromatic light (589 nm), against the path difference of its two waves, and
the same plate with its axis tilted by 20 degrees: the cross's centre against Snell's law.

1. Ring radii. The polariser and analyser are turned to +45 and -45 degrees so that the dark
   cross lies along the diagonals and the image's middle rows are where the rings are darkest
   and brightest (sin^2(2 phi) = 1). Rendered: the two middle rows of a 256-pixel square image
   of a 40 degree lens (a crop), 64 spp, a 1 nm band on the plate (it averages out the
   fringes of the plate's multiple reflections, whose path 2 n d cos t is 3.3 mm; the rings'
   path difference, up to 8 um, keeps 99.8 % of its contrast). Predicted: the profile
   sin^2(pi Delta(i) / lambda) with Delta(i) = d ((n_o/n_e) sqrt(n_e^2 - sin^2 i) -
   sqrt(n_o^2 - sin^2 i)) (the scene's `path_difference_nm`), n_o and n_e of calcite at 589 nm
   from the calculator, i the angle of each point of each pixel (16 x 16 points per pixel, the
   box filter). The dark rings of both profiles are located by the same estimator (the vertex
   of the parabola through a local minimum and its neighbours; it is biased by the pixel
   sampling by up to 0.1 orders at the edge, the same for both), and compared ring by ring.
   Bound per ring: 5 degrees of phase (the exact plate against the formula: its faces' s/p
   transmission and its incoherently summed multiple reflections, which the formula leaves out,
   shift the rings by up to 0.05 px here) converted to pixels by that ring's spacing, plus
   0.05 px for the Monte Carlo noise. A plate 1 % thicker moves the outer rings by 0.6 px.
2. The tilted axis. Polariser along x, analyser along y, the axis tilted by 20 degrees towards
   +x, a 90 degree lens (128 pixels). The light that travels along the axis inside the plate
   leaves it at sin i = n_o sin 20 degrees (both waves have the index n_o along the axis): the
   melatope, 34.6 degrees towards -x in the image (light leaving towards +x reaches a camera
   looking down from the left), 44.1 px from the centre. The row through it is all dark (there
   the polariser's x is the p wave of a plane of incidence that holds the axis, so only the e
   wave is excited); the other arm of the cross crosses the rows near it. Measured: that arm's
   x (the darkest pixel, refined by a parabola) in the rows 4.5 to 9.5 px above and below the
   melatope's row (nearer, everything is dark), fitted by x_m + a y^2 (the figure is symmetric
   in y); x_m against the melatope within 0.5 px (measured 0.02 px; n_e in place of n_o in
   Snell's law would put it 6.3 px away). The untilted plate's cross stays at 0 (within 0.1 px).
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401
import scene_optics as so

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import conoscope  # noqa: E402

LAMBDA, THICKNESS_UM = 589.0, 1000.0


def render(**options) -> np.ndarray:
    mi.set_variant("scalar_spectral_polarized")
    d = conoscope.scene(wavelength_nm=LAMBDA, filter_bandwidth=1.0, **options)
    d["sensor"]["sampler"]["type"] = "multijitter"
    return np.array(mi.render(mi.load_dict(d), seed=5), dtype=np.float64)[..., 0]


def dark_rings(profile: np.ndarray) -> np.ndarray:
    """Sub-pixel positions (pixel index units) of the local minima of a profile."""
    out = []
    for j in range(1, len(profile) - 1):
        a, b, c = profile[j - 1: j + 2]
        if b < a and b <= c:
            den = a - 2 * b + c
            out.append(j + (0.5 * (a - c) / den if den > 0 else 0.0))
    return np.array(out)


def predicted_profile(width: int, fov_deg: float, rows: np.ndarray, n_o: float, n_e: float,
                      thickness_um: float = THICKNESS_UM, sub: int = 16) -> np.ndarray:
    """sin^2(pi Delta / lambda) over each pixel of the rows `rows` (pixel indices), averaged."""
    scale = 2 * math.tan(math.radians(fov_deg / 2)) / width
    offsets = ((np.arange(sub) + 0.5) / sub - 0.5) * scale
    tx = conoscope.pixel_tangents(width, fov_deg)[:, None, None] + offsets[None, :, None]
    out = np.zeros(width)
    for r in rows:
        ty = (r + 0.5 - width / 2) * scale + offsets[None, None, :]
        incidence = np.degrees(np.arctan(np.hypot(tx, ty)))
        delta = conoscope.path_difference_nm(incidence, n_o, n_e, thickness_um)
        out += (np.sin(np.pi * delta / LAMBDA) ** 2).mean(axis=(1, 2))
    return out / len(rows)


def test_dark_rings_follow_the_path_difference():
    width, fov = 256, 40.0
    n_o, n_e = so.crystal_indices("calcite", LAMBDA)
    rows = np.array([width // 2 - 1, width // 2])
    image = render(width=width, height=width, spp=64, fov_deg=fov, polarizer_deg=45.0,
                   analyser_deg=-45.0, crop=(0, int(rows[0]), width, 2))
    rendered = dark_rings(image.mean(axis=0))
    predicted = dark_rings(predicted_profile(width, fov, rows, n_o, n_e))
    assert len(rendered) == len(predicted) == 29, (rendered, predicted)  # 14 rings each side
    # Ring spacing (px) at each predicted ring: the phase bound in pixels.
    spacing = np.gradient(predicted)
    spacing[len(spacing) // 2] = np.inf  # the centre's minimum is not a ring
    bound = 5.0 / 360.0 * np.abs(spacing) + 0.05
    miss = np.abs(rendered - predicted)
    centre = width / 2
    tangent = (2 * (rendered + 0.5) / width - 1) * math.tan(math.radians(fov / 2))
    order = -conoscope.path_difference_nm(np.degrees(np.arctan(np.abs(tangent))), n_o, n_e,
                                          THICKNESS_UM) / LAMBDA
    print(f"{len(rendered) // 2} rings each side up to "
          f"{np.degrees(np.arctan(np.abs(tangent).max())):.1f} degrees; |rendered - predicted| max "
          f"{miss.max():.3f} px (bound at least {bound.min():.3f} px); Delta / lambda at the rendered "
          f"rings (the estimator's bias included): {np.round(order[rendered > centre], 2)}")
    assert np.all(miss <= bound), np.c_[rendered, predicted, bound]
    # The sensitivity claimed above: a plate 1 % thicker.
    thicker = dark_rings(predicted_profile(width, fov, rows, n_o, n_e, 1.01 * THICKNESS_UM))
    assert np.abs(thicker - predicted).max() > 0.5


def cross_centre(tilt_deg: float, width: int = 128, fov: float = 90.0) -> tuple[float, float]:
    """(measured, predicted) x of the cross's centre, pixels from the image centre (module
    docstring, part 2)."""
    n_o, _ = so.crystal_indices("calcite", LAMBDA)
    focal = width / 2 / math.tan(math.radians(fov / 2))
    predicted = -focal * math.tan(math.radians(conoscope.melatope_deg(n_o, tilt_deg)))
    x0, y0, w, h = int(round(width / 2 + predicted)) - 16, width // 2 - 10, 33, 20
    image = render(width=width, height=width, spp=32, fov_deg=fov, axis_tilt_deg=tilt_deg,
                   crop=(x0, y0, w, h))
    ys = np.arange(y0, y0 + h) + 0.5 - width / 2
    xs = np.arange(x0, x0 + w) + 0.5 - width / 2
    keep = np.abs(ys) >= 4.5
    arm = []
    for row in image[keep]:
        j = int(np.argmin(row[4:-4])) + 4
        a, b, c = row[j - 1: j + 2]
        arm.append(xs[j] + 0.5 * (a - c) / (a - 2 * b + c))
    # x = x_m + a y^2, least squares.
    design = np.c_[np.ones(keep.sum()), ys[keep] ** 2]
    x_m = np.linalg.lstsq(design, np.array(arm), rcond=None)[0][0]
    return float(x_m), predicted


def test_tilted_axis_moves_the_cross():
    straight, at_zero = cross_centre(0.0)
    tilted, predicted = cross_centre(20.0)
    print(f"cross centre: untilted {straight:+.3f} px (predicted {at_zero:+.3f}); tilted 20 degrees "
          f"{tilted:+.3f} px (predicted {predicted:+.3f}, the melatope at "
          f"{conoscope.melatope_deg(so.crystal_indices('calcite', LAMBDA)[0], 20.0):.2f} degrees)")
    assert abs(straight) < 0.1
    assert abs(tilted - predicted) < 0.5
    assert predicted < -40.0  # off centre: the melatope is 44 px from it
