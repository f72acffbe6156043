"""scenes/cellophane.py: the colours of one, two and three overlapping cellophane layers between
crossed polarisers, in a channel render, against the calculator's stack over the same sRGB
channels and against an independent transfer-matrix calculation.

What is rendered: at each probe of `cellophane.PROBES` (a point under a known set of strips, at
least 0.08 scene units from every strip edge) the scene seen through a 2 x 2 pixel window 0.04
units wide (one orthographic camera per probe, all on one film: a `batch` sensor), by
`render_analytic` (srgb-d65 channels; the stack is the one plate on the path, so the channel
render is exact), 1024 spp per pass with the multijitter sampler.

References:
1. the calculator (`birefringence stack`, the core's channel integration over srgb-d65: the same
   integral the plugin computes, asked through another door): the pixel is
   (1/4) (M00 + a M01 + b M10 + a b M11) of its transmission Mueller matrix per channel, a and b
   the Stokes S1 of the polariser (along x) and analyser (along y) in the calculator's frame. The
   light reaches the stack from below: the calculator is given the layers in the order the light
   meets them and a frame turned by 180 degrees about x (x' = x, y' = -y, z' = -z), so each axis
   angle is negated; at normal incidence s = y', and S1 = +1 is s (Mitsuba's convention), so
   a = -1 (x is p) and b = +1.
2. the layers' characteristic matrices (tests/python/scene_optics.py: Born & Wolf's film
   matrix per principal polarisation, every internal reflection, coherent) on a 0.1 nm grid over
   360-830 nm, through ideal polarisers, weighted by Mitsuba's colour matching and D65.

Noise. The pixel's only randomness is the stack's choice between reflection (which leaves the
view) and transmission, made with probability p_T = the unpolarised transmission (0.92-0.93
here): a pixel's estimate is n_T / (N p_T) times the exact value, with n_T the number of its N
samples that chose transmission. The multijitter sampler stratifies that choice, so n_T is
floor(N p_T) or ceil(N p_T): the relative error is below 1 / (N p_T) = 1.1e-3 at N = 1024
(measured: 2.7e-4). The layers have constant indices, so p_T is the same in the three channels
to 1e-9, every pass makes the same choices, and the ratios of the channels carry no noise at all:
they are compared to 1e-4 (float32 passes). A film 3 % thinner fails every probe but the
black one. (The order of the layers hardly matters here: between crossed polarisers along x and
y, lossless retarders in either order pass the same light; only the faces' reflections make a
difference, 7e-4 at 60 under 15 degrees, which the brightness check sees.)
"""

import math
import pathlib
import sys

import mitsuba as mi
import numpy as np
import pytest

import mitsuba_birefringent as mb
import scene_optics as so

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import cellophane  # noqa: E402
from _common import T  # noqa: E402

SPP, WINDOW = 1024, 0.04
#: Relative bound of the reflection/transmission choice's rounding: 1 / (SPP * p_T), p_T >= 0.9.
COUNT_BOUND = 1.0 / (SPP * 0.9)
STEP = 0.1  # nm: the films' multiple-reflection fringes have periods of 0.8 nm and more


def film_layers(top_first):
    """(n_o, n_e, d_nm, angle) of the strips `top_first`, in the order the light meets them."""
    return [(cellophane.INDEX, cellophane.INDEX + cellophane.BIREFRINGENCE,
             cellophane.THICKNESS_UM * 1e3, cellophane.STRIPS[k].angle_deg) for k in reversed(top_first)]


def calculator_pixel(top_first):
    """Reference 1 (module docstring): the calculator's channel values between the polarisers."""
    layers = [{"eta_o": n_o, "eta_e": n_e, "thickness_um": d_nm * 1e-3,
               "optic_axis": [math.cos(math.radians(-a)), math.sin(math.radians(-a)), 0.0]}
              for n_o, n_e, d_nm, a in film_layers(top_first)]
    q = {"wavelength_nm": 550.0, "theta_deg": 0.0, "ext_ior": so.AIR, "layers": layers,
         "spectrum": {"weights": "srgb-d65"}}
    m = np.array(so.calculator("stack", q)["mueller_T"])
    a, b = -1.0, 1.0
    return 0.25 * (m[:, 0, 0] + a * m[:, 0, 1] + b * m[:, 1, 0] + a * b * m[:, 1, 1])


