"""The thin-film scene (scenes/thin_film.py): the analytic RGB integration of the plate
(scalar_rgb) renders the same image as exact per-wavelength spectral sampling (scalar_spectral,
filter_bandwidth 0) in the limit of many samples.

Both sides render the same 6 x 6 image R = 8 times with independent seeds (scalar_rgb at 8 spp:
its only noise is the choice between the reflected and the transmitted lobe; scalar_spectral
at 256 spp: that noise plus the sampled wavelengths). Per 2 x 2 block of pixels and per RGB
channel (27 comparisons), the block means of the two sides are compared by Welch's statistic
z = (mean_a - mean_b) / sqrt(se_a^2 + se_b^2), each mean over 8 renders (about 14 degrees of
freedom). Threshold: max |z| < 5, a family-wise false-alarm rate below
27 x P(|t_14| > 5) ~ 5e-3. The image means (all pixels and channels) of the two sides must
also agree: the same statistic on them below 4 (one comparison, P(|t_14| > 4) ~ 1.3e-3); the
only expected bias, the Gaussian fit of the CIE weights the core integrates over (validated to
mean CIEDE2000 < 0.5 in tests/spectral_rgb.rs), is far below that resolution. A power check: the same statistic
detects a 30 % change of the film's thickness. Small because scalar_rgb costs several ms per
plate query on this dispersive film.
"""

from __future__ import annotations

import pathlib
import sys

import mitsuba as mi
import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import thin_film  # noqa: E402

SIZE, BLOCK, RENDERS, THRESHOLD = 6, 2, 8, 5.0


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
    rgb = renders("scalar_rgb", 8)
    spectral = renders("scalar_spectral", 256, filter_bandwidth=0.0)
    z = max_z(rgb, spectral)
    per_render = lambda x: x.reshape(RENDERS, -1).mean(axis=1)[:, None]
    z_mean = max_z(per_render(rgb), per_render(spectral))
    print(f"thin film rgb vs spectral: max |z| = {z:.2f} over {rgb[0].size} block channels, "
          f"image means {rgb.mean():.4f} / {spectral.mean():.4f} (z = {z_mean:.2f})")
    assert z < THRESHOLD
    assert z_mean < 4.0
    # Power: a film 30 % thinner shifts the interference colours; the same test must see it.
    thinner = renders("scalar_rgb", 8, max_thickness_um=0.7 * thin_film.MAX_THICKNESS_UM)
    z_thin = max_z(thinner, spectral)
    print(f"power check (30 % thinner film): max |z| = {z_thin:.2f}")
    assert z_thin > THRESHOLD
