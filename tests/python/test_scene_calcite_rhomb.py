"""scenes/calcite_rhomb.py: the two images of text under a calcite block, their offset and their
extinction by a polariser.

The renders are monochromatic (550 nm: a 0.01 nm sensor band), so the walk-off has one value.
Independent reference: the walk-off closed form (Born & Wolf sect. 15.3) with calcite's indices
at 550 nm from Ghosh's Sellmeier fit (Opt. Commun. 163, 95 (1999)) evaluated here; the direction (the e
image displaced opposite to the axis azimuth: calcite is negative, its e ray walks away from the
axis) and the polarisations (o perpendicular to the principal plane, e in it) are textbook facts.
The text is the scene's own bitmap, box-filtered to the render's pixels (the scene maps the
bitmap exactly onto the view).

Extinction is measured on a sheet of isolated bright squares instead of the text (each
square's o and e images lie 5.3 px apart, so the light of each image is summed apart, with no
fit): a polariser along the axis azimuth must leave nothing of the o images, one at 90 degrees
nothing of the e images (ideal polarisers; o polarised perpendicular to the principal plane, e
in it). On the text, the least-squares weight of the o image under the first polariser came out
at -1.8 % with seed 5: not light (the squares show 2e-8) but the fit's Monte Carlo noise (over
seeds 5 and 10-15 the weight's spread is 1.3 % and its mean -0.03 +- 0.55 %) and its model
dependence (windows sampled bilinearly, as Mitsuba looks the bitmap up, at the exact offset
instead of in steps of 1/8 px move it by +1.4 %; the e rays of the crop's last columns leave
through the block's side).

Reduced run: 120 x 80 pixels, and only the window over the text under the block is rendered
(the check needs nothing else), 48 samples per pixel, two renders (polariser along the axis
azimuth: e image only; at 90 degrees to it: o image only), then the same two on the squares at
16 samples per pixel.
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import calcite_rhomb as cr  # noqa: E402

W, H, SPP, LAMBDA = 120, 80, 48, 550.0
PX = 2 * cr.VIEW_X / W  # scene units per pixel (square pixels: 2 VIEW_Y / H is the same)
THICKNESS, TILT, AZIMUTH = 1.2, 44.6, 30.0
# Crop over the block's interior (block: x in +-0.8, y in +-0.55 -> columns 28-92, rows 18-62),
# 2 px inside its sides (rays near the sides leave through them), rows 25-55: the two lines of
# text under the block (and the e image's offset).
C0, R0, CW, CH = 30, 25, 60, 30
MAXSHIFT = 9  # correlation search range (px); the expected e offset is ~5 px


def ghosh_calcite(lam_nm):
    l2 = (lam_nm * 1e-3) ** 2
    n_o = math.sqrt(1.73358749 + 0.96464345 * l2 / (l2 - 1.94325203e-2) + 1.82831454 * l2 / (l2 - 120))
    n_e = math.sqrt(1.35859695 + 0.82427830 * l2 / (l2 - 1.06689543e-2) + 0.14429128 * l2 / (l2 - 120))
    return n_o, n_e


def walk_off(n_o, n_e, t_deg):
    t = math.radians(t_deg)
    return math.atan((n_o**2 - n_e**2) * math.sin(t) * math.cos(t)
                     / (n_e**2 * math.cos(t) ** 2 + n_o**2 * math.sin(t) ** 2))


def template_hr():
    """The text bitmap as floats in [0, 1] (the scene reads it raw: value / 255), row 0 = top."""
    mi.set_variant("scalar_spectral_polarized")
    grey = np.array(mi.Bitmap(str(cr.TEXT_BITMAP)), dtype=np.float64)
    return (grey[..., 0] if grey.ndim == 3 else grey) / 255.0


def window(tpl, f, dr, dc):
    """The render-pixel window (crop) of the bitmap seen with an offset of (dr, dc) pixels:
    box-average of the bitmap (f bitmap pixels per render pixel) shifted to 1/f pixel."""
    r0, c0 = round((R0 + dr) * f), round((C0 + dc) * f)
    block = tpl[r0: r0 + CH * f, c0: c0 + CW * f]
    return block.reshape(CH, f, CW, f).mean(axis=(1, 3))


def render(polarizer_deg, sheet=None, spp=SPP):
    """The crop, polariser at `polarizer_deg`; `sheet`: a bitmap (render-pixel rows and columns
    times f) replacing the text."""
    d = cr.scene(width=W, height=H, spp=spp, thickness=THICKNESS, axis_tilt_deg=TILT,
                 axis_azimuth_deg=AZIMUTH, polarizer_deg=polarizer_deg, wavelength_nm=LAMBDA)
    d["sensor"]["film"].update({"crop_offset_x": C0, "crop_offset_y": R0, "crop_width": CW,
                                "crop_height": CH})
    if sheet is not None:
        radiance = d["sheet"]["emitter"]["radiance"]
        del radiance["filename"]
        radiance["bitmap"] = mi.Bitmap(np.ascontiguousarray(sheet, dtype=np.float32))
    return np.array(mi.render(mi.load_dict(d), seed=5))[..., 0]


# Bright 2 x 2 px squares (top-left render pixel (r, c)) on a dark sheet, where both images of
# each lie inside the crop and their rays inside the block: the e image of a square at q is at
# q - (offset), 2.7 px down and 4.6 px left.
SQUARES = [(r, c) for r in (28, 36, 44) for c in (38, 50, 62, 74, 84)]


def squares_sheet(f):
    sheet = np.zeros((H * f, W * f))
    for r, c in SQUARES:
        sheet[r * f:(r + 2) * f, c * f:(c + 2) * f] = 1.0
    return sheet


def image_light(img, offset):
    """Light of the squares' images at `offset` (px: the image of a square at q is at q -
    offset): sums over 4 x 4 px windows around each, in crop coordinates."""
    total = 0.0
    for r, c in SQUARES:
        r0 = int(round(r + 1 - offset[0] - 2)) - R0
        c0 = int(round(c + 1 - offset[1] - 2)) - C0
        assert 0 <= r0 and r0 + 4 <= CH and 0 <= c0 and c0 + 4 <= CW, (r, c)
        total += img[r0:r0 + 4, c0:c0 + 4].sum()
    return total


def peak(img, tpl, f):
    """(row, column) offset maximising the normalised correlation of img with the shifted bitmap: the best
    whole-pixel offset, then a search at the bitmap's resolution (1/f px) within +-1 px of it,
    refined by a parabola through the best point and its neighbours along each axis (on the fine
    grid the parabola's bias is a small fraction of 1/f px)."""
    a = img - img.mean()

    def corr(dr, dc):  # normalised (Pearson): windows of more contrast are not favoured
        w = window(tpl, f, dr, dc)
        w = w - w.mean()
        return np.sum(a * w) / np.sqrt(np.sum(w * w))
    shifts = range(-MAXSHIFT, MAXSHIFT + 1)
    coarse = np.array([[corr(dr, dc) for dc in shifts] for dr in shifts])
    i, j = np.unravel_index(np.argmax(coarse), coarse.shape)
    fine = np.arange(-f, f + 1) / f
    r0, c0 = i - MAXSHIFT, j - MAXSHIFT
    grid = np.array([[corr(r0 + dr, c0 + dc) for dc in fine] for dr in fine])
    k, m = np.unravel_index(np.argmax(grid), grid.shape)
    k, m = min(max(k, 1), 2 * f - 1), min(max(m, 1), 2 * f - 1)
    sub = lambda lo, p, hi: 0.5 * (lo - hi) / (lo - 2 * p + hi)
    return (r0 + (fine[k] + sub(grid[k - 1, m], grid[k, m], grid[k + 1, m]) / f),
            c0 + (fine[m] + sub(grid[k, m - 1], grid[k, m], grid[k, m + 1]) / f))


def fit(img, t_o, t_e):
    """Least-squares img = a t_o + b t_e + c: the weights of the o and e images."""
    A = np.stack([t_o.ravel(), t_e.ravel(), np.ones(t_o.size)], axis=1)
    return np.linalg.lstsq(A, img.ravel(), rcond=None)[0][:2]


def test_two_images_offset_by_walk_off_each_extinguished_by_a_polariser():
    tpl = template_hr()
    f = tpl.shape[1] // W
    assert tpl.shape == (H * f, W * f)
    e_only, o_only = render(AZIMUTH), render(AZIMUTH + 90.0)

    # Expected e offset: the image moves by -t tan(rho) along the azimuth; the render shows at
    # pixel p the text at p + t tan(rho) (cos az, sin az) (image rows run along -y).
    def expected(lam):
        s = THICKNESS * math.tan(walk_off(*ghosh_calcite(lam), TILT)) / PX
        return (-s * math.sin(math.radians(AZIMUTH)), s * math.cos(math.radians(AZIMUTH)))
    exp = np.array(expected(LAMBDA))
    # Tolerance 0.15 px: the Monte Carlo noise of the correlation peak (the o image, at the same
    # noise, is found within 0.02 px of 0); for scale, calcite's walk-off changes the offset by
    # 0.15 px between 550 and 450 nm.
    tol = 0.15

    got_o, got_e = np.array(peak(o_only, tpl, f)), np.array(peak(e_only, tpl, f))
    print(f"o image offset {got_o.round(3)} px (expected 0); e image offset {got_e.round(3)} px "
          f"(closed form {exp.round(3)}, |offset| {np.hypot(*got_e):.3f} vs "
          f"{np.hypot(*exp):.3f} px; tolerance {tol:.3f} px)")
    assert np.abs(got_o).max() < 0.25, got_o
    assert np.abs(got_e - exp).max() < tol, (got_e, exp)

    # The passed image carries about as much light in both cases (one of the two modes of
    # unpolarised light each, times the Fresnel transmission of two faces): the least-squares
    # weights of the o and e images (bitmap windows: o at 0, e at the measured offset).
    t_o = window(tpl, f, 0, 0)
    t_e = window(tpl, f, got_e[0], got_e[1])
    a_e, b_e = fit(e_only, t_o, t_e)
    a_o, b_o = fit(o_only, t_o, t_e)
    print(f"e weight / o weight of the passed images {b_e / a_o:.4f}")
    assert b_e > 0 and a_o > 0 and abs(b_e / a_o - 1) < 0.1, (b_e, a_o)

    # Extinction, on the squares: each image's light summed apart. Measured: the o images keep
    # 1.7e-8 of the e images' light under the polariser along the axis azimuth, the e images
    # 5e-9 to 6e-9 of the o images' at 90 degrees (float32 rounding: the crystal's modes and the
    # polarisers are exact). Bound 1e-5: a polariser 0.2 degrees off leaks sin^2(0.2) = 1.2e-5,
    # a mode of the wrong polarisation far more.
    sheet = squares_sheet(f)
    e_sq, o_sq = render(AZIMUTH, sheet, spp=16), render(AZIMUTH + 90.0, sheet, spp=16)
    zero = np.zeros(2)
    leak_o = image_light(e_sq, zero) / image_light(e_sq, got_e)
    leak_e = image_light(o_sq, got_e) / image_light(o_sq, zero)
    print(f"squares: o light / e light under the polariser along the axis azimuth {leak_o:.1e}; "
          f"e light / o light at 90 degrees {leak_e:.1e}")
    assert image_light(e_sq, got_e) > 0 and image_light(o_sq, zero) > 0
    assert 0 <= leak_o < 1e-5 and 0 <= leak_e < 1e-5, (leak_o, leak_e)
