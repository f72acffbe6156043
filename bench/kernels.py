#!/usr/bin/env python3
"""The plugins inside Mitsuba's kernels (``make bench-kernels``, part of ``make bench``): render
time, first render with its kernel compilation, Dr.Jit's kernel cache and peak memory, ours
against Mitsuba's own plugins, both in Mitsuba's default (symbolic) mode.

    .venv/bin/python bench/kernels.py [--out bench/out] [--repeats N] [--backend llvm|cuda]

``--backend cuda`` (``make bench-cuda``) runs the rows of the kernel path in the cuda_ad
variants instead (a machine with an NVIDIA GPU; without one it stops with Dr.Jit's reason); the
llvm_ad_rgb row has no CUDA counterpart (a plate over colour channels needs the host: refused
in CUDA variants at load).

Scenes (llvm_ad_spectral_polarized unless said otherwise):

- ``six_plates``: six quartz plates (0, 5, 20, 50, 100, 150 um, ``material="quartz"``) side by
  side between crossed linear polarisers on a backlight, 96 x 64 pixels, 16 spp, ``path``;
  against ``thindielectric`` of quartz's ordinary index (1.544);
- ``bouncing_calcite``: bench/scenes.py's calcite sphere on the floor of a closed room, light
  bouncing inside it (``path``, max_depth 8), optic axis [1, 1, 1] in world space, against
  ``dielectric`` 1.658;
- ``bouncing_glass``: the same sphere with isotropic indices (eta_o = eta_e = 1.5) against
  ``dielectric`` 1.5;
- ``six_plates`` in llvm_ad_rgb: there the plate is integrated over the sRGB channels by the
  core on the host (docs/architecture.md, "Which path runs"), in Dr.Jit's evaluated mode, which
  keeps Mitsuba's own plugins out of symbolic mode in the same process: ours is timed in its own
  process against Mitsuba's in another, each its median (not interleaved).

Measurements, each configuration in processes of its own:

1. **First render** (one process per configuration): load and first render with Dr.Jit's
   kernel cache empty (a fresh ``HOME``, where Dr.Jit keeps it); the number of kernels compiled
   and their compile time.
2. **Time** (processes of their own, kernel cache warm): ``PAIRS`` pairs of processes, ours then
   Mitsuba's, each loading its scene, rendering it once and then ``repeats`` times with fresh
   seeds; per process the median render time, per configuration the median over its processes,
   and their ratio ours / Mitsuba's. Separate processes, because in one process Mitsuba's
   symbolic calls trace every registered BSDF instance: a scene of Mitsuba's rendered while one
   of ours exists compiles and carries our program in its kernels too (measured as
   ``theirs_beside_ours``: Mitsuba's scene interleaved with ours in one process, its median
   over its median alone).
3. **Peak memory** (the first-render processes): the peak resident set of the process
   (``VmHWM``, compilation included) over its resident set after loading the scene, before the
   first render.

Writes ``bench/out/kernels.json`` and ``bench/out/kernels.png`` and prints the tables with the
machine's load. Timings on a shared machine move with its load: compare ratios of one run.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
RESULT = "\nbench-kernels result: "
REPEATS = 5
#: Pairs of timing processes (ours, Mitsuba's) per row.
PAIRS = 3
POLARIZED = "llvm_ad_spectral_polarized"
#: (scene, variant, goal of the ratio ours / Mitsuba's) of the issue that made the kernel path.
ROWS = [("six_plates", POLARIZED, 2.0), ("bouncing_calcite", POLARIZED, 2.0),
        ("bouncing_glass", POLARIZED, 1.3), ("six_plates", "llvm_ad_rgb", 2.0)]
QUARTZ_UM = (0, 5, 20, 50, 100, 150)


def bench_scenes():
    """bench/scenes.py, for its room, sphere and the plugins' dicts."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("bench_scenes", ROOT / "bench" / "scenes.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def six_plates(mi, ours: bool) -> dict:
    """Six plates in a row (each 0.3 x 0.4) between crossed polarisers over a backlight, seen by
    an orthographic camera along their normal, 96 x 64 pixels."""
    T = mi.ScalarTransform4f
    d = {"type": "scene", "integrator": {"type": "path", "max_depth": 8},
         "sensor": {"type": "orthographic",
                    "to_world": T().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]) @ T().scale([1.05, 1.05, 1]),
                    "film": {"type": "hdrfilm", "width": 96, "height": 64, "rfilter": {"type": "box"}},
                    "sampler": {"type": "independent", "sample_count": 16}},
         "light": {"type": "rectangle", "to_world": T().translate([0, 0, -1]).scale([2, 2, 1]),
                   "emitter": {"type": "area", "radiance": {"type": "d65"}}},
         "polarizer": {"type": "rectangle", "to_world": T().translate([0, 0, -0.5]).scale([2, 2, 1]),
                       "bsdf": {"type": "polarizer", "theta": 45.0}},
         "analyser": {"type": "rectangle", "to_world": T().translate([0, 0, 0.5]).scale([2, 2, 1]),
                      "bsdf": {"type": "polarizer", "theta": -45.0}}}
    for i, um in enumerate(QUARTZ_UM):
        x = -0.875 + 0.35 * i
        bsdf = ({"type": "thinbirefringent", "material": "quartz", "thickness": float(um),
                 "optic_axis": [1.0, 0.0, 0.0]} if ours
                else {"type": "thindielectric", "int_ior": 1.544, "ext_ior": 1.0})
        d[f"plate{i}"] = {"type": "rectangle", "bsdf": bsdf,
                          "to_world": T().translate([x, 0, 0]).scale([0.15, 0.2, 1])}
    return d


