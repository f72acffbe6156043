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


def test_rgb_bsdf_is_the_spectral_bsdf_integrated_with_mitsubas_tables():
    """The film's scalar_rgb BSDF value (the plate integrated over the sRGB weights in the core)
    equals its scalar_spectral BSDF (exact per wavelength) integrated at 1 nm over 360-830 nm
    with Mitsuba's own CIE 1931 tables (`mi.cie1931_xyz`), D65 (the `d65` plugin) and the sRGB
    matrix: an independent route to the same colour. Thicknesses 0.1-0.8 um at 40 degrees,
    including 0.28-0.29 um, where the film's colour lies outside the sRGB gamut (R < 0: the
    value must stay negative, as in the spectral image).

    Tolerance 2e-3 (reflectances up to 0.4): the two CIE tables differ by up to 0.55 % of a
    channel's mass (L1), the core's Gaussian fit of its table adds ~1e-4; measured worst 5e-4."""
    theta = np.radians(40.0)
    lams = np.arange(360.0, 830.1, 1.0)

    def bsdf(variant, thickness_um):
        mi.set_variant(variant)
        import mitsuba_birefringent  # noqa: F401

        return mi.load_dict({
            "type": "thinbirefringent", "material": thin_film.MATERIAL, "ext_ior": 1.0,
            "exit_ior": thin_film.SUBSTRATE_IOR, "optic_axis": [1, 0, 0], "thickness": 1.0,
            "thickness_scale": float(thickness_um), "filter_bandwidth": 0.0,
            "absorbing_exit": True})

    def value(b, wavelengths=None):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(0.0, float(np.sin(theta)), float(np.cos(theta)))
        si.n = mi.Vector3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        if wavelengths is not None:
            si.wavelengths = mi.Spectrum(wavelengths)
        return np.array(b.sample(mi.BSDFContext(), si, 0.5, mi.Point2f(0.5, 0.5))[1])

    mi.set_variant("scalar_spectral")
    xyz = np.array([list(mi.cie1931_xyz(float(x))) for x in lams])
    d65 = mi.load_dict({"type": "d65"})
    si = mi.SurfaceInteraction3f()
    illum = []
    for x in lams:
        si.wavelengths = mi.Spectrum([float(x)] * 4)
        illum.append(d65.eval(si)[0])
    srgb = np.array([[3.240479, -1.537150, -0.498535], [-0.969256, 1.875991, 0.041556],
                     [0.055648, -0.204043, 1.057311]])
    weights = (xyz @ srgb.T) * np.array(illum)[:, None]
    weights /= weights.sum(axis=0)

    worst, negative = 0.0, 0
    for d in list(np.arange(0.1, 0.81, 0.05)) + [0.28, 0.285, 0.29]:
        rgb = value(bsdf("scalar_rgb", d))
        b = bsdf("scalar_spectral", d)
        padded = np.concatenate([lams, np.full(-len(lams) % 4, 550.0)])
        f = np.concatenate([value(b, list(padded[i:i + 4])) for i in range(0, len(padded), 4)])
        f = f[:len(lams)]
        spectral = weights.T @ f
        worst = max(worst, float(np.abs(rgb - spectral).max()))
        negative += int(spectral[0] < -0.01 and rgb[0] < -0.01)
        assert np.abs(rgb - spectral).max() < 2e-3, (d, rgb, spectral)
    assert negative >= 2, "no out-of-gamut case was exercised"
    print(f"scalar_rgb vs integrated scalar_spectral: worst {worst:.2e}")


# A scalar_rgb render of the film in a fresh process (the log's appenders are those of a new
# process): the render's log, then log lines of the kind the film emits, given by hand.
SIGNED_RGB_WORKER = r"""
import gc, json, sys
import mitsuba as mi
mi.set_variant("scalar_rgb")
import mitsuba_birefringent
sys.path.insert(0, sys.argv[1])
import thin_film
import numpy as np
scene = mi.load_dict(thin_film.scene(width=12, height=12, spp=2))
img = np.array(mi.render(scene))
print("MIN_RED", float(img[..., 0].min()), flush=True)
W = mi.LogLevel.Warn
mi.Log(W, "[ImageBlock] Invalid sample value: [-0.5, 0.25, 0.25, 1]")   # finite: replaced
mi.Log(W, "[ImageBlock] Invalid sample value: [nan, 0.25, 0.25, 1]")    # shown
mi.Log(W, "[ImageBlock] Invalid sample value: [0.5, 0.25, 0.25, -1]")   # negative weight: shown
del scene
gc.collect()
mi.Log(W, "[ImageBlock] Invalid sample value: [-0.25, 0.5, 0.5, 1]")    # no plate left: shown
"""


def test_signed_rgb_colours_warn_once_and_stay_signed():
    """Out-of-gamut colours of the film in scalar_rgb are negative linear sRGB channels, the
    values Mitsuba's spectral variants accumulate for them (its film does not check samples
    there); the RGB film's per-sample warning about them ("Invalid sample value", formerly once
    per sample: 20 in a 16 x 16, 2 spp render) is replaced by one notice with the reason, the
    stored value stays negative, and non-finite or negative-weight samples are still reported,
    as are negative colours once no scalar_rgb plate exists."""
    import subprocess
    import sys as _sys

    scenes = str(pathlib.Path(__file__).resolve().parents[2] / "scenes")
    out = subprocess.run([_sys.executable, "-c", SIGNED_RGB_WORKER, scenes], capture_output=True,
                         text=True, timeout=300, check=True)
    log = out.stdout + out.stderr
    invalid = [line for line in log.splitlines() if "Invalid sample value" in line]
    notices = [line for line in log.splitlines() if "Out-of-gamut colours" in line]
    min_red = float(log.split("MIN_RED ")[1].split()[0])
    print(f"min red channel {min_red:.4f}; notices {len(notices)}; other lines {invalid}")
    assert min_red < -0.01  # kept signed (not clamped)
    assert len(notices) == 1 and "[ThinBirefringent]" in notices[0]
    assert [line.split("Invalid sample value: ")[1] for line in invalid if "Out-of-gamut" not in line] == [
        "[nan, 0.25, 0.25, 1]", "[0.5, 0.25, 0.25, -1]", "[-0.25, 0.5, 0.5, 1]"]
