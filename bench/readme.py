#!/usr/bin/env python3
"""Regenerate the benchmark section of README.md from bench/results.json.

    .venv/bin/python bench/readme.py [RESULTS_JSON] [README]

Replaces everything between the lines ``<!-- bench:begin -->`` and ``<!-- bench:end -->`` of the
README (both must be present, once each) with tables of the figures in the results file: the
machine and date, the render-time overhead against Mitsuba's own plugins, the speed-up of the
closed-form spectral integration (or band filter) at equal image error per scene, and the
speed ratios of the core's shortcuts. Nothing is measured or typed here: every number comes
from the JSON that ``make bench`` wrote.
"""

from __future__ import annotations

import json
import pathlib
import sys

BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"

SHORTCUT_TEXT = {
    "intensity_only": "intensity only (M00) instead of Mueller matrices, 1000 um plate, 4 nm band (core)",
    "incoherent_thick_plate": "incoherent thick plate (2 coherent orders + closed-form tail) vs the coherent path sum, 1000 um, 4 nm band (core)",
    "isotropic_fast_path": "isotropic fast path vs eta_e = eta_o + 1e-9, exact plate at one wavelength (core)",
    "one_lobe": "transmission only vs both lobes, 1000 um plate, 4 nm band (core)",
    "isotropic_fast_path_scene_thin": "isotropic fast path, room with 3 `thinbirefringent` panes (scene, scalar_spectral_polarized)",
    "isotropic_fast_path_scene_bulk": "isotropic fast path, room with a `birefringent` sphere and cube (scene, scalar_spectral_polarized)",
}


def fmt_load(load) -> str:
    return f"{load[0]:.2f}" if load else "n/a"


def busy(m: dict) -> str:
    """A warning when the load average exceeded the number of cores during the run."""
    loads = [x[0] for x in (m.get("load_average_start"), m.get("load_average_end")) if x]
    if loads and max(loads) > (m.get("logical_cores") or 1):
        return (" (above the number of cores: other jobs shared the machine, so the times are "
                "noisier and longer than on an idle one)")
    return ""


def section(r: dict) -> str:
    m = r["machine"]
    o = r["overhead_vs_mitsuba_by_variant"]
    s = r["settings"]["overhead"]
    lines = [
        f"Measured by `make bench-scenes` (the last step of `make bench`) on {r['date']}: {m['cpu']}, "
        f"{m['logical_cores']} logical cores ({m['system']}), Mitsuba {r['mitsuba']}; scene benchmark "
        f"{r['bench_seconds'] / 60:.1f} min; load average (1 min) {fmt_load(m.get('load_average_start'))} "
        f"at the start and {fmt_load(m.get('load_average_end'))} at the end{busy(m)}. Figures from "
        "`bench/results.json` (every measurement in `bench/out/scenes.json` and `shortcuts.json`, plots "
        "`bench/out/error_vs_time-<scene>.png`), written by `bench/readme.py`.",
        "",
        f"**Render time against Mitsuba's own plugins** (same room scene, {s['size']}x{s['size']} px, "
        f"{s['spp']} spp, {s['integrator']}, isotropic parameters, median of {s['repeats']} interleaved renders; "
        "goal <= 1.5):",
        "",
        "| ours / Mitsuba's | " + " | ".join(o) + " |",
        "| --- | " + " | ".join("---" for _ in o) + " |",
    ]
    for name, ref in (("thinbirefringent", "thindielectric"), ("birefringent", "dielectric")):
        lines.append(f"| `{name}` / `{ref}` | " + " | ".join(f"{o[v][name]:.2f}" for v in o) + " |")
    lines += [
        "",
        "**At equal error** (mean CIEDE2000 against an exact per-wavelength reference): time exact "
        "per-wavelength sampling needs to reach the error of the method, divided by the method's time "
        "(goal for the thin film with scalar_rgb: >= 50):",
        "",
        "| scene | image | method | method's spp | its error | its time (s) | exact sampling's time (s) | ratio |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    label = {"rgb": "analytic RGB (scalar_rgb)", "filter": "4 nm band filter"}
    frames = r["settings"].get("frames", {})
    for scene, d in r["equal_error_detail"].items():
        flag = " (extrapolated)" if d["extrapolated"] else ""
        lines.append(f"| {scene} | {image(frames.get(scene))} | {label[d['method']]} | {d['spp']} | {d['error']:.3f} | "
                     f"{d['seconds']:.2f} | {d['exact_seconds_at_error']:.2f} | {d['ratio']:.3g}{flag} |")
    lines += ["", "**Shortcuts** (speed of the full computation's time over the shortcut's):", "",
              "| shortcut | speed ratio |", "| --- | --- |"]
    for k, v in r["shortcuts"].items():
        lines.append(f"| {SHORTCUT_TEXT.get(k, k)} | {v:.2f} |")
    return "\n".join(lines)


def image(frame: dict | None) -> str:
    """'32x32', or '32x32 crop of 256x256' for a scene rendered as a crop (bench/scenes.py CROPS)."""
    if not frame:
        return "?"
    w, h = frame["crop"][2:]
    full = frame["size"]
    return f"{w}x{h}" if [w, h] == full else f"{w}x{h} crop of {full[0]}x{full[1]}"


def main() -> int:
    src = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "bench/results.json")
    readme = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else "README.md")
    text = readme.read_text(encoding="utf-8")
    if text.count(BEGIN) != 1 or text.count(END) != 1 or text.index(BEGIN) > text.index(END):
        print(f"{readme}: needs one '{BEGIN}' line followed by one '{END}' line", file=sys.stderr)
        return 1
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    body = section(json.loads(src.read_text(encoding="utf-8")))
    readme.write_text(f"{head}{BEGIN}\n{body}\n{END}{tail}", encoding="utf-8")
    print(f"{readme}: benchmark section regenerated from {src}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
