"""Channel renders (`render_analytic`) with each weight set, on a scene whose Stokes vector is
known in closed form and has a large S3: D65 (or, for xyz-e, equal-energy) light through a linear
polariser at +45 degrees and a quarter-wave plate with its axis along x, seen directly and
through two circular analysers of opposite handedness (Mitsuba's `retarder`, a quarter wave with
its fast axis at +-45 degrees, then a `polarizer` along x).

The plate has constant indices n_o = 1.544, n_e = 1.553 (no dispersion), is a quarter wave at
550 nm (d = 550 nm / (4 (n_e - n_o))) and sits between media of index 1.55 (its faces reflect
~1e-6: no etalon ripple, and the renders are deterministic: the plate's reflection lobe is almost
never chosen). So at each wavelength it is an ideal retarder of delta = (pi / 2)(550 / lambda):
after it S = (1, 0, cos delta, sin delta) / 2 (S3 > 0: a positive crystal delays the wave along
its axis, as tests/python/test_scene_waveplates.py checks at 550 nm), and an ideal circular
analyser passes (S0 +- S3) / 2. Each channel's value is then the channel-weighted mean of these
over wavelength, computed here from Mitsuba's CIE 1931 tables and D65 spectrum.

Checked: the channel values of each weight set against those closed forms, and every Stokes
image in linear sRGB against the fixed-wavelength reference (tests/python/channel_reference.py);
a coloured light, in the D65 sets, comes out as its own colour (the scene's colours become
channel values through the inverse of the channel matrix, the passes back to sRGB through the
matrix).
"""

from __future__ import annotations

import functools
import pathlib
import sys

import mitsuba as mi
import numpy as np
import pytest

import mitsuba_birefringent as mb
from bfr_helpers import variant
from channel_reference import WAVELENGTHS, channel_weights, combine, transfer
from mitsuba_birefringent.library import channel_matrix

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))

N_O, N_E, DESIGN_NM = 1.544, 1.553, 550.0
THICKNESS_UM = DESIGN_NM / (4 * (N_E - N_O)) * 1e-3
WHITE = {"srgb-d65": {"type": "d65"}, "xyz-d65": {"type": "d65"},
         "xyz-e": {"type": "uniform", "value": 1.0}}
#: Tolerance of a channel value (S0 of the light after the polariser is 0.5): the core's
#: Gaussian fits of the weights are within 2e-3 (L1) of the tables, of which a smooth spectrum
#: sees a small part. Measured worst: 4.7e-5 against the closed forms, 1.4e-4 against the
#: fixed-wavelength reference (its 5-nm quadrature), in all three sets.
ATOL = 5e-4


def scene(light: dict, spp: int = 4) -> dict:
    """Columns of a 3 x 1 image: the light after polariser and plate; through a circular
    analyser with the retarder's fast axis at +45 degrees; at -45 degrees."""
    from _common import T, layer, ortho_sensor

    variant("scalar_spectral_polarized")
    plate = {"type": "thinbirefringent", "eta_o": N_O, "eta_e": N_E, "optic_axis": [1, 0, 0],
             "thickness": THICKNESS_UM, "ext_ior": 1.55, "exit_ior": 1.55}
    d = {"type": "scene",
         "integrator": {"type": "stokes", "integrator": {"type": "volpath", "max_depth": 8}},
         "sensor": ortho_sensor(3, 1, spp, 1.5, 0.5),
         "light": {"type": "rectangle", "to_world": T().translate([0, 0, -3]).scale([4, 4, 1]),
                   "emitter": {"type": "area", "radiance": light}},
         # Mitsuba's polarizer transmits along -theta (scenes/_common.py): +45 degrees.
         "polarizer": layer(-2.0, 2, 2, {"type": "polarizer", "theta": -45.0}),
         "plate": layer(0.0, 2, 2, plate)}
    for name, theta, x in (("a", 45.0, 0.0), ("b", -45.0, 1.0)):
        d[f"retarder_{name}"] = layer(1.0, 0.5, 0.5, {"type": "retarder", "theta": theta,
                                                      "delta": 90.0}, centre_x=x)
        d[f"analyser_{name}"] = layer(1.5, 0.5, 0.5, {"type": "polarizer", "theta": 0.0},
                                      centre_x=x)
    return d


