#!/usr/bin/env python3
"""Reproduce Figure 1 of the supplemental of S. Steinberg, "Analytic Spectral Integration of
Birefringence-Induced Iridescence", Computer Graphics Forum 38(4), 2019.

Usage (``make render`` runs it)::

    .venv/bin/python tools/plot_fig1.py [BINARY] [OUT_DIR]

BINARY defaults to ``target/release/birefringence`` and OUT_DIR to ``out``. Writes
``OUT_DIR/fig1.png`` and ``OUT_DIR/fig1.json``.

The figure (supplement's caption): "Plots of Fresnel power ratios at isotropic-anisotropic
interfaces. The isotropic medium's index-of-refraction is fixed at η = 1 while the anisotropic
medium's constants are: η_o = 1.4, η_e = 1.55, A = [0.1, 0.9, 0.42] (normalised). The Brewster's
angle, the angle at which the reflected light is fully s-polarized, is marked with a dotted green
line and varies slightly as a function of the optic axis."

Every number comes from the calculator, ``birefringence interface --batch``, called once for the
whole angle grid (θ = 0, 0.1, ..., 89.9 degrees) and a few more times to refine the Brewster angle.

Coordinates
-----------
The paper writes vectors as (x, y, z) with x perpendicular to the plane of incidence, y along the
surface normal and z tangential (in the plane of incidence). Our local frame is Mitsuba's shading
frame: z is the surface normal (towards the exterior), and with ``phi_deg = 0`` the plane of
incidence is the local x-z plane (light arrives from the direction (sin θ, 0, cos θ)), so local x
is tangential and local y is perpendicular to the plane of incidence. Hence the paper's
A = [0.1, 0.9, 0.42] is our ``optic_axis = [0.42, 0.1, 0.9]``:

    ours = (x: tangential, y: perpendicular, z: normal) = (A_z, A_x, A_y) of the paper's A.

Signs: the supplement puts the interface in its XZ plane, the source medium at Y > 0, and writes
the incident ray as I_i = [0, cos θ, sin θ]; its +cos θ normal component points into the source
medium, so I_i points from the point of incidence back towards the source, which therefore lies
on the +z side. With ``phi_deg = 0`` our light arrives from the
direction (sin θ, 0, cos θ), i.e. from the +x side: paper +z is our +x, and paper +y (the normal
into the source medium) is our +z. The sign of the perpendicular component does not matter (mirror
symmetry in the plane of incidence); the tangential one does, slightly: with it flipped,
[-0.42, 0.1, 0.9], the Brewster angle moves by about -0.004°. The calculator normalises the axis.

Plotted quantities
------------------
Incident light is unpolarised: an equal, incoherent mix of s- and p-polarised incident power.
The calculator's ``R[ab]`` is the fraction of the incident power of polarisation ``a`` reflected
into polarisation ``b`` and ``T[a][m]`` the fraction transmitted into the crystal's mode
``m`` (o or e). For unpolarised light

    R_s = (R_ss + R_ps) / 2     reflected s power
    R_p = (R_sp + R_pp) / 2     reflected p power
    T_o = (T_s,o + T_p,o) / 2   transmitted ordinary power
    T_e = (T_s,e + T_p,e) / 2   transmitted extraordinary power

which add up to 1 (no absorption). The second panel shows the four polarisation-resolved
reflectances R_ss, R_sp, R_ps, R_pp on a log scale.

Brewster angle: the angle at which the reflected light is most nearly fully s-polarised, i.e. the
minimum of R_p / (R_s + R_p) for unpolarised incident light. It is located on the grid, then
refined by repeatedly re-sampling a shrinking bracket around the minimum (one calculator call
per round), then a parabola through the best three samples.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

WAVELENGTH_NM = 550.0  # irrelevant (no dispersion), but the calculator requires it
EXT_IOR = 1.0
ETA_O = 1.4
ETA_E = 1.55
AXIS_PAPER = (0.1, 0.9, 0.42)  # (perpendicular, normal, tangential) as printed in the supplement
OPTIC_AXIS = (AXIS_PAPER[2], AXIS_PAPER[0], AXIS_PAPER[1])  # our local frame: (0.42, 0.1, 0.9)
PHI_DEG = 0.0

THETA_STEPS_PER_DEG = 10  # grid step 0.1 degree
THETA_COUNT = 900  # 0, 0.1, ..., 89.9 degrees

POLS = ("s", "p")
MODES = ("o", "e")


class CalculatorError(RuntimeError):
    """The calculator failed or returned an error for some input."""


def case(theta_deg: float, optic_axis=OPTIC_AXIS) -> dict:
    """One calculator input line (optic axis in our local frame)."""
    return {
        "wavelength_nm": WAVELENGTH_NM,
        "ext_ior": EXT_IOR,
        "eta_o": ETA_O,
        "eta_e": ETA_E,
        "optic_axis": [float(a) for a in optic_axis],
        "theta_deg": float(theta_deg),
        "phi_deg": PHI_DEG,
        "side": "outside",
    }


def run_calculator(binary: str, thetas, optic_axis=OPTIC_AXIS) -> list[dict]:
    """Runs ``binary interface --batch`` once over ``thetas`` (degrees); one result per angle."""
    thetas = [float(t) for t in thetas]
    text = "".join(json.dumps(case(t, optic_axis)) + "\n" for t in thetas)
    try:
        proc = subprocess.run(
            [binary, "interface", "--batch"],
            input=text,
            capture_output=True,
            text=True,
            check=False,
        )
    except OSError as e:
        raise CalculatorError(f"cannot run {binary}: {e} (build it with `make setup`)") from e
    lines = [line for line in proc.stdout.splitlines() if line.strip()]
    if len(lines) != len(thetas):
        raise CalculatorError(
            f"{binary} exited {proc.returncode} with {len(lines)} output lines for "
            f"{len(thetas)} inputs; stderr:\n{proc.stderr}"
        )
    results = [json.loads(line) for line in lines]
    errors = [(t, r["error"]) for t, r in zip(thetas, results) if "error" in r]
    if errors:
        shown = "; ".join(f"theta_deg={t}: {msg}" for t, msg in errors[:5])
        raise CalculatorError(f"{len(errors)} calculator error(s): {shown}")
    if proc.returncode != 0:
        raise CalculatorError(f"{binary} exited {proc.returncode}; stderr:\n{proc.stderr}")
    return results


def curves(results: list[dict]) -> dict[str, np.ndarray]:
    """Polarisation-resolved and unpolarised power ratios as arrays over the results."""
    c: dict[str, np.ndarray] = {}
    for a in POLS:
        for b in POLS:
            c[f"R_{a}{b}"] = np.array([r["R"][a + b] for r in results], dtype=float)
        for m in MODES:
            c[f"T_{a}{m}"] = np.array([r["T"][a][m] for r in results], dtype=float)
    c["R_s"] = (c["R_ss"] + c["R_ps"]) / 2
    c["R_p"] = (c["R_sp"] + c["R_pp"]) / 2
    c["T_o"] = (c["T_so"] + c["T_po"]) / 2
    c["T_e"] = (c["T_se"] + c["T_pe"]) / 2
    return c


def p_fraction(c: dict[str, np.ndarray]) -> np.ndarray:
    """R_p / (R_s + R_p): the p-polarised fraction of the reflected power."""
    return c["R_p"] / (c["R_s"] + c["R_p"])


def brewster(binary: str, theta: np.ndarray, frac: np.ndarray, optic_axis=OPTIC_AXIS,
             rounds: int = 4, samples: int = 41):
    """Angle (degrees) minimising the reflected p fraction, refined from the grid minimum, and
    the unpolarised curves' values there.

    ``frac`` is the p fraction on the grid ``theta`` (for the same ``optic_axis``). Each round samples the current bracket at ``samples`` points (one calculator call) and
    shrinks the bracket to the neighbours of the best sample; finally a parabola through the
    best sample and its two neighbours gives the vertex (kept only if it falls between them).
    """
    i = int(np.argmin(frac))
    lo = theta[max(i - 1, 0)]
    hi = theta[min(i + 1, len(theta) - 1)]
    ts, fs = theta, frac
    for _ in range(rounds):
        ts = np.linspace(lo, hi, samples)
        fs = p_fraction(curves(run_calculator(binary, ts, optic_axis)))
        i = int(np.argmin(fs))
        lo, hi = ts[max(i - 1, 0)], ts[min(i + 1, samples - 1)]
    best = float(ts[i])
    if 0 < i < len(ts) - 1:
        (t0, t1, t2), (f0, f1, f2) = ts[i - 1 : i + 2], fs[i - 1 : i + 2]
        denom = (t0 - t1) * (f0 - f2) - (t0 - t2) * (f0 - f1)
        if denom != 0.0:
            vertex = t0 - 0.5 * ((t0 - t1) ** 2 * (f0 - f2) - (t0 - t2) ** 2 * (f0 - f1)) / denom
            if t0 < vertex < t2:
                best = float(vertex)
    c = curves(run_calculator(binary, [best], optic_axis))
    # Keep the parabola's vertex only if it is really no worse than the best sample.
    if p_fraction(c)[0] > fs[i]:
        best = float(ts[i])
        c = curves(run_calculator(binary, [best], optic_axis))
    return best, {k: float(v[0]) for k, v in c.items()}


def plot(path: Path, theta: np.ndarray, c: dict[str, np.ndarray], theta_b: float) -> None:
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 5.2), constrained_layout=True)
    fig.suptitle(
        "Fresnel power ratios at an isotropic–uniaxial interface: "
        f"isotropic η = {EXT_IOR:g}; uniaxial η_o = {ETA_O:g}, η_e = {ETA_E:g}, "
        f"A = [{', '.join(f'{a:g}' for a in AXIS_PAPER)}] (normalised; paper's axes)"
    )
    brewster_label = f"Brewster angle θ_B = {theta_b:.3f}°"

    ax1.plot(theta, c["R_s"], color="tab:blue", label="R_s = (R_ss + R_ps)/2  (reflected s)")
    ax1.plot(theta, c["R_p"], color="tab:orange", label="R_p = (R_sp + R_pp)/2  (reflected p)")
    ax1.plot(theta, c["T_o"], color="tab:purple", label="T_o = (T_s→o + T_p→o)/2  (transmitted o)")
    ax1.plot(theta, c["T_e"], color="tab:red", label="T_e = (T_s→e + T_p→e)/2  (transmitted e)")
    ax1.axvline(theta_b, color="green", linestyle=":", linewidth=1.8, label=brewster_label)
    ax1.set_title("Unpolarised incident light: fractions of the incident power")
    ax1.set_xlabel("angle of incidence θ (degrees)")
    ax1.set_ylabel("power ratio")
    ax1.set_xlim(0, 90)
    ax1.set_ylim(0, 1)
    ax1.grid(alpha=0.3)
    ax1.legend(loc="upper left", fontsize=8.5)

    styles = {"ss": "tab:blue", "sp": "tab:cyan", "ps": "tab:olive", "pp": "tab:orange"}
    for ab, color in styles.items():
        y = np.where(c[f"R_{ab}"] > 0, c[f"R_{ab}"], np.nan)
        ax2.semilogy(theta, y, color=color, label=f"R_{ab}  ({ab[0]} in → {ab[1]} out)")
    ax2.axvline(theta_b, color="green", linestyle=":", linewidth=1.8, label=brewster_label)
    ax2.set_title("Polarisation-resolved reflectances (input polarisation first)")
    ax2.set_xlabel("angle of incidence θ (degrees)")
    ax2.set_ylabel("fraction of the incident power (log scale)")
    ax2.set_xlim(0, 90)
    positive = np.concatenate([c[f"R_{ab}"][c[f"R_{ab}"] > 0] for ab in styles])
    ax2.set_ylim(max(positive.min() / 3, 1e-14), 1.5)
    ax2.grid(alpha=0.3, which="both")
    ax2.legend(loc="lower left", fontsize=8.5)

    fig.savefig(path, dpi=150)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary", nargs="?", default="target/release/birefringence",
                        help="the birefringence calculator (default: %(default)s)")
    parser.add_argument("out_dir", nargs="?", default="out",
                        help="output directory (default: %(default)s)")
    args = parser.parse_args(argv)

    out = Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    theta = np.arange(THETA_COUNT) / THETA_STEPS_PER_DEG  # k/10: the nearest doubles to 0.1 k
    try:
        results = run_calculator(args.binary, theta)
        c = curves(results)
        theta_b, at_b = brewster(args.binary, theta, p_fraction(c))
    except CalculatorError as e:
        print(f"plot_fig1: {e}", file=sys.stderr)
        return 1

    data = {
        "figure": "Steinberg 2019, supplemental Figure 1: Fresnel power ratios at an "
                  "isotropic-anisotropic interface",
        "parameters": {
            "wavelength_nm": WAVELENGTH_NM,
            "ext_ior": EXT_IOR,
            "eta_o": ETA_O,
            "eta_e": ETA_E,
            "optic_axis_paper": list(AXIS_PAPER),
            "optic_axis_local": list(OPTIC_AXIS),
            "phi_deg": PHI_DEG,
            "side": "outside",
        },
        "definitions": {
            "R_s": "(R_ss + R_ps)/2, reflected s power, unpolarised incident light",
            "R_p": "(R_sp + R_pp)/2, reflected p power, unpolarised incident light",
            "T_o": "(T_s,o + T_p,o)/2, transmitted o power, unpolarised incident light",
            "T_e": "(T_s,e + T_p,e)/2, transmitted e power, unpolarised incident light",
            "R_ab": "fraction of incident a-polarised power reflected into b",
            "brewster": "argmin over theta of R_p/(R_s + R_p)",
        },
        "theta_deg": theta.tolist(),
        "unpolarised": {k: c[k].tolist() for k in ("R_s", "R_p", "T_o", "T_e")},
        "R": {a + b: c[f"R_{a}{b}"].tolist() for a in POLS for b in POLS},
        "T": {a: {m: c[f"T_{a}{m}"].tolist() for m in MODES} for a in POLS},
        "brewster": {
            "theta_deg": theta_b,
            "R_s": at_b["R_s"],
            "R_p": at_b["R_p"],
            "p_fraction": at_b["R_p"] / (at_b["R_s"] + at_b["R_p"]),
            "isotropic_eta_o_deg": math.degrees(math.atan(ETA_O / EXT_IOR)),
            "isotropic_eta_e_deg": math.degrees(math.atan(ETA_E / EXT_IOR)),
        },
    }
    json_path = out / "fig1.json"
    json_path.write_text(json.dumps(data, indent=1) + "\n")
    png_path = out / "fig1.png"
    plot(png_path, theta, c, theta_b)
    print(
        f"wrote {png_path} and {json_path}: Brewster angle {theta_b:.6f} deg "
        f"(R_p/R_s there = {at_b['R_p'] / at_b['R_s']:.3e}; isotropic η_o, η_e: "
        f"{data['brewster']['isotropic_eta_o_deg']:.3f}, "
        f"{data['brewster']['isotropic_eta_e_deg']:.3f} deg)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
