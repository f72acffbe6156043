#!/usr/bin/env python3
"""The plugins in Mitsuba's llvm variants: render time and peak memory (``make bench-jit``, the
last step of ``make bench``).

    .venv/bin/python bench/jit.py [--out bench/out] [--repeats N]

The scenes of the scalar overhead table (bench/scenes.py: a closed diffuse room with a ceiling
light, 48x48 pixels, 32 spp, ``path`` with max_depth 8) with three glass panes
(``thinbirefringent`` eta_o = eta_e = 1.5, 1000 um, against ``thindielectric`` int_ior 1.5) or a
glass sphere and cube (``birefringent`` eta_o = eta_e = 1.5 against ``dielectric``), with
isotropic parameters and with birefringent ones (eta_e = 1.5 + 1e-9: optically the same glass,
the core's general path; the bulk one only in the polarized variants, which a birefringent
crystal needs). Every llvm variant renders in Dr.Jit's evaluated mode (which the plugins need;
Mitsuba's own plugins are timed in it too, so the ratios compare like with like), and ours are
also timed in the scalar variant of the same spectrum type.

1. **Time.** One process per variant loads every configuration, renders each once (kernel
   compilation) and then ``repeats`` interleaved rounds with fresh seeds, with Dr.Jit's default
   thread pool (every core). Figures: the median time of each, the ratios ours / Mitsuba's
   (goal for isotropic parameters: <= 1.3) and ours in llvm / ours in the scalar variant.
2. **Peak memory.** One process per (variant, configuration) loads it and renders it twice; its
   peak resident set (``ru_maxrss``) is the figure, beside that of a process that imports
   Mitsuba, sets the variant and loads the empty room (the baseline).

Writes ``bench/out/jit.json`` (every measurement) and ``bench/out/jit.png`` (the ratios and the
peak memory), and prints the tables.
"""

from __future__ import annotations

import argparse
import datetime
import importlib.util
import json
import pathlib
import resource
import statistics
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
LLVM = ("llvm_ad_rgb", "llvm_ad_mono", "llvm_ad_mono_polarized", "llvm_ad_spectral",
        "llvm_ad_spectral_polarized")
REPEATS = 5
RESULT = "\nbench-jit result: "


def overhead_scenes():
    """bench/scenes.py, the scalar benchmark, for its room and objects."""
    spec = importlib.util.spec_from_file_location("bench_scenes", ROOT / "bench" / "scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def scalar_counterpart(variant: str) -> str | None:
    name = "scalar_" + variant.removeprefix("llvm_ad_")
    return name if name in ("scalar_rgb", "scalar_spectral", "scalar_spectral_polarized") else None


def configurations(variant: str) -> dict:
    """Name -> (objects maker) of every configuration timed in `variant`."""
    s = overhead_scenes()
    thin = lambda e: {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": e, "ext_ior": 1.0,  # noqa: E731
                      "thickness": 1000.0}
    bulk = lambda e: {"type": "birefringent", "eta_o": 1.5, "eta_e": e, "ext_ior": 1.0}  # noqa: E731
    configs = {
        "thinbirefringent": lambda mi: s.panes(mi, thin(1.5)),
        "birefringent": lambda mi: s.solids(mi, bulk(1.5)),
    }
    configs["thinbirefringent_birefringent"] = lambda mi: s.panes(mi, thin(1.5 + 1e-9))
    if "polarized" in variant:
        configs["birefringent_birefringent"] = lambda mi: s.solids(mi, bulk(1.5 + 1e-9))
    if variant.startswith("llvm_"):
        configs["thindielectric"] = lambda mi: s.panes(mi, {"type": "thindielectric", "int_ior": 1.5,
                                                            "ext_ior": 1.0})
        configs["dielectric"] = lambda mi: s.solids(mi, {"type": "dielectric", "int_ior": 1.5,
                                                         "ext_ior": 1.0})
    return configs


def load(variant: str, config: str | None):
    """Mitsuba in `variant` and the room with `config` (None: the empty room), loaded."""
    import mitsuba as mi

    mi.set_variant(variant)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)

    s = overhead_scenes()
    objects = configurations(variant)[config](mi) if config else {}
    return mi, mi.load_dict(s.room(mi, objects)), s.OVERHEAD_SPP


def render(mi, scene, spp: int, seed: int) -> float:
    import drjit as dr
    import mitsuba_birefringent

    start = time.perf_counter()
    with mitsuba_birefringent.evaluated_mode():
        image = mi.render(scene, spp=spp, seed=seed)
        if mi.variant().startswith("llvm_"):
            dr.eval(image)
            dr.sync_thread()
    return time.perf_counter() - start


def time_worker(variant: str, repeats: int) -> dict:
    """Interleaved rounds of every configuration of `variant` (see the module docstring)."""
    scenes = {}
    for name in configurations(variant):
        mi, scenes[name], spp = load(variant, name)
        render(mi, scenes[name], spp, seed=0)  # kernel compilation, first-use allocations
    times = {name: [] for name in scenes}
    for rep in range(repeats):
        for name, scene in scenes.items():
            times[name].append(render(mi, scene, spp, seed=10 * rep + 1))
    return {"seconds": times, "median_seconds": {k: statistics.median(v) for k, v in times.items()}}