def scene_dict(mi, scene: str, ours: bool) -> dict:
    if scene == "six_plates":
        return six_plates(mi, ours)
    s = bench_scenes()
    name = {"bouncing_calcite": "bouncing_calcite", "bouncing_glass": "bouncing_glass"}[scene]
    config = f"{name}/birefringent" if ours else f"{name}/dielectric"
    return s.room(mi, s.CONFIGS[config](mi))


def setup(variant: str):
    import mitsuba as mi

    mi.set_variant(variant)
    import mitsuba_birefringent  # noqa: F401

    return mi


def host_path(variant: str) -> bool:
    """Whether our plates render on the host in `variant` (evaluated mode)."""
    return "_spectral" not in variant


def render(mi, scene, seed: int, evaluated: bool) -> float:
    import mitsuba_birefringent

    start = time.perf_counter()
    if evaluated:
        with mitsuba_birefringent.evaluated_mode():
            image = mi.render(scene, seed=seed)
    else:
        image = mi.render(scene, seed=seed)
    image.numpy()
    return time.perf_counter() - start


def status_kib(field: str) -> int:
    for line in pathlib.Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise KeyError(field)


def child_time(scene: str, variant: str, repeats: int) -> dict:
    """Ours and Mitsuba's interleaved in one process (both in default mode)."""
    mi = setup(variant)
    scenes = {who: mi.load_dict(scene_dict(mi, scene, who == "ours")) for who in ("ours", "theirs")}
    for s in scenes.values():
        render(mi, s, 0, False)
    times = {who: [] for who in scenes}
    for r in range(repeats):
        for who, s in scenes.items():
            times[who].append(render(mi, s, r + 1, False))
    return times


def child_alone(scene: str, variant: str, who: str, repeats: int) -> dict:
    """One configuration alone: load, first render (with its kernels), `repeats` more renders'
    times, and the peak memory of two of them."""
    import drjit as dr

    mi = setup(variant)
    evaluated = who == "ours" and host_path(variant)
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    start = time.perf_counter()
    s = mi.load_dict(scene_dict(mi, scene, who == "ours"))
    loaded = status_kib("VmRSS")
    first = render(mi, s, 0, evaluated)
    first_with_load = time.perf_counter() - start
    history = [k for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT]
    compiled = [k for k in history if not k.get("cache_hit")]
    compile_ms = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in compiled)
    dr.set_flag(dr.JitFlag.KernelHistory, False)
    times = [render(mi, s, r + 1, evaluated) for r in range(repeats)]
    peak = status_kib("VmHWM")
    return {"first_render_s": first, "first_with_load_s": first_with_load,
            "kernels": len(history), "compiled": len(compiled), "compile_ms": compile_ms,
            "median_s": statistics.median(times), "render_peak_mib": max(0, peak - loaded) / 1024,
            "evaluated_mode": evaluated}


def run_child(args: list[str], env: dict | None = None):
    out = subprocess.run([sys.executable, __file__, "--child", *args], capture_output=True,
                         text=True, env=env, cwd=ROOT)
    if out.returncode != 0 or RESULT not in out.stdout:
        raise RuntimeError(f"child {args} failed:\n{out.stdout[-3000:]}\n{out.stderr[-3000:]}")
    return json.loads(out.stdout.split(RESULT)[-1])


def measure_row(scene: str, variant: str, repeats: int) -> dict:
    """Per configuration a process with Dr.Jit's kernel cache empty (a fresh HOME), then PAIRS
    alternating pairs of processes with it warm (the same HOME), and (kernel path only) one
    process rendering both interleaved."""
    with tempfile.TemporaryDirectory() as home:
        env = {**os.environ, "HOME": home}
        run = lambda who: run_child(["alone", scene, variant, who, str(repeats)], env)  # noqa: E731
        row = {who: {"cold": run(who), "warm": []} for who in ("ours", "theirs")}
        for _ in range(PAIRS):
            for who in ("ours", "theirs"):
                row[who]["warm"].append(run(who))
        if not host_path(variant):
            row["interleaved"] = run_child(["time", scene, variant, str(repeats)], env)
    for who in ("ours", "theirs"):
        row[who]["median_s"] = statistics.median(w["median_s"] for w in row[who]["warm"])
        row[who]["first_warm_s"] = statistics.median(w["first_with_load_s"] for w in row[who]["warm"])
    return row