def closed_form(weights: str) -> tuple[np.ndarray, np.ndarray]:
    """Per channel of `weights`: (S0..S3 of the first column, S0 of the analysers' columns as
    (S0 + S3) / 2 and (S0 - S3) / 2), each the channel-weighted mean over wavelength."""
    w = channel_weights(weights)
    w = w / w.sum(axis=0)
    delta = 0.5 * np.pi * DESIGN_NM / WAVELENGTHS
    s = 0.5 * np.stack([np.ones_like(delta), np.zeros_like(delta), np.cos(delta), np.sin(delta)])
    first = s @ w  # (4, channels)
    return first, np.stack([(first[0] + first[3]) / 2, (first[0] - first[3]) / 2])


@functools.lru_cache(maxsize=None)
def white_transfer() -> np.ndarray:
    """The scene's transfer at each wavelength of the reference (one set of renders for every
    weight set: what the scene does to light does not depend on the illuminant)."""
    return transfer(scene({"type": "d65"}), spp=4, seed=3)


def in_channels(stokes: np.ndarray, weights: str) -> np.ndarray:
    """Linear-sRGB Stokes images (..., 4, 3) as the weight set's channel values."""
    return stokes @ np.linalg.inv(np.array(channel_matrix(weights))).T


@pytest.mark.parametrize("weights", list(WHITE))
def test_each_weight_set_renders_a_known_s3(weights):
    out = mb.render_analytic(scene(WHITE[weights]), spp=4, weights=weights)
    channels = in_channels(out["stokes"][0], weights)  # (columns, 4, channels)
    first, analysers = closed_form(weights)
    assert np.all(first[3] > 0.9 * first[0])  # a large S3 in every channel
    np.testing.assert_allclose(out["channels"][0, 0], first[0], atol=ATOL)
    np.testing.assert_allclose(channels[0], first, atol=ATOL)
    # One analyser passes the circular light, the other blocks it: which one is Mitsuba's
    # retarder convention (the same in the reference below).
    through = channels[1:, 0, :]
    bright = int(np.argmax(through[:, 1]))
    np.testing.assert_allclose(through[bright], analysers[0], atol=ATOL)
    np.testing.assert_allclose(through[1 - bright], analysers[1], atol=ATOL)
    ref = combine(white_transfer(), weights)[0]
    worst = float(np.abs(out["stokes"][0] - ref).max())
    worst_closed = max(float(np.abs(channels[0] - first).max()),
                       float(np.abs(through[[bright, 1 - bright]] - analysers).max()))
    print(f"{weights}: S3/S0 {first[3] / first[0]}; worst |ours - closed form| {worst_closed:.1e}, "
          f"|ours - fixed-wavelength reference| {worst:.1e} (sRGB)")
    np.testing.assert_allclose(out["stokes"][0], ref, atol=ATOL)


@pytest.mark.parametrize("weights", ["srgb-d65", "xyz-d65"])
def test_a_coloured_light_keeps_its_colour_in_each_weight_set(weights):
    """An rgb light c: after the polariser the first column's S0 is c / 2 in linear sRGB; every
    Stokes component of each column is the closed form times the light's channel values
    (A^-1 c, with A the channel matrix inverted here)."""
    colour = np.array([0.9, 0.5, 0.2])
    out = mb.render_analytic(scene({"type": "rgb", "value": colour.tolist()}), spp=4,
                             weights=weights)
    np.testing.assert_allclose(out["rgb"][0, 0], colour / 2, atol=ATOL)
    a = np.array(channel_matrix(weights))
    light = np.linalg.solve(a, colour)
    first, _ = closed_form(weights)
    want = (first * light) @ a.T  # (4, 3): channels scaled by the light, back to sRGB
    np.testing.assert_allclose(out["stokes"][0, 0], want, atol=ATOL)
