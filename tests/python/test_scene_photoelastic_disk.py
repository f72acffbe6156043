"""scenes/photoelastic_disk.py: the dark isochromatic fringes of the diametrically compressed disk
in a monochromatic render (550 nm, exact plate: filter_bandwidth 0) lie where the stress-optic
law puts them.

Independent reference: the textbook stresses along the two diameters (tau_xy = 0 on both), not
the scene's 2-D field: on the horizontal one sigma_x = (2P / pi D t) ((D^2 - 4x^2) / (D^2 +
4x^2))^2 and sigma_y = -(2P / pi D t) (4 D^4 / (D^2 + 4x^2)^2 - 1), so sigma_1 - sigma_2 =
(8P / pi D t) (1 - xi^2) / (1 + xi^2)^2 with xi = 2x / D; on the vertical one sigma_x =
2P / (pi D t) and sigma_y = -(2P / pi t) (2 / (D - 2y) + 2 / (D + 2y) - 1 / D), so sigma_1 -
sigma_2 = (8P / pi D t) / (1 - eta^2) with eta = 2y / D (at the centre 2P / (pi D t) and
-6P / (pi D t)). Hence N = N0 (1 - xi^2) / (1 + xi^2)^2 resp. N0 / (1 - eta^2), with
N0 = 8 P C / (pi D lambda) (the thickness cancels).

Reduced run: only the pixels the check measures are rendered, as crop windows of the 512 x 512
film (4 rows across the horizontal diameter, 4 columns across the vertical one): the same pixel
grid as the full image, so "one pixel" means the same, at a fraction of the time.
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import photoelastic_disk  # noqa: E402

SIZE, SPP, WAVELENGTH = 512, 32, 550.0
OPTS = dict(load_n=500.0, diameter_mm=50.0, thickness_mm=6.0, stress_optic_per_pa=8e-11)
N0 = 8 * OPTS["load_n"] * OPTS["stress_optic_per_pa"] / (
    math.pi * OPTS["diameter_mm"] * 1e-3 * WAVELENGTH * 1e-9)
# Pixel -> disk coordinate (radius 1): pixel centres over [-VIEW_HALF, VIEW_HALF].
PX = 2 * photoelastic_disk.VIEW_HALF / SIZE


def render_crop(crop) -> np.ndarray:
    mi.set_variant("scalar_spectral_polarized")
    d = photoelastic_disk.scene(width=SIZE, height=SIZE, spp=SPP, filter_bandwidth=0.0,
                                wavelength_nm=WAVELENGTH, crop=crop, **OPTS)
    return np.array(mi.render(mi.load_dict(d), seed=7))[..., 0]


def dark_fringes(profile: np.ndarray, threshold: float) -> np.ndarray:
    """Sub-pixel positions (pixel-centre coordinates) of the local minima of `profile` below
    `threshold`: a parabola through each discrete minimum and its two neighbours (I ~ (x - x0)^2
    next to a zero of sin^2(pi N) where N is locally linear)."""
    out = []
    for j in range(1, len(profile) - 1):
        a, b, c = profile[j - 1: j + 2]
        if b < threshold and b <= a and b < c:
            out.append(j + 0.5 * (a - c) / (a - 2 * b + c))
    return np.array(out)


def solve(f, k, lo, hi):
    """x in [lo, hi] with f(x) = k, f monotonic on the interval (bisection to 1e-12)."""
    flo = f(lo) - k
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        if (f(mid) - k) * flo > 0:
            lo, flo = mid, f(mid) - k
        else:
            hi = mid
    return 0.5 * (lo + hi)


def check(profile, predicted_px, label):
    # Threshold: the bright field between fringes reaches ~the profile's maximum; a dark fringe
    # goes to 0 (up to Monte Carlo noise), so 10 % of the maximum separates them.
    found = dark_fringes(profile, 0.1 * profile.max())
    errors = []
    for p in predicted_px:
        nearest = found[np.argmin(np.abs(found - p))]
        errors.append(nearest - p)
    errors = np.array(errors)
    print(f"{label}: {len(predicted_px)} fringes, N0 = {N0:.3f}, worst |measured - predicted| = "
          f"{np.abs(errors).max():.3f} px, mean {errors.mean():+.3f} px")
    # Tolerance of the issue: one pixel at 512 x 512.
    assert np.abs(errors).max() < 1.0, (label, errors)
    return found


def test_dark_fringes_on_both_diameters():
    centre = SIZE // 2
    # Horizontal diameter (y = 0 lies between rows 255 and 256: average those two).
    img = render_crop((0, centre - 2, SIZE, 4))
    prof_h = img[1:3].mean(axis=0)
    # Vertical diameter (x = 0 between columns 255 and 256).
    img = render_crop((centre - 2, 0, 4, SIZE))
    prof_v = img[:, 1:3].mean(axis=1)

    to_px = lambda u: (u + photoelastic_disk.VIEW_HALF) / PX - 0.5
    n_h = lambda xi: N0 * (1 - xi**2) / (1 + xi**2) ** 2
    pred_h = []
    for k in range(1, math.floor(N0) + 1):
        xi = solve(n_h, k, 0.0, 1.0)
        pred_h += [to_px(-xi), to_px(xi)]
    found_h = check(prof_h, np.array(pred_h), "horizontal diameter")
    # No dark fringe where the closed form has none (inside the disk): as many minima as fringes.
    inside = found_h[np.abs(found_h * PX - photoelastic_disk.VIEW_HALF + 0.5 * PX) < 0.98]
    assert len(inside) == len(pred_h), (inside, pred_h)

    n_v = lambda eta: N0 / (1 - eta**2)
    pred_v = []
    k = math.ceil(N0)
    while True:
        eta = solve(n_v, k, 0.0, 1.0)
        # Fringe spacing in pixels there: 1 / (dN/d eta) / PX; beyond 4 px spacing the dark
        # fringes are too narrow for a 3-point minimum at 512 px (and the image row is the check).
        spacing = (1 - eta**2) ** 2 / (2 * N0 * eta) / PX
        if spacing < 4.0:
            break
        pred_v += [to_px(-eta), to_px(eta)]
        k += 1
    assert len(pred_v) >= 8
    # Image rows run along -y; the profile is symmetric, so the order does not matter.
    check(prof_v, np.array(pred_v), "vertical diameter")