@pytest.fixture(scope="module")
def rendered():
    """Every probe's window by channels, in one render (a `batch` sensor: an orthographic camera
    per probe, side by side on one film): name -> (channel values, linear sRGB), each the mean of
    the probe's 2 x 2 pixels."""
    mi.set_variant("scalar_spectral_polarized")
    names = list(cellophane.PROBES)
    d = cellophane.scene(width=2, height=2, spp=SPP)
    cameras = {}
    for k, name in enumerate(names):
        x, y, _ = cellophane.probe(cellophane.PROBES[name])
        cameras[f"probe_{k}"] = {"type": "orthographic", "to_world": T().look_at(
            origin=[x, y, 10], target=[x, y, 0], up=[0, 1, 0]) @ T().scale([WINDOW / 2, WINDOW / 2, 1])}
    d["sensor"] = {"type": "batch", **cameras,
                   "film": {"type": "hdrfilm", "width": 2 * len(names), "height": 2,
                            "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                   "sampler": {"type": "multijitter", "sample_count": SPP}}
    out = mb.render_analytic(d, spp=SPP, seed=3)
    window = lambda a, k: np.asarray(a, float)[:, 2 * k: 2 * k + 2].reshape(-1, 3).mean(axis=0)
    return {name: (window(out["channels"], k), window(out["rgb"], k)) for k, name in enumerate(names)}


def test_slots_keep_the_laying_order():
    """Every texel's strips lie in distinct slots, the later-laid strip in the higher slot, and the
    stack needs no more slots than the most strips over one texel (4: the render's cost)."""
    x, y = cellophane.texel_centres()
    slots = cellophane.slots()
    inside = np.array([s.inside(x, y) for s in cellophane.STRIPS])
    depth = inside.sum(axis=0)
    assert max(slots) + 1 == depth.max() == 4, (slots, depth.max())
    for j in range(len(slots)):
        for k in range(j):
            if (inside[j] & inside[k]).any():
                assert slots[j] > slots[k], (k, j, slots)
    # The slot textures reproduce the strips: coverage and angle per texel.
    for slot, (coverage, angle) in enumerate(cellophane.slot_textures()):
        mine = [k for k, s in enumerate(slots) if s == slot]
        covered = inside[mine].any(axis=0)
        assert np.array_equal(coverage > 0, covered), slot
        for k in mine:
            assert np.all(angle[inside[k]] == cellophane.STRIPS[k].angle_deg), (slot, k)


@pytest.fixture(scope="module")
def weights():
    mi.set_variant("scalar_spectral_polarized")
    lam = np.arange(360.0, 830.0, STEP) + STEP / 2
    w = so.colour_weights(lam, STEP)
    # White through nothing: Mitsuba's D65 maps to sRGB (1, 1, 1) (2e-4: its tables' rounding).
    np.testing.assert_allclose(w.sum(axis=0), 1.0, atol=5e-4)
    return lam, w


@pytest.mark.parametrize("name", list(cellophane.PROBES))
def test_probe_colour(name, weights, rendered):
    lam, w = weights
    mi.set_variant("scalar_spectral_polarized")
    x, y, clearance = cellophane.probe(cellophane.PROBES[name])
    assert clearance >= 0.08 > WINDOW / math.sqrt(2)  # the window lies inside the probe's region
    top_first = cellophane.covering(np.array([x]), np.array([y]))[0]
    assert sorted(top_first) == sorted(cellophane.PROBES[name])

    channels, rgb = rendered[name]
    calc = calculator_pixel(top_first)
    tm = w.T @ so.between_polarisers(so.stack_jones(film_layers(top_first), lam), 0.0, 90.0)
    print(f"{name}: render {np.round(channels, 5)}, calculator {np.round(calc, 5)}, transfer matrix "
          f"{np.round(tm, 5)} (render's sRGB {np.round(rgb, 5)})")
    if np.abs(calc).max() < 1e-6:  # the cancellation: black in every reference (float32: 1e-6)
        assert np.abs(channels).max() < 1e-6 and np.abs(tm).max() < 1e-6, (channels, tm)
        return
    # Brightness: the choice's rounding (module docstring) and float32.
    assert np.all(np.abs(channels - calc) <= COUNT_BOUND * np.abs(calc) + 1e-5), (channels, calc)
    # Colour: the ratios of the channels, free of that noise.
    assert np.abs(channels / channels.sum() - calc / calc.sum()).max() < 1e-4, (channels, calc)
    # The independent transfer matrix, against the render's linear sRGB: the rounding above,
    # plus the difference between the core's channel weights and Mitsuba's colour matching and
    # the channel integration's incoherent sum of the films' round trips (measured together:
    # at most 1.5e-4): 5e-4.
    assert np.all(np.abs(rgb - tm) <= COUNT_BOUND * np.abs(tm) + 5e-4), (rgb, tm)