def plot(rows: list[dict], path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = [f"{r['scene']}\n{r['variant'].split('_ad_')[1]}" for r in rows]
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    x = range(len(rows))
    axes[0].bar(x, [r["time_ratio"] for r in rows], color="tab:blue")
    axes[0].scatter(x, [r["goal"] for r in rows], color="k", marker="_", s=400, label="goal")
    axes[0].set_title("render time, ours / Mitsuba's (default mode)")
    axes[0].legend()
    w = 0.4
    for i, who in enumerate(("ours", "theirs")):
        axes[1].bar([k + (i - 0.5) * w for k in x], [r[who]["cold"]["first_with_load_s"] for r in rows],
                    w, label=who)
        axes[2].bar([k + (i - 0.5) * w for k in x], [r[who]["cold"]["render_peak_mib"] for r in rows],
                    w, label=who)
    axes[1].set_title("first render with load, kernel cache empty (s)")
    axes[2].set_title("peak memory over the loaded scene (MiB)")
    for ax in axes:
        ax.set_xticks(list(x), labels, fontsize=8)
    axes[1].legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> int:
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        kind, scene, variant = sys.argv[2:5]
        result = (child_time(scene, variant, int(sys.argv[5])) if kind == "time"
                  else child_alone(scene, variant, sys.argv[5], int(sys.argv[6])))
        print(RESULT + json.dumps(result))
        return 0
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out")
    p.add_argument("--repeats", type=int, default=REPEATS)
    p.add_argument("--backend", choices=("llvm", "cuda"), default="llvm")
    a = p.parse_args()
    rows_wanted = ROWS
    if a.backend == "cuda":
        import drjit as dr

        if not dr.has_backend(dr.JitBackend.CUDA):
            print("bench-kernels: no CUDA device here (Dr.Jit found no CUDA backend); run "
                  "make bench-cuda on a machine with an NVIDIA GPU", file=sys.stderr)
            return 2
        rows_wanted = [(s, v.replace("llvm_", "cuda_"), g) for s, v, g in ROWS if not host_path(v)]
    load_before = os.getloadavg()
    start = time.perf_counter()
    rows = []
    for scene, variant, goal in rows_wanted:
        row = {"scene": scene, "variant": variant, "goal": goal, **measure_row(scene, variant, a.repeats)}
        row["time_ratio"] = row["ours"]["median_s"] / row["theirs"]["median_s"]
        if "interleaved" in row:
            row["theirs_beside_ours"] = (statistics.median(row["interleaved"]["theirs"])
                                         / row["theirs"]["median_s"])
        row["memory_ratio"] = (row["ours"]["cold"]["render_peak_mib"]
                               / max(row["theirs"]["cold"]["render_peak_mib"], 1e-9))
        rows.append(row)
        print(f"{scene:18s} {variant:28s} time ratio {row['time_ratio']:.2f} (goal {goal})", flush=True)
    load_after = os.getloadavg()
    result = {"measured": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
              "cpus": os.cpu_count(), "load_before": load_before, "load_after": load_after,
              "repeats": a.repeats, "rows": rows, "seconds": time.perf_counter() - start}
    a.out.mkdir(parents=True, exist_ok=True)
    stem = "kernels" if a.backend == "llvm" else "kernels_cuda"
    (a.out / f"{stem}.json").write_text(json.dumps(result, indent=1))
    plot(rows, a.out / f"{stem}.png")
    print(f"\nload {load_before[0]:.1f} -> {load_after[0]:.1f} on {os.cpu_count()} cpus; "
          f"{result['seconds']:.0f} s")
    print(f"{'scene':18s} {'variant':28s} {'ratio':>6s} {'goal':>5s} {'ours s':>7s} {'theirs s':>8s} "
          f"{'1st cold':>9s} {'1st warm':>9s} {'theirs':>7s} {'compile':>8s} {'MiB':>6s} {'theirs':>6s} "
          f"{'beside':>7s}")
    for r in rows:
        o, t = r["ours"], r["theirs"]
        print(f"{r['scene']:18s} {r['variant']:28s} {r['time_ratio']:6.2f} {r['goal']:5.1f} "
              f"{o['median_s']:7.3f} {t['median_s']:8.3f} "
              f"{o['cold']['first_with_load_s']:9.2f} {o['first_warm_s']:9.2f} "
              f"{t['cold']['first_with_load_s']:7.2f} {o['cold']['compile_ms'] / 1e3:8.2f} "
              f"{o['cold']['render_peak_mib']:6.0f} {t['cold']['render_peak_mib']:6.0f} "
              f"{r.get('theirs_beside_ours', float('nan')):7.2f}")
    print("(ratio: median render time ours / Mitsuba's, each in processes of its own; 1st: load + "
          "first render, Dr.Jit's kernel cache cold / warm, theirs cold; compile: our kernels' "
          "compile time, cold (s); MiB: the process's peak resident set over its resident set "
          "after loading the scene; beside: Mitsuba's render time in a process that also holds "
          "ours, over alone)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
