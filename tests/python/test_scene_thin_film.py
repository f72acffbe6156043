"""The thin-film scene (scenes/thin_film.py): the analytic RGB integration of the plate
(scalar_rgb) renders the same image as exact per-wavelength spectral sampling (scalar_spectral,
filter_bandwidth 0) in the limit of many samples.

Both sides render the same 12 x 12 image R = 12 times with independent seeds (scalar_rgb at
16 spp: its only noise is the choice between the reflected and the transmitted lobe;
scalar_spectral at 256 spp: that noise plus the sampled wavelengths). Per 3 x 3 block of pixels
and per RGB channel (48 comparisons), the block means of the two sides are compared by Welch's
statistic z = (mean_a - mean_b) / sqrt(se_a^2 + se_b^2); each mean is over 12 renders of 9
pixels, so z is close to normal (about 20 degrees of freedom). Threshold: max |z| < 5, a
family-wise false-alarm rate below 48 x P(|t_20| > 5) ~ 3e-3. The image mean of the two sides
must also agree within 3 % (relative): the standard error of that difference is about 1 %
(measured), and the only expected bias, the Gaussian fit of the CIE weights the core
integrates over (validated to mean CIEDE2000 < 0.5 in tests/spectral_rgb.rs), is far below.
A power check: the same statistic detects a 20 % change of the film's thickness.
"""

from __future__ import annotations

import pathlib
import sys

import mitsuba as mi
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import thin_film  # noqa: E402

SIZE, BLOCK, RENDERS, THRESHOLD = 12, 3, 12, 5.0


def renders(variant: str, spp: int, **options) -> np.ndarray:
    mi.set_variant(variant)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins for this variant)

    scene = mi.load_dict(thin_film.scene(width=SIZE, height=SIZE, spp=spp, **options))
    out = [np.array(mi.render(scene, seed=s))[..., :3] for s in range(RENDERS)]
    n = SIZE // BLOCK
    return np.array(out).reshape(RENDERS, n, BLOCK, n, BLOCK, 3).mean(axis=(2, 4))


def max_z(a: np.ndarray, b: np.ndarray) -> float:
    se2 = lambda x: x.var(axis=0, ddof=1) / len(x)
    return float(np.abs((a.mean(0) - b.mean(0)) / np.sqrt(se2(a) + se2(b) + 1e-30)).max())


def test_variants_listed():
    assert thin_film.VARIANTS[0] == "scalar_rgb"
    assert set(thin_film.VARIANTS) == {"scalar_rgb", "scalar_spectral", "scalar_spectral_polarized"}


def test_analytic_rgb_matches_converged_spectral():
    rgb = renders("scalar_rgb", 16)
    spectral = renders("scalar_spectral", 256, filter_bandwidth=0.0)
    z = max_z(rgb, spectral)
    rel = abs(rgb.mean() / spectral.mean() - 1.0)
    print(f"thin film rgb vs spectral: max |z| = {z:.2f} over {rgb[0].size} block channels, "
          f"image means {rgb.mean():.4f} / {spectral.mean():.4f} (relative difference {rel:.4f})")
    assert z < THRESHOLD
    assert rel < 0.03
    # Power: a film 20 % thinner shifts the interference colours; the same test must see it.
    thinner = renders("scalar_rgb", 16, max_thickness_um=0.8 * thin_film.MAX_THICKNESS_UM)
    z_thin = max_z(thinner, spectral)
    print(f"power check (20 % thinner film): max |z| = {z_thin:.2f}")
    assert z_thin > THRESHOLD
