#!/usr/bin/env python3
"""What each Mitsuba variant costs with the plugins: render time and peak memory against
scalar_spectral_polarized, for the default scene (a `thinbirefringent` plate, photoelastic_disk)
and a bulk crystal (`birefringent`, calcite_rhomb), and the channel render (`render_analytic`).

    .venv/bin/python bench/variants.py [--size 128] [--spp 16] [--pairs 3]
        [--out bench/out/variants.json]

Time: for each variant, one process loads the scene in that variant and in
scalar_spectral_polarized, renders each once (Dr.Jit compiles its kernels, the plugins make
their first call), then renders them in turn, `--pairs` times (reference, variant, reference,
variant, ...): the ratio is the median over the pairs of the variant's render time over the
reference's just before it, so that the machine's load, which other jobs change, is the same
for both terms of each ratio. A render is `mi.render` of the loaded scene (in evaluated mode in
the llvm variants); `render_analytic` is its whole call (three llvm_ad_mono_polarized passes,
each loading and rendering the scene).

Memory: for each variant, a fresh process loads the scene in that variant alone and renders it
twice; its peak resident set (the interpreter, Mitsuba, the scene and Dr.Jit's buffers) is the
variant's memory, and the ratio is to scalar_spectral_polarized's process.

The scenes keep their own sampler (independent). A named crystal's bulk surface needs a
polarized variant: the other variants are not measured for it. Prints a Markdown table and writes
the JSON (with the machine's load at the start and the end).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import pathlib
import platform
import resource
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: The variants of the table, and the channel render (a pseudo-variant: three passes of
#: llvm_ad_mono_polarized), in the order of the table.
VARIANTS = ("scalar_rgb", "scalar_spectral", "scalar_spectral_polarized", "llvm_ad_rgb",
            "llvm_ad_mono", "llvm_ad_mono_polarized", "llvm_ad_spectral",
            "llvm_ad_spectral_polarized", "render_analytic")
#: The reference of the ratios.
REFERENCE = "scalar_spectral_polarized"
#: The scene of each plugin (a module of scenes/).
SCENES = {"thinbirefringent": "photoelastic_disk", "birefringent": "calcite_rhomb"}
#: Variants a named crystal's bulk surface loads in.
POLARIZED = ("scalar_spectral_polarized", "llvm_ad_mono_polarized", "llvm_ad_spectral_polarized",
             "render_analytic")
#: Precedes a child's measurement on its standard output (Mitsuba's log shares it).
MARKER = "variants.py result: "


class Renderer:
    """One scene in one variant (or the channel render of its scalar_spectral_polarized dict)."""

    def __init__(self, variant: str, scene_name: str, size: int, spp: int):
        import mitsuba as mi

        sys.path.insert(0, str(ROOT / "scenes"))
        self.variant, self.spp = variant, spp
        mi.set_variant(REFERENCE if variant == "render_analytic" else variant)
        import mitsuba_birefringent

        self.dict = importlib.import_module(scene_name).scene(width=size, height=size, spp=spp)
        self.scene = None if variant == "render_analytic" else mi.load_dict(self.dict)
        self.mb = mitsuba_birefringent

    def __call__(self) -> float:
        """Seconds of one render."""
        import drjit as dr
        import mitsuba as mi

        start = time.perf_counter()
        if self.scene is None:
            self.mb.render_analytic(self.dict, spp=self.spp)
        else:
            mi.set_variant(self.variant)
            with self.mb.evaluated_mode():
                image = mi.render(self.scene, seed=0)
                dr.eval(image)
                dr.sync_thread()
        return time.perf_counter() - start


def measure_time(variant: str, scene_name: str, size: int, spp: int, pairs: int) -> dict:
    ref, ours = Renderer(REFERENCE, scene_name, size, spp), Renderer(variant, scene_name, size, spp)
    ref(), ours()  # warm-up: kernels compiled, first calls made
    times = [(ref(), ours()) for _ in range(pairs)]
    return {"seconds": statistics.median(t for _, t in times),
            "reference_seconds": statistics.median(r for r, _ in times),
            "ratio": statistics.median(t / r for r, t in times), "pairs": times}


def measure_memory(variant: str, scene_name: str, size: int, spp: int) -> dict:
    render = Renderer(variant, scene_name, size, spp)
    render(), render()
    return {"peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def child(what: str, variant: str, scene_name: str, a: argparse.Namespace) -> dict | None:
    cmd = [sys.executable, __file__, "--child", what, variant, scene_name, "--size", str(a.size),
           "--spp", str(a.spp), "--pairs", str(a.pairs)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=3600)
    if r.returncode != 0 or MARKER not in r.stdout:
        print(f"  {what} {variant} {scene_name}: failed\n{r.stderr[-2000:]}", file=sys.stderr)
        return None
    return json.loads(r.stdout.rsplit(MARKER, 1)[1].splitlines()[0])


def table(results: dict) -> str:
    lines = ["| variant | " + " | ".join(f"`{p}` ({s}): time, ratio | peak memory, ratio"
                                          for p, s in SCENES.items()) + " |",
             "| --- |" + " --- | --- |" * len(SCENES)]
    for v in VARIANTS:
        cells = []
        for plugin in SCENES:
            t, m = results[plugin].get(v, {}).get("time"), results[plugin].get(v, {}).get("memory")
            ref = results[plugin].get(REFERENCE, {}).get("memory")
            cells.append(f"{t['seconds']:.2f} s, {t['ratio']:.2f}x" if t else "—")
            cells.append(f"{m['peak_rss_mib']:.0f} MiB, {m['peak_rss_mib'] / ref['peak_rss_mib']:.2f}x"
                         if m and ref else "—")
        lines.append(f"| {v} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--pairs", type=int, default=3)
    p.add_argument("--only", nargs="*", default=None, help="only these variants")
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out" / "variants.json")
    p.add_argument("--child", nargs=3, metavar=("WHAT", "VARIANT", "SCENE"), help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.child:
        what, variant, scene_name = a.child
        m = (measure_time(variant, scene_name, a.size, a.spp, a.pairs) if what == "time"
             else measure_memory(variant, scene_name, a.size, a.spp))
        print(MARKER + json.dumps(m))
        return 0
    variants = [v for v in VARIANTS if not a.only or v in a.only or v == REFERENCE]
    load_start, start = os.getloadavg(), time.time()
    results: dict[str, dict[str, dict]] = {p: {} for p in SCENES}
    for v in variants:
        for plugin, scene_name in SCENES.items():
            if plugin == "birefringent" and v not in POLARIZED:
                continue
            entry = results[plugin].setdefault(v, {})
            entry["memory"] = child("memory", v, scene_name, a)
            if v != REFERENCE:
                entry["time"] = child("time", v, scene_name, a)
            print(f"{v} {scene_name}: {entry}", flush=True)
    for plugin in SCENES:  # the reference against itself
        if REFERENCE in results[plugin]:
            others = [e["time"] for e in results[plugin].values() if e.get("time")]
            results[plugin][REFERENCE]["time"] = {
                "seconds": statistics.median(t["reference_seconds"] for t in others) if others else 0.0,
                "ratio": 1.0}
    out = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(start)),
           "machine": {"cpu": platform.processor() or platform.machine(),
                       "logical_cores": os.cpu_count(), "load_average_start": load_start,
                       "load_average_end": os.getloadavg()},
           "settings": {"size": a.size, "spp": a.spp, "pairs": a.pairs, "scenes": SCENES},
           "minutes": (time.time() - start) / 60, "results": results}
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(out, indent=1))
    print(table(results))
    print(f"{a.size}x{a.size} px, {a.spp} spp; time: median of {a.pairs} alternating pairs per "
          f"variant; load average {load_start[0]:.2f} at the start, "
          f"{out['machine']['load_average_end'][0]:.2f} at the end; {out['minutes']:.1f} min; {a.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
