"""The inverse example (scenes/inverse_photoelastic.py) at a small size: the stressed disk's
birefringence and principal-direction textures (12 x 12 texels), fitted by gradient descent
through the renderer to noise-free targets (24 x 24 pixels, two wavelengths, three analyser
states behind a circular polariser; the targets share the fit's samples), from a uniform start,
are recovered to the issue's bar: retardance RMS <= 2 % of its range, principal direction RMS
<= 2 degrees where the retardance is above a tenth of its largest. Measured (90 iterations):
0.20 % and 0.77 degrees. The start is 38 % and 25 degrees off: a gradient of the wrong sign, or
none through `axis_angle`, leaves the direction there.
"""

from __future__ import annotations

import sys
import pathlib

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))

import inverse_photoelastic as ip  # noqa: E402


def test_small_reconstruction_meets_the_targets():
    r = ip.reconstruct(texture=12, size=24, wavelengths=(500.0, 600.0), iterations=90)
    m = r["maps"]
    span = m["true_stress"].max() - m["true_stress"].min()
    start_ret = np.sqrt(np.mean((m["start_stress"] - m["true_stress"]) ** 2)) / span
    where = m["true_stress"] > ip.NEAR_ZERO * m["true_stress"].max()
    start_dir = np.sqrt(np.mean(ip.direction_error(m["start_angle"], m["true_angle"])[where] ** 2))
    assert start_ret > 0.2 and start_dir > 20.0
    assert r["direction_texels"] > 50
    assert r["losses"][-1] < 1e-2 * r["losses"][0]
    assert r["retardance_rms_of_range"] <= 0.02, r["retardance_rms_of_range"]
    assert r["direction_rms_deg"] <= 2.0, r["direction_rms_deg"]