def memory_worker(variant: str, config: str | None) -> dict:
    """Peak resident set (KiB) of this process after loading `config` and rendering it twice
    (the empty room is not rendered: the baseline of Mitsuba in `variant`)."""
    mi, scene, spp = load(variant, config)
    if config:
        for seed in range(2):
            render(mi, scene, spp, seed)
    return {"peak_rss_kib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}


def run_worker(*args: str) -> dict:
    out = subprocess.run([sys.executable, __file__, "--worker", *args], capture_output=True,
                         text=True, timeout=3600)
    if out.returncode != 0:
        raise RuntimeError(f"worker {args} failed:\n{out.stderr[-3000:]}")
    # Mitsuba's log shares stdout (and leaves colour codes before the next line): the result is
    # the text after the last marker.
    return json.loads(out.stdout.rsplit(RESULT, 1)[1])


def measure(repeats: int) -> dict:
    variants = list(LLVM) + sorted({scalar_counterpart(v) for v in LLVM} - {None})
    results = {}
    for v in variants:
        t = run_worker("time", v, str(repeats))
        memory = {name: run_worker("memory", v, name)["peak_rss_kib"] for name in configurations(v)}
        memory["empty room (baseline)"] = run_worker("memory", v, "")["peak_rss_kib"]
        results[v] = {**t, "peak_rss_kib": memory}
        med = t["median_seconds"]
        print(f"{v}: " + ", ".join(f"{k} {s:.2f} s" for k, s in med.items()), flush=True)
    return results


def ratios(results: dict) -> dict:
    """ours / Mitsuba's in each llvm variant, ours in llvm / ours in the scalar variant."""
    out = {}
    for v in LLVM:
        med = results[v]["median_seconds"]
        r = {"thinbirefringent / thindielectric": med["thinbirefringent"] / med["thindielectric"],
             "birefringent / dielectric": med["birefringent"] / med["dielectric"]}
        if "thinbirefringent_birefringent" in med:
            r["thinbirefringent (birefringent) / thindielectric"] = \
                med["thinbirefringent_birefringent"] / med["thindielectric"]
        if "birefringent_birefringent" in med:
            r["birefringent (birefringent) / dielectric"] = med["birefringent_birefringent"] / med["dielectric"]
        scalar = scalar_counterpart(v)
        if scalar:
            sm = results[scalar]["median_seconds"]
            for name in ("thinbirefringent", "birefringent", "thinbirefringent_birefringent",
                         "birefringent_birefringent"):
                if name in med and name in sm:
                    r[f"{name}: llvm / {scalar}"] = med[name] / sm[name]
        out[v] = r
    return out


def plot(results: dict, rat: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(14, 5.5))
    keys = ["thinbirefringent / thindielectric", "thinbirefringent (birefringent) / thindielectric",
            "birefringent / dielectric", "birefringent (birefringent) / dielectric"]
    x = np.arange(len(LLVM))
    width = 0.8 / len(keys)
    for k, key in enumerate(keys):
        ax1.bar(x + (k - 1.5) * width, [rat[v].get(key, np.nan) for v in LLVM], width, label=key)
    ax1.axhline(1.3, color="k", ls=":", lw=1, label="goal for isotropic parameters (1.3)")
    ax1.set_xticks(x, [v.removeprefix("llvm_ad_") for v in LLVM], rotation=20)
    ax1.set_yscale("log")
    ax1.set_ylim(bottom=0.5)
    ax1.set_ylabel("render time, ours / Mitsuba's (evaluated mode, log scale)")
    ax1.set_title("llvm variants, room 48x48, 32 spp")
    ax1.legend(fontsize=7)
    names = ["thindielectric", "thinbirefringent", "dielectric", "birefringent",
             "empty room (baseline)"]
    width = 0.8 / len(names)
    for k, name in enumerate(names):
        ax2.bar(x + (k - 2) * width, [results[v]["peak_rss_kib"].get(name, np.nan) / 1024 for v in LLVM],
                width, label=name)
    ax2.set_xticks(x, [v.removeprefix("llvm_ad_") for v in LLVM], rotation=20)
    ax2.set_ylabel("peak resident set (MiB)")
    ax2.set_title("peak memory of a process rendering the scene twice")
    ax2.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out")
    p.add_argument("--repeats", type=int, default=REPEATS)
    p.add_argument("--worker", nargs="+", help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.worker:
        kind, variant, *rest = a.worker
        r = time_worker(variant, int(rest[0])) if kind == "time" else memory_worker(variant, rest[0] or None)
        print(RESULT + json.dumps(r))
        return 0
    start = time.time()
    results = measure(a.repeats)
    rat = ratios(results)
    a.out.mkdir(parents=True, exist_ok=True)
    doc = {"date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
           "machine": overhead_scenes().machine(), "repeats": a.repeats,
           "minutes": (time.time() - start) / 60, "results": results, "ratios": rat}
    (a.out / "jit.json").write_text(json.dumps(doc, indent=1))
    plot(results, rat, a.out / "jit.png")
    print("\nratios (medians of interleaved renders):")
    for v, r in rat.items():
        print(f"  {v}:")
        for k, x in r.items():
            print(f"    {k:58s} {x:6.2f}")
    print("\npeak resident set (MiB):")
    for v, r in results.items():
        print(f"  {v}: " + ", ".join(f"{k} {m / 1024:.0f}" for k, m in r["peak_rss_kib"].items()))
    print(f"\nwrote {a.out / 'jit.json'} and {a.out / 'jit.png'} ({doc['minutes']:.1f} min)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
