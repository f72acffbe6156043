"""Figure 1 of the supplement, reproduced by tools/plot_fig1.py with the calculator binary.

Needs ``target/release/birefringence`` (``make setup`` builds it; ``BIREFRINGENCE_BIN`` overrides
the path).
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import struct
import subprocess
import sys
import zlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "tools" / "plot_fig1.py"
BINARY = Path(os.environ.get("BIREFRINGENCE_BIN", ROOT / "target" / "release" / "birefringence"))

ETA_O, ETA_E = 1.4, 1.55


def brewster_closed_form(axis: str) -> float:
    """Brewster angle (degrees), exterior index 1, for a principal orientation of the optic axis.

    The p wave is then a pure e- (or o-) wave and r_pp vanishes where
    * axis along the normal:      sin²θ = η_e²(η_o² − 1) / (η_o²η_e² − 1)
    * axis along the tangential:  sin²θ = η_o²(η_e² − 1) / (η_o²η_e² − 1)
    * axis perpendicular to the plane of incidence: the p wave sees η_o only, tan θ = η_o.
    """
    o2, e2 = ETA_O**2, ETA_E**2
    if axis == "normal":
        return math.degrees(math.asin(math.sqrt(e2 * (o2 - 1) / (o2 * e2 - 1))))
    if axis == "tangential":
        return math.degrees(math.asin(math.sqrt(o2 * (e2 - 1) / (o2 * e2 - 1))))
    if axis == "perpendicular":
        return math.degrees(math.atan(ETA_O))
    raise ValueError(axis)


def load_script():
    spec = importlib.util.spec_from_file_location("plot_fig1", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def fig1(tmp_path_factory):
    if not BINARY.is_file():
        pytest.fail(f"{BINARY} does not exist: run `make setup` (cargo build --release) first")
    out = tmp_path_factory.mktemp("fig1")
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), str(BINARY), str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert proc.returncode == 0, f"plot_fig1.py failed:\n{proc.stdout}\n{proc.stderr}"
    data = json.loads((out / "fig1.json").read_text())
    return out, data


def png_chunks(blob: bytes):
    """(type, data) of every chunk of a PNG, checking the signature and every CRC."""
    assert blob[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG signature"
    pos, chunks = 8, []
    while pos < len(blob):
        (length,) = struct.unpack(">I", blob[pos : pos + 4])
        kind = blob[pos + 4 : pos + 8]
        data = blob[pos + 8 : pos + 8 + length]
        (crc,) = struct.unpack(">I", blob[pos + 8 + length : pos + 12 + length])
        assert zlib.crc32(kind + data) == crc, f"bad CRC in chunk {kind!r}"
        chunks.append((kind, data))
        pos += 12 + length
    return chunks


def test_png_is_a_valid_figure(fig1):
    out, _ = fig1
    path = out / "fig1.png"
    assert path.is_file()
    blob = path.read_bytes()
    assert 20_000 < len(blob) < 5_000_000
    chunks = png_chunks(blob)
    assert chunks[0][0] == b"IHDR" and chunks[-1][0] == b"IEND"
    width, height = struct.unpack(">II", chunks[0][1][:8])
    assert width >= 1000 and height >= 500, (width, height)
    assert width > height  # two panels side by side
    # It decodes, and is not a blank canvas.
    import matplotlib.image

    pixels = matplotlib.image.imread(path)
    assert pixels.shape[:2] == (height, width)
    assert float(np.std(pixels[..., :3])) > 0.05


def test_angles_and_curves(fig1):
    _, d = fig1
    theta = np.array(d["theta_deg"])
    assert len(theta) == 900
    assert theta[0] == 0.0 and theta[-1] == pytest.approx(89.9, abs=1e-12)
    assert np.allclose(np.diff(theta), 0.1, atol=1e-12)
    for name, values in d["unpolarised"].items():
        v = np.array(values)
        assert v.shape == theta.shape, name
        assert np.all((v >= 0) & (v <= 1)), name
    # The unpolarised curves are the documented averages of the polarisation-resolved ones.
    R, T, u = d["R"], d["T"], d["unpolarised"]
    half = lambda a, b: (np.array(a) + np.array(b)) / 2  # noqa: E731
    assert np.allclose(u["R_s"], half(R["ss"], R["ps"]), rtol=0, atol=1e-15)
    assert np.allclose(u["R_p"], half(R["sp"], R["pp"]), rtol=0, atol=1e-15)
    assert np.allclose(u["T_o"], half(T["s"]["o"], T["p"]["o"]), rtol=0, atol=1e-15)
    assert np.allclose(u["T_e"], half(T["s"]["e"], T["p"]["e"]), rtol=0, atol=1e-15)


def test_energy_is_conserved(fig1):
    _, d = fig1
    u = {k: np.array(v) for k, v in d["unpolarised"].items()}
    total = u["R_s"] + u["R_p"] + u["T_o"] + u["T_e"]
    worst = int(np.argmax(np.abs(total - 1)))
    assert abs(total[worst] - 1) <= 1e-12, (d["theta_deg"][worst], total[worst])


def test_normal_incidence_reflectance_between_isotropic_values(fig1):
    _, d = fig1
    u = d["unpolarised"]
    assert d["theta_deg"][0] == 0.0
    r0 = u["R_s"][0] + u["R_p"][0]
    lo = ((ETA_O - 1) / (ETA_O + 1)) ** 2
    hi = ((ETA_E - 1) / (ETA_E + 1)) ** 2
    assert lo <= r0 <= hi, (lo, r0, hi)


def test_brewster_angle(fig1):
    _, d = fig1
    b = d["brewster"]
    theta_b = b["theta_deg"]
    # Not between atan(η_o) and atan(η_e): with the optic axis close to the normal, as here, the
    # Brewster angle is below atan(η_o) (axis exactly along the normal: 52.05°). It lies between
    # the closed forms for the axis along the normal and along the tangential direction.
    assert brewster_closed_form("normal") < theta_b < brewster_closed_form("tangential")
    assert abs(theta_b - brewster_closed_form("normal")) < 2.0  # axis ~25° from the normal
    # Reflected light is (almost) fully s-polarised there.
    assert b["R_p"] < 1e-3 * b["R_s"]
    # It is the minimum of the p fraction: no grid angle does better.
    u = {k: np.array(v) for k, v in d["unpolarised"].items()}
    frac = u["R_p"] / (u["R_s"] + u["R_p"])
    assert b["p_fraction"] <= frac.min()
    assert abs(d["theta_deg"][int(np.argmin(frac))] - theta_b) <= 0.1


@pytest.mark.parametrize("axis_name, axis", [
    ("normal", (0.0, 0.0, 1.0)),
    ("tangential", (1.0, 0.0, 0.0)),
    ("perpendicular", (0.0, 1.0, 0.0)),
])
def test_brewster_search_matches_closed_forms(axis_name, axis):
    """The script's Brewster search, on principal axes where the answer is known exactly."""
    if not BINARY.is_file():
        pytest.fail(f"{BINARY} does not exist: run `make setup` first")
    f = load_script()
    theta = np.arange(900) / 10
    c = f.curves(f.run_calculator(str(BINARY), theta, axis))
    theta_b, at_b = f.brewster(str(BINARY), theta, f.p_fraction(c), axis)
    assert theta_b == pytest.approx(brewster_closed_form(axis_name), abs=1e-6)
    assert at_b["R_p"] < 1e-20


def test_script_reports_a_broken_calculator(tmp_path):
    proc = subprocess.run(
        [sys.executable, str(SCRIPT), "/bin/false", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert proc.returncode == 1
    assert "plot_fig1:" in proc.stderr
    assert not (tmp_path / "fig1.png").exists()
