#!/usr/bin/env python3
"""Regenerate the benchmark page docs/benchmarks.md, and the summary of it in README.md, from
bench/results.json.

    .venv/bin/python bench/readme.py [RESULTS_JSON] [BENCHMARKS_MD] [README]

In BENCHMARKS_MD (default docs/benchmarks.md) it replaces everything between the lines
``<!-- bench:begin -->`` and ``<!-- bench:end -->`` (both must be present, once each) with tables
of the figures in the results file: the machine and date, the render-time overhead against
Mitsuba's own plugins (each row labelled isotropic or anisotropic, each figure against the goal
the results state for it: bench/scenes.py's ``OVERHEAD_GOALS``), the speed-up of the closed-form
spectral integration (or band filter) at equal image error per scene, the channel render's
(``render_analytic``) at equal error and the equal-time figure of bench/equal_time.py, each
against its goal (``GOALS``: met or not met), and every measured speed ratio of each of the
core's shortcuts. In README (default README.md) it replaces what lies between
``<!-- bench-summary:begin -->`` and ``<!-- bench-summary:end -->`` with a few lines of headline
ratios (``summary``: the overhead's range per kind of row and variant, the channel render's
ratio at equal error), which follow new rows of the tables by themselves. Nothing is measured
or typed here: every number comes from the JSON that ``make bench`` wrote.
"""

from __future__ import annotations

import json
import os
import pathlib
import sys

BEGIN, END = "<!-- bench:begin -->", "<!-- bench:end -->"
SUMMARY_BEGIN, SUMMARY_END = "<!-- bench-summary:begin -->", "<!-- bench-summary:end -->"
#: Where the tables and the summary go, relative to the repository (the defaults of main).
BENCHMARKS_MD, README_MD = "docs/benchmarks.md", "README.md"

# The goals the figures are judged against (the project's requirements), in one place:
# (comparison, bound).
# (The overhead table's goals are bench/scenes.py's OVERHEAD_GOALS, stated in results.json.)
GOALS = {
    "thin_film_rgb_equal_error": (">=", 50.0),  # the thin film's analytic RGB at equal error
    # the channel render (render_analytic) at 16 spp against exact sampling at equal error, in
    # scalar_spectral_polarized and in llvm_ad_spectral_polarized, for CHANNEL_GOAL_SCENES
    "channel_render_equal_error": (">=", 50.0),
}
#: The scenes the channel render's goal is set for (the others are reported without one), and
#: the channel render's spp it is judged at.
CHANNEL_GOAL_SCENES, CHANNEL_GOAL_SPP = ("photoelastic_disk", "michel_levy"), 16

# Each shortcut of examples/bench_shortcuts.rs (and bench/scenes.py's scene-level ones): what it
# replaces, and each case it was timed on (keys of results.json's "shortcut_cases").
SHORTCUTS = {
    "intensity_only": ("intensity only (M00) instead of Mueller matrices", {
        "1000um_band4nm": "1000 um plate, 4 nm band (core)",
        "1um_band4nm": "1 um plate, 4 nm band (core)",
    }),
    "incoherent_thick_plate": ("incoherent thick plate (2 coherent orders + closed-form tail)", {
        "1000um_vs_paths": "1000 um plate, 4 nm band, vs the coherent path sum (core)",
        "100um_vs_paths": "100 um plate, 4 nm band, vs the coherent path sum (core)",
        "100um_vs_quadrature": "100 um plate, 4 nm band, vs quadrature resolving every fringe (core)",
    }),
    "isotropic_fast_path": ("isotropic fast path vs eta_e = eta_o + 1e-9", {
        "plate_exact": "exact plate at one wavelength (core)",
        "plate_1000um_band4nm": "1000 um plate, 4 nm band (core)",
        "crystal_surface": "bulk crystal surface (core)",
        "scene_thin": "room with 3 `thinbirefringent` panes (scene, scalar_spectral_polarized)",
        "scene_bulk": "room with a `birefringent` sphere and cube (scene, scalar_spectral_polarized)",
    }),
    "one_lobe": ("transmission only vs both lobes", {
        "plate_1000um_band4nm": "1000 um plate, 4 nm band (core)",
        "plate_exact": "exact plate at one wavelength (core)",
    }),
}


def verdict(goal: str, value: float) -> str:
    """'met' or 'not met' for `value` against GOALS[goal]."""
    op, bound = GOALS[goal]
    ok = value <= bound if op == "<=" else value >= bound
    return "met" if ok else "not met"


def goal_text(goal: str) -> str:
    op, bound = GOALS[goal]
    return f"{op} {bound:g}"


