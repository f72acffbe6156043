"""scenes/michel_levy.py (in the gallery): the colours of a quartz wedge between crossed and
parallel polarisers, column by column, against the closed form of the scene as it is rendered.

What the scene renders (scenes/michel_levy.py): variant scalar_spectral_polarized; an
orthographic camera whose view is exactly the wedge's rectangle (x in [-1.5, 1.5]), RGB
`hdrfilm` with a box filter; an area light of `d65` radiance (scale 1) behind the optical train;
a Mitsuba `polarizer` (theta 0), the wedge (`thinbirefringent`, quartz, optic axis [1, 1, 0]: in
the plate at 45 degrees to both polarisers, `filter_bandwidth` 4 nm), and an analyser (theta 90
crossed, 0 parallel), all in air (the plugin's default `ext_ior`, 1.000277). The thickness is a
512-texel bilinear ramp from 0 to 1 (clamped) times `max_thickness_um` (120 um), so at
u in [0, 1] across the wedge d(u) = 120 um * clamp(512 u - 0.5, 0, 511) / 511; pixel column i
averages u over [i / W, (i + 1) / W] (box filter; image x runs along +x, u = 0 on the left).

Closed form, written out here:
- at normal incidence the o and e waves (indices n_o, n_e of quartz from Ghosh's Sellmeier fit,
  Opt. Commun. 163, 95 (1999), evaluated here) cross the plate as two Airy etalons in air, each
  t = t12 t21 e^{i phi} / (1 - r^2 e^{2 i phi}), phi = 2 pi n d / lambda (Born & Wolf 7.6.1);
- an ideal linear polariser passes half of unpolarised light, polarised along its axis; with the
  plate's axis at 45 degrees the analyser passes |t_e - t_o|^2 / 4 of it (crossed) or
  |t_e + t_o|^2 / 4 (parallel): sin^2(pi (n_e - n_o) d / lambda) and cos^2 times the Fresnel
  losses, for an ideal retarder;
- the plugin integrates each sampled wavelength over a Gaussian band of 4 nm FWHM, and the film
  turns the spectrum into linear sRGB by Mitsuba's own colour matching
  (`mi.spectrum_to_srgb`, the mean over the sampled wavelengths of linear_rgb_rec(lambda) L times
  MI_CIE_Y_NORMALIZATION, the wavelengths drawn with the inverse pdf as weight over 360-830 nm):
  pixel = integral over 360-830 nm of (G * rgb_d65)(lambda) T(lambda) d lambda with rgb_d65 the
  channel weights times the `d65` emitter's spectrum and G the band (convolving the weights
  instead of the transmission: the same integral, G being symmetric to first order).
The weights are checked to give white (1, 1, 1) for T = 1.
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401
import scene_optics

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import michel_levy  # noqa: E402

W, H, SPP = 48, 4, 64
MAX_THICKNESS_NM = 120e3  # the scene's default max_thickness_um, stated here independently
AIR = 1.000277  # Mitsuba's "air", the plugin's default ext_ior
FWHM = 4.0  # the band this test renders the scene with (filter_bandwidth)
# Wavelength grid step (nm). The Airy fringes of the thickest column have a period of
# lambda^2 / (2 n d) >= 0.7 nm; against weights smoothed by the band the sum over them converges
# fast: a step of 0.02 nm changes the prediction by 1.2e-7.
STEP = 0.1


def ghosh_quartz(lam_nm):
    """(n_o, n_e) of crystalline quartz, Ghosh (1999), lambda in um in the formula."""
    l2 = (lam_nm * 1e-3) ** 2
    n_o = np.sqrt(1.28604141 + 1.07044083 * l2 / (l2 - 1.00585997e-2) + 1.10202242 * l2 / (l2 - 100))
    n_e = np.sqrt(1.28851804 + 1.09509924 * l2 / (l2 - 1.02101864e-2) + 1.15662475 * l2 / (l2 - 100))
    return n_o, n_e


def airy_t(n, d_nm, lam_nm):
    """Transmission amplitude of an etalon of index n and thickness d in air."""
    r = (AIR - n) / (AIR + n)
    t12, t21 = 2 * AIR / (AIR + n), 2 * n / (n + AIR)
    phi = 2 * np.pi * n * d_nm / lam_nm
    return t12 * t21 * np.exp(1j * phi) / (1 - r**2 * np.exp(2j * phi))


def colour_weights(lam):
    """Per wavelength of the grid `lam`: linear sRGB of the film times the d65 emitter's
    radiance times the grid step (so that sum(weights * T) is the pixel value)."""
    return scene_optics.colour_weights(lam, STEP)


def band_convolved(weights):
    """The weights convolved with the plugin's band (FWHM 4 nm; a Gaussian in wavenumber is one
    in wavelength to first order in FWHM / lambda)."""
    s = FWHM / (2 * math.sqrt(2 * math.log(2))) / STEP
    x = np.arange(-int(6 * s), int(6 * s) + 1)
    g = np.exp(-0.5 * (x / s) ** 2)
    g /= g.sum()
    return np.stack([np.convolve(weights[:, c], g, mode="same") for c in range(3)], axis=1)


def predicted(weights, lam, crossed, retardance_scale=1.0, sub=8):
    """Closed-form RGB per column; `retardance_scale` scales n_e - n_o (for the sensitivity
    check)."""
    n_o, n_e = ghosh_quartz(lam)
    n_e = n_o + retardance_scale * (n_e - n_o)
    out = []
    for i in range(W):
        u = (i + (np.arange(sub) + 0.5) / sub) / W
        d = MAX_THICKNESS_NM * np.clip(512 * u - 0.5, 0, 511)[:, None] / 511
        t_o, t_e = airy_t(n_o, d, lam), airy_t(n_e, d, lam)
        t = np.abs(t_e - t_o) ** 2 / 4 if crossed else np.abs(t_e + t_o) ** 2 / 4
        out.append(0.5 * (t.mean(axis=0) @ weights))
    return np.array(out)

def render(crossed: bool) -> np.ndarray:
    mi.set_variant("scalar_spectral_polarized")
    scene = mi.load_dict(michel_levy.scene(width=W, height=H, spp=SPP, crossed=crossed, filter_bandwidth=FWHM))
    return np.array(mi.render(scene, seed=1))[..., :3].mean(axis=0)  # per column, RGB


def test_wedge_colours_follow_the_closed_form():
    mi.set_variant("scalar_spectral_polarized")
    lam = np.arange(360.0, 830.0, STEP) + STEP / 2
    weights = colour_weights(lam)
    # White through nothing: Mitsuba's D65 is normalised to Y = 1 and maps to sRGB (1, 1, 1).
    np.testing.assert_allclose(weights.sum(axis=0), 1.0, atol=5e-4)
    weights = band_convolved(weights)
    for crossed in (True, False):
        got = render(crossed)
        want = predicted(weights, lam, crossed)
        rms = np.sqrt(((got - want) ** 2).mean())
        wrong = {s: np.sqrt(((got - predicted(weights, lam, crossed, s)) ** 2).mean())
                 for s in (0.5, 0.9, 1.1, 2.0)}
        print(f"{'crossed' if crossed else 'parallel'}: rms |render - closed form| = {rms:.4f} "
              f"(max {np.abs(got - want).max():.3f}); against retardance x0.5 {wrong[0.5]:.3f}, "
              f"x0.9 {wrong[0.9]:.3f}, x1.1 {wrong[1.1]:.3f}, x2 {wrong[2.0]:.3f}")
        # Measured rms 0.0091 (crossed) and 0.0086 (parallel): the Monte Carlo noise of 64 spp
        # over 4 rows (at 1024 spp it falls to 0.0020 and 0.0022, a quarter, and the mean
        # difference per channel is below 5e-4: the closed form's own neglects are smaller).
        # Bound 0.02; a retardance 10 % off gives 0.13, half or double 0.24.
        assert rms < 0.02, (crossed, rms, np.c_[got, want])
