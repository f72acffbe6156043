#!/usr/bin/env python3
"""Plot the error-vs-time comparison of ``examples/bench_core.rs``.

Usage (``make bench`` runs it)::

    .venv/bin/python bench/plot_core.py [CORE_JSON] [OUT_PNG]

CORE_JSON defaults to ``bench/out/core.json`` and OUT_PNG to
``bench/out/core_error_vs_time.png``.

Log-log axes: x = time per plate (seconds, one core), y = mean CIEDE2000 of the
crossed-polariser transmission colour (``xyz-d65``) against the dense quadrature reference,
over the benchmark's random plates and seeds. Curves: stochastic spectral sampling with N
wavelengths per estimate (hero-wavelength rotations, and i.i.d. for comparison), labelled by
N; points: the closed-form (analytic) integration, mean time per plate (transmission only, and
reflection + transmission), and its per-plate median time. Error bars on the stochastic
curves: standard deviation of the per-seed means. Dashed lines: the issue's targets (mean
CIEDE2000 1 and 0.5). Every number is read from the JSON; nothing is measured here.
"""

from __future__ import annotations

import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    src = sys.argv[1] if len(sys.argv) > 1 else "bench/out/core.json"
    dst = sys.argv[2] if len(sys.argv) > 2 else "bench/out/core_error_vs_time.png"
    with open(src, encoding="utf-8") as f:
        data = json.load(f)
    evt = data["error_vs_time"]
    fig, ax = plt.subplots(figsize=(8.0, 5.6), dpi=130)

    styles = {"hero": ("C0", "o", "stochastic, hero-wavelength rotations"),
              "iid": ("C2", "s", "stochastic, i.i.d. wavelengths")}
    for name, rows in evt["stochastic"].items():
        color, marker, label = styles.get(name, ("C7", "x", name))
        t = [r["seconds_per_plate"] for r in rows]
        e = [r["mean_de"] for r in rows]
        sd = [r["std_of_seed_means"] for r in rows]
        ax.errorbar(t, e, yerr=sd, color=color, marker=marker, ms=4, lw=1.4, capsize=2,
                    label=f"{label} (N = {rows[0]['n']}..{rows[-1]['n']})")
        if name == "hero":
            for r in rows:
                ax.annotate(f"N={r['n']}", (r["seconds_per_plate"], r["mean_de"]),
                            textcoords="offset points", xytext=(4, 4), fontsize=7, color=color)

    a = evt["analytic"]
    ax.plot([a["seconds_per_plate_T"]], [a["mean_de"]], "r*", ms=13,
            label="analytic, T only (mean time per plate)")
    ax.plot([a["seconds_per_plate_RT"]], [a["mean_de"]], "r^", ms=8, mfc="none",
            label="analytic, R + T (mean time per plate)")
    ax.plot([a["median_seconds_per_plate_T"]], [a["mean_de"]], "rD", ms=6, mfc="none",
            label="analytic, T only (median per-plate time)")

    for level, style in ((evt.get("target_de", 1.0), "--"), (0.5, ":")):
        ax.axhline(level, color="0.4", ls=style, lw=0.9)
        ax.text(0.99, level, f"CIEDE2000 = {level:g} ", va="bottom", ha="right", fontsize=7,
                color="0.3", transform=ax.get_yaxis_transform())
    t1 = evt.get("stochastic_seconds_to_target")
    if t1:
        ax.axvline(t1, color="C0", ls="--", lw=0.7)

    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time per plate (s, one core)")
    ax.set_ylabel("mean CIEDE2000 vs quadrature (crossed polarisers, xyz-d65)")
    m = data.get("machine", {})
    speed = evt.get("speedup_at_target")
    speed_txt = f"{speed:.3g}x" if speed is not None else "n/a"
    ax.set_title(
        f"Spectral integration: error vs time, {evt['plates']} random plates\n"
        f"speed-up of the analytic method at CIEDE2000 {evt.get('target_de', 1.0):g} "
        f"(stochastic time / analytic mean time) = {speed_txt}\n"
        f"{m.get('cpu_model', '?')}, one core; load average at start {m.get('loadavg_at_start', '?')}",
        fontsize=9)
    ax.grid(True, which="both", alpha=0.25)
    ax.legend(fontsize=7, loc="lower left")
    fig.tight_layout()
    fig.savefig(dst)
    print(f"wrote {dst}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
