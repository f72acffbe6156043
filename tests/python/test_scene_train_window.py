"""scenes/train_window.py: the stressed pane shows colours through the polarising filter and almost
none without it, and the glare behind it is polarised as Fresnel's equations say.

1. Colourfulness: the default scene (filter over the left half) at 96 x 64 pixels, 16 samples per
   pixel. The stress pattern is periodic with period pitch / 2 = 0.25 units = 8 pixels in x and
   y, so each half is folded onto one 8 x 8 cell (the mean over its 6 x 8 cells): 48x more
   samples per folded pixel without blurring the pattern. Colourfulness = luminance-weighted mean
   distance of the rg chromaticity (R, G over R + G + B, linear sRGB) from white (1/3, 1/3: the
   D65 sky, reflected by a non-dispersive surface, is white in linear sRGB).
2. Partial polarisation: with no stress in the pane, the filter passes only the p part of the
   glare, a fraction R_p / (R_s + R_p) of it (Fresnel's equations for water at 60 degrees,
   computed here); the pane's own losses are the same with and without the filter.
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import train_window as tw  # noqa: E402

W, H, SPP, CELL = 96, 64, 16, 8


def render(**options):
    mi.set_variant("scalar_spectral_polarized")
    return np.array(mi.render(mi.load_dict(tw.scene(**options)), seed=3))[..., :3].astype(np.float64)


def colourfulness(img):
    cells = img.reshape(H // CELL, CELL, img.shape[1] // CELL, CELL, 3).mean(axis=(0, 2))
    total = cells.sum(axis=-1)
    rg = cells[..., :2] / np.maximum(total, 1e-12)[..., None]
    dist = np.hypot(rg[..., 0] - 1 / 3, rg[..., 1] - 1 / 3)
    return float((dist * total).sum() / total.sum())


def test_colours_only_through_the_filter():
    img = render(width=W, height=H, spp=SPP, polarising_filter="half")
    c_filter, c_none = colourfulness(img[:, : W // 2]), colourfulness(img[:, W // 2:])
    lum_filter, lum_none = img[:, : W // 2].mean(), img[:, W // 2:].mean()
    print(f"colourfulness with filter {c_filter:.4f}, without {c_none:.4f} (ratio "
          f"{c_filter / c_none:.1f}); mean brightness {lum_filter:.4f} vs {lum_none:.4f}")
    # The filtered half shows saturated first-order colours (a chromaticity distance of ~0.1 is a
    # strongly coloured pixel); the other half only the residual Monte Carlo colour noise of
    # spectral sampling after folding (~0.003). 10x separates them with a wide margin both ways.
    assert c_filter > 0.05, c_filter
    assert c_filter > 10 * c_none, (c_filter, c_none)


def test_glare_is_partially_polarised_as_fresnel_says():
    n, i = 1.333, math.radians(60.0)
    ct = math.sqrt(1 - (math.sin(i) / n) ** 2)
    rs = ((math.cos(i) - n * ct) / (math.cos(i) + n * ct)) ** 2
    rp = ((n * math.cos(i) - ct) / (n * math.cos(i) + ct)) ** 2
    expected = rp / (rs + rp)
    opts = dict(width=8, height=8, spp=64, peak_stress_mpa=0.0)
    filtered = render(polarising_filter="full", **opts).mean()
    bare = render(polarising_filter="none", **opts).mean()
    print(f"filtered / bare glare {filtered / bare:.5f}, Fresnel R_p / (R_s + R_p) = {expected:.5f} "
          f"(degree of polarisation {(rs - rp) / (rs + rp):.4f})")
    # Tolerance 3 % relative: the only randomness is the pane's reflection lobe (~8 % of the
    # samples), ~0.5 % standard error on each mean of 4096 samples.
    assert abs(filtered / bare / expected - 1) < 0.03, (filtered / bare, expected)