def fmt_load(load) -> str:
    return f"{load[0]:.2f}" if load else "n/a"


def busy(m: dict) -> str:
    """A warning when the load average exceeded the number of cores during the run."""
    loads = [x[0] for x in (m.get("load_average_start"), m.get("load_average_end")) if x]
    if loads and max(loads) > (m.get("logical_cores") or 1):
        return (" (above the number of cores: other jobs shared the machine, so the times are "
                "noisier and longer than on an idle one)")
    return ""


def section(r: dict, base: str = "") -> str:
    """The benchmark page's generated part; `base`: the path from the page to the repository's
    root (links to files of the repository start with it)."""
    m = r["machine"]
    lines = [
        f"Measured by `make bench-scenes` (the last step of `make bench`) on {r['date']}: {m['cpu']}, "
        f"{m['logical_cores']} logical cores ({m['system']}), Mitsuba {r['mitsuba']}; scene benchmark "
        f"{r['bench_seconds'] / 60:.1f} min; load average (1 min) {fmt_load(m.get('load_average_start'))} "
        f"at the start and {fmt_load(m.get('load_average_end'))} at the end{busy(m)}; a table that was "
        "measured later on its own gives its own date and load. Figures from "
        "`bench/results.json` (every measurement in `bench/out/scenes.json` and `shortcuts.json`, plots "
        "`bench/out/error_vs_time-<scene>.png`), written by `bench/readme.py`.",
        "",
    ]
    lines += overhead_table(r["overhead"])
    lines += [
        "",
        "**At equal error** (mean CIEDE2000 against an exact per-wavelength reference): time exact "
        "per-wavelength sampling needs to reach the error of the method, divided by the method's time "
        f"(goal for the thin film with scalar_rgb: {goal_text('thin_film_rgb_equal_error')}; the other "
        "scenes have none):",
        "",
        "| scene | image | method | method's spp | its error | its time (s) | exact sampling's time (s) | ratio | goal |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    label = {"rgb": "analytic RGB (scalar_rgb)", "filter": "4 nm band filter"}
    frames = r["settings"].get("frames", {})
    for scene, d in r["equal_error_detail"].items():
        flag = " (extrapolated)" if d["extrapolated"] else ""
        goal = "—"
        if scene == "thin_film" and d["method"] == "rgb":
            g = "thin_film_rgb_equal_error"
            goal = f"{goal_text(g)}: {verdict(g, d['ratio'])}"
        lines.append(f"| {scene} | {image(frames.get(scene))} | {label[d['method']]} | {d['spp']} | {d['error']:.3f} | "
                     f"{d['seconds']:.2f} | {d['exact_seconds_at_error']:.2f} | {d['ratio']:.3g}{flag} | {goal} |")
    lines += channel_section(r, base)
    lines += ["", "**Shortcuts** (speed of the full computation's time over the shortcut's, every case "
              "measured; below 1 the shortcut is slower there):", "",
              "| shortcut | case | speed ratio |", "| --- | --- | --- |"]
    lines += shortcut_rows(r)
    return "\n".join(lines)


def within(value: float, at_most: float) -> str:
    """An overhead figure's verdict against its goal (results.json's per row and variant)."""
    return f"<= {at_most:g}: {'met' if value <= at_most else 'not met'}"


def overhead_table(o: dict) -> list[str]:
    """The overhead paragraph and table: one row per pair, labelled isotropic or anisotropic,
    each figure with its goal (as results.json states it) and verdict."""
    s, m = o["settings"], o["measured"]
    variants = s["variants"]
    goals = "; ".join(f"{g['what']} <= {g['at_most']:g}" for g in s["goals"].values())
    channel = s.get("channel_pass", {})
    header = [f"{v}: one render_analytic pass ({c})" if (c := channel.get(v)) else v for v in variants]
    kernels = s.get("kernels_while_timed", {})
    jit = [v for v in variants if v.startswith("llvm_")]
    lines = [
        f"**Render time against Mitsuba's own plugins**, measured on {m['date']} by `{m['command']}` "
        f"({m['seconds'] / 60:.1f} min; load average (1 min) {fmt_load(m.get('load_average_start'))} at "
        f"the start and {fmt_load(m.get('load_average_end'))} at the end{busy(m)}): the same room "
        f"({s['size']}x{s['size']} px, {s['spp']} spp, {s['integrator']}) with ours and with the plugin a "
        f"user would use instead, median of {s['repeats']} interleaved renders, ours / Mitsuba's. "
        "*Isotropic* rows have eta_o = eta_e (the core's isotropic fast path); *anisotropic* rows are "
        "birefringent (the core's general path). "
        + (f"In the llvm variants ({', '.join(jit)}) ours render in Dr.Jit's evaluated mode, which they "
           "need; while a scene of ours exists in a process no symbolic render can run, so both rooms of "
           "a pair are timed in evaluated mode, interleaved, and then, ours deleted, Mitsuba's rooms in "
           "evaluated against symbolic mode (Mitsuba's default), interleaved: the figure is ours against "
           "Mitsuba's symbolic mode, the product of the two ratios (against its evaluated mode after "
           "\"evaluated:\"). Every configuration is rendered once at the timed spp before the rounds "
           "(this compiles Dr.Jit's kernels); a timed render during which Dr.Jit compiled a kernel (in "
           "evaluated mode a new seed can need a new kernel variant) is repeated at once with its seed and "
           "the repeat timed: "
           + "; ".join(f"{v} {k['repeated_renders']} renders repeated, {k['compiled']} kernels compiled "
                       f"in the timed renders of {k['launched']} launched"
                       for v in jit if (k := kernels.get(v)))
           + ". " if jit else "")
        + (f"The channel-pass column is one pass of `mitsuba_birefringent.render_analytic`: the room "
           "rewritten for one colour channel as `render_analytic` rewrites it (our plates integrate over "
           "the channel in closed form; walls and light take their channel value) and rendered in the "
           "pass's variant, against the same rewritten room with `thindielectric` in the same variant, "
           "timed as above (loading excluded, as in every column). " if channel else "")
        + f"Each figure against its goal: {goals}. —: not timed (a bulk crystal needs a polarised "
        "variant; the channel pass is timed for the quartz plates).",
        "",
        "| kind | scene: ours vs Mitsuba's | " + " | ".join(header) + " |",
        "| --- | --- | " + " | ".join("---" for _ in variants) + " |",
    ]
    for row in o["rows"].values():
        cells = []
        for v in variants:
            x = row["ratio"].get(v)
            e = row.get("ratio_vs_evaluated", {}).get(v)
            cells.append("—" if x is None else f"{x:.2f} ({within(x, row['goal'][v])})"
                         + ("" if e is None else f"; evaluated: {e:.2f}"))
        lines.append(f"| {row['kind']} | {row['what']} | " + " | ".join(cells) + " |")
    for row in o["rows"].values():
        if "measured" in row:  # measured apart (bench/scenes.py --pairs), with the same settings
            r = row["measured"]
            lines.append(f"\nThe row \"{row['what']}\" was measured on its own on {r['date']} by "
                         f"`{r['command']}` ({r['seconds'] / 60:.1f} min; load average (1 min) "
                         f"{fmt_load(r.get('load_average_start'))} at the start and "
                         f"{fmt_load(r.get('load_average_end'))} at the end{busy(r)}), as above.")
    return lines


def channel_section(r: dict, base: str = "") -> list[str]:
    """The channel render's tables (results.json "channel_render") and the equal-time figure
    ("equal_time", written by bench/equal_time.py); nothing when the results lack them."""
    channel = r.get("channel_render")
    if not channel:
        return []
    s = r["settings"]
    jit = s["jit"]
    frames = s.get("frames", {})
    lines = [
        "",
        "**The channel render at equal error** (`mitsuba_birefringent.render_analytic`: one "
        "llvm_ad_mono_polarized pass per sRGB channel, the plate integrated over each channel in closed "
        "form), against the same exact per-wavelength reference (its own error, from the spread of its "
        "passes, in the reference column): the time exact per-wavelength sampling needs to reach the "
        "channel render's mean CIEDE2000, in scalar_spectral_polarized and in "
        f"{jit['variant']} (evaluated mode, passes of {jit['samples_per_pass']} spp), divided by the "
        "channel render's time. That time is the whole call: its three passes, each loading the scene "
        "and rendering it (the second of two calls at each spp: the first compiles Dr.Jit's kernels, "
        "see the first-call column; exact sampling's times are `mi.render` of a loaded scene). "
        "Exact sampling's spp for it: the samples per pixel scalar_spectral_polarized needs for that "
        "error (the same interpolation); the ratio is that saving in samples times the ratio of the "
        "costs per sample. "
        "\"extrapolated\": exact sampling's curve does not reach that error within its samples, and "
        "its time is extrapolated along the curve's last measured segment (log time against log "
        f"error). Goal {goal_text('channel_render_equal_error')} at {CHANNEL_GOAL_SPP} spp in both "
        f"variants for {', '.join(CHANNEL_GOAL_SCENES)}; the other scenes have none.",
        "",
        "| scene | image | reference: spp, own error | sampler | spp | mean CIEDE2000 | time (s) | first call (s) "
        "| exact sampling's spp for it | scalar: time to reach it (s) | ratio | llvm: time to reach it (s) "
        "| ratio | goal |",
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for scene, c in channel.items():
        ref = c["reference"]
        for method, entries in c["at_equal_error"].items():
            first = {row["spp"]: row.get("first_seconds") for row in c["curves"][method]}
            for e in entries:
                lines.append(
                    f"| {scene} | {image(frames.get(scene))} | {ref['spp']}, {ref['noise']['mean_de2000']:.2f} "
                    f"| {e['sampler']} | {e['spp']} | {e['mean_de2000']:.3f} | {e['seconds']:.2f} "
                    f"| {first.get(e['spp']) or float('nan'):.2f} | {e['exact']['spp_at_error']:.0f}"
                    f"{' (extrapolated)' if e['exact']['extrapolated'] else ''} "
                    f"| {at_error(e['exact'])} | {at_error(e['exact_llvm'])} | {channel_goal(scene, e)} |")
    lines += ["", "Every point of the channel render's curves (mean CIEDE2000, and time in s in brackets):", ""]
    spps = sorted({row["spp"] for c in channel.values() for m in c["at_equal_error"]
                   for row in c["curves"][m]})
    lines += ["| scene | sampler | " + " | ".join(f"{n} spp" for n in spps) + " |",
              "| --- | --- | " + " | ".join("---" for _ in spps) + " |"]
    for scene, c in channel.items():
        for method, entries in c["at_equal_error"].items():
            rows = {row["spp"]: row for row in c["curves"][method]}
            cells = [f"{rows[n]['mean_de2000']:.2f} ({rows[n]['seconds']:.2f})" if n in rows else "—"
                     for n in spps]
            lines.append(f"| {scene} | {entries[0]['sampler']} | " + " | ".join(cells) + " |")
    lines += equal_time_section(r.get("equal_time"), base)
    return lines


def at_error(x: dict) -> str:
    """Two cells: exact sampling's time at the channel render's error, and the ratio."""
    flag = " (extrapolated)" if x["extrapolated"] else ""
    return f"{x['seconds_at_error']:.2f}{flag} | {x['ratio']:.3g}{flag}"


def channel_goal(scene: str, e: dict) -> str:
    """The goal's verdict at CHANNEL_GOAL_SPP for CHANNEL_GOAL_SCENES: met when both ratios
    meet it."""
    if scene not in CHANNEL_GOAL_SCENES or e["spp"] != CHANNEL_GOAL_SPP:
        return "—"
    g = "channel_render_equal_error"
    worst = min(e["exact"]["ratio"], e["exact_llvm"]["ratio"])
    return f"{goal_text(g)}: {verdict(g, worst)}"


def equal_time_section(t: dict | None, base: str = "") -> list[str]:
    """The figure of bench/equal_time.py and what each panel took."""
    if not t:
        return []
    spp = next(iter(t["scenes"].values()))["panels"][0]["spp"]
    lines = ["", f"**At equal render time** (`bench/equal_time.py`): the channel render at {spp} spp and exact "
             "sampling given the time of the channel render with the scene's own (independent) sampler, "
             "against an exact reference (mean CIEDE2000 under each panel):", "",
             f"![The channel render and exact spectral sampling at equal render time]({base}{t['figure']})",
             ""]
    for scene, d in t["scenes"].items():
        w, h = d["frame"]["crop"][2:]
        panels = "; ".join(f"{p['label'].replace(chr(10), ' ')} {p['spp']} spp in {p['seconds']:.1f} s: "
                           f"{p['mean_de2000']:.2f}" for p in d["panels"])
        lines.append(f"- {scene} ({w}x{h} px; reference {d['reference']['spp']} spp, own error "
                     f"{d['reference']['noise']['mean_de2000']:.2f}): {panels}.")
    return lines


def shortcut_rows(r: dict) -> list[str]:
    """One row per measured case, grouped by shortcut (the shortcut named on its first row);
    cases of results.json that SHORTCUTS does not describe are listed under their key."""
    cases = dict(r["shortcut_cases"])
    rows = []
    for key, (what, described) in SHORTCUTS.items():
        first = True
        for case, text in described.items():
            v = cases.pop(f"{key}/{case}", None)
            if v is None:
                continue
            rows.append(f"| {what if first else ''} | {text} | {v:.2f} |")
            first = False
    rows += [f"| {k.split('/')[0]} | {k} | {v:.2f} |" for k, v in cases.items()]
    return rows


def image(frame: dict | None) -> str:
    """'32x32', or '32x32 crop of 256x256' for a scene rendered as a crop (bench/scenes.py CROPS)."""
    if not frame:
        return "?"
    w, h = frame["crop"][2:]
    full = frame["size"]
    return f"{w}x{h}" if [w, h] == full else f"{w}x{h} crop of {full[0]}x{full[1]}"


def span(values: list[float]) -> str:
    """'1.62x', or '1.50-2.24x' for the range of several ratios."""
    lo, hi = min(values), max(values)
    return f"{lo:.3g}x" if f"{lo:.3g}" == f"{hi:.3g}" else f"{lo:.3g}-{hi:.3g}x"


def summary(r: dict) -> str:
    """The README's headline ratios: per kind of overhead row and plugin, the range of ours /
    Mitsuba's in each variant; the channel render's ratio at equal error at CHANNEL_GOAL_SPP."""
    o = r["overhead"]
    variants = o["settings"]["variants"]
    groups: dict[tuple[str, str], list[dict]] = {}
    for row in o["rows"].values():
        groups.setdefault((row["kind"], row["plugin"]), []).append(row)
    m = o["measured"]
    lines = [f"Render time of the plugins against Mitsuba's own (`thindielectric`, `dielectric`) in the "
             f"same scene, ours / theirs (median of {o['settings']['repeats']} interleaved renders, "
             f"measured on {m['date']}, load average {fmt_load(m.get('load_average_start'))} to "
             f"{fmt_load(m.get('load_average_end'))} on {r['machine']['logical_cores']} cores"
             + ("; in the llvm variants ours in Dr.Jit's evaluated mode, which they need, against "
                "Mitsuba's in its default symbolic mode" if o["settings"].get("evaluated_mode") else "")
             + "):", ""]
    passes = o["settings"].get("channel_pass", {})
    where = {v: f"one render_analytic pass ({v}, {passes[v]})" if v in passes else v for v in variants}
    for (kind, plugin), rows in groups.items():
        cells = [f"{span([x['ratio'][v] for x in rows if v in x['ratio']])} in {where[v]}"
                 for v in variants if any(v in x["ratio"] for x in rows)]
        lines.append(f"- {kind} `{plugin}` ({len(rows)} scene{'s' if len(rows) > 1 else ''}): "
                     + ", ".join(cells))
    channel = r.get("channel_render") or {}
    by_sampler: dict[str, list[float]] = {}
    for c in channel.values():
        for entries in c["at_equal_error"].values():
            for e in entries:
                if e["spp"] == CHANNEL_GOAL_SPP:
                    by_sampler.setdefault(e["sampler"], []).append(e["exact"]["ratio"])
    if by_sampler:
        cells = [f"{span(v)} with `{s}`" for s, v in by_sampler.items()]
        lines += ["", f"`render_analytic` at {CHANNEL_GOAL_SPP} spp against spectral sampling in "
                  "scalar_spectral_polarized at equal error (mean CIEDE2000), the time spectral sampling "
                  f"needs over the channel render's, over {len(channel)} scenes: " + ", ".join(cells) + "."]
    return "\n".join(lines)


def replaced_between(path: pathlib.Path, begin: str, end: str, body: str) -> str | None:
    """The text of `path` with what lies between the lines `begin` and `end` replaced by `body`;
    None (and a message) if the file lacks them."""
    text = path.read_text(encoding="utf-8")
    if text.count(begin) != 1 or text.count(end) != 1 or text.index(begin) > text.index(end):
        print(f"{path}: needs one '{begin}' line followed by one '{end}' line", file=sys.stderr)
        return None
    head, rest = text.split(begin, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{begin}\n{body}\n{end}{tail}"


def main() -> int:
    src = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "bench/results.json")
    page = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else BENCHMARKS_MD)
    readme = pathlib.Path(sys.argv[3] if len(sys.argv) > 3 else README_MD)
    results = json.loads(src.read_text(encoding="utf-8"))
    # Links from the page to the repository's files (the figure) start from the page's folder.
    root = pathlib.Path(__file__).resolve().parents[1]
    base = os.path.relpath(root, page.resolve().parent).replace(os.sep, "/") + "/"
    texts = {page: replaced_between(page, BEGIN, END, section(results, "" if base == "./" else base)),
             readme: replaced_between(readme, SUMMARY_BEGIN, SUMMARY_END, summary(results))}
    if None in texts.values():
        return 1
    for path, text in texts.items():
        path.write_text(text, encoding="utf-8")
    print(f"{page} and the summary in {readme} regenerated from {src}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
