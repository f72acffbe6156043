#!/usr/bin/env python3
"""Gradient renders with the plugins (``make bench-gradients``, part of ``make bench``): time and
peak memory of a primal render, a forward-mode and a reverse-mode gradient render of the
photoelastic disk (scenes/photoelastic_disk.py) in llvm_ad_spectral_polarized, in Mitsuba's
default (symbolic) mode: the plate's derivatives are Dr.Jit's AD through its replayed program.

    .venv/bin/python bench/gradients.py [--out bench/out] [--repeats N] [--size 128] [--spp 8]

Gradients are taken with respect to one parameter at a time: the plate's `birefringence`
texture (its bitmap data: what the inverse example fits), its `thickness` (a float: a uniform
texture), and, for comparison, a parameter of Mitsuba's own `retarder` behind the disk
(`qwp_out.bsdf.delta`: Mitsuba's AD alone, the plate's queries asking for no derivative).
A gradient render is `mi.render` with the parameter's gradient enabled, then `dr.backward` of
the image's mean (reverse) or `dr.forward` from the parameter (forward), evaluated. With the
gradient enabled the parameter is an input of the plate's program instead of a constant
(docs/gradients.md section 2): its own kernels, compiled in the first round.

1. **Time.** One process renders every configuration once (kernel compilation), then
   ``repeats`` interleaved rounds; the figures are medians of the process's CPU time
   (`time.process_time`: every thread of the process, less sensitive to other processes on a
   shared machine than the wall time, which is recorded too) and the ratios to the primal
   render's.
2. **Peak memory.** One process per configuration loads the scene, resets the kernel's
   high-water mark of its resident set (`/proc/self/clear_refs`) and renders three times (the
   first compiles the kernels): the figure is that peak (`VmHWM`) over the resident set after
   loading, i.e. what the renders and their compilation hold at their peak (Dr.Jit keeps the
   memory of one render for the next: measured after a first render, the peak of later ones
   over it was 0).

Writes ``bench/out/gradients.json`` and prints the table with the machine's load.
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
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]
VARIANT = "llvm_ad_spectral_polarized"
REPEATS = 5
#: (name, parameter, mode); mode None: the primal render.
RUNS = [
    ("primal", None, None),
    ("reverse: plate birefringence (bitmap)", "disk.bsdf.birefringence.data", "reverse"),
    ("forward: plate birefringence (bitmap)", "disk.bsdf.birefringence.data", "forward"),
    ("reverse: plate thickness", "disk.bsdf.thickness.value", "reverse"),
    ("forward: plate thickness", "disk.bsdf.thickness.value", "forward"),
    ("reverse: Mitsuba's retarder delta", "qwp_out.bsdf.delta.value", "reverse"),
    ("forward: Mitsuba's retarder delta", "qwp_out.bsdf.delta.value", "forward"),
]
RESULT = "\nbench-gradients result: "


def load(size: int, spp: int):
    import mitsuba as mi

    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401

    sys.path.insert(0, str(ROOT / "scenes"))
    import photoelastic_disk

    scene = mi.load_dict(photoelastic_disk.scene(width=size, height=size, spp=spp))
    return scene, mi.traverse(scene)


def run_one(scene, params, key, mode, spp: int) -> None:
    """One render (and gradient), evaluated (the result read back)."""
    import drjit as dr
    import mitsuba as mi

    if mode is None:
        dr.eval(mi.render(scene, params, spp=spp, seed=1))
        return
    dr.enable_grad(params[key])
    params.update()
    image = mi.render(scene, params, spp=spp, seed=1)
    if mode == "reverse":
        dr.backward(dr.mean(image, axis=None))
        dr.eval(dr.grad(params[key]))
    else:
        dr.forward(params[key])
        dr.eval(dr.grad(image))
    dr.disable_grad(params[key])
    params.update()


def time_all(size: int, spp: int, repeats: int) -> dict:
    scene, params = load(size, spp)
    times = {name: {"cpu": [], "wall": []} for name, _, _ in RUNS}
    for _, key, mode in RUNS:
        run_one(scene, params, key, mode, spp)
    for _ in range(repeats):
        for name, key, mode in RUNS:
            c, w = time.process_time(), time.perf_counter()
            run_one(scene, params, key, mode, spp)
            times[name]["cpu"].append(time.process_time() - c)
            times[name]["wall"].append(time.perf_counter() - w)
    return times


def status_kib(field: str) -> int:
    """A field of /proc/self/status in KiB (VmRSS, VmHWM)."""
    for line in pathlib.Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1])
    raise KeyError(field)


def peak_memory(index: int, size: int, spp: int) -> None:
    """The child process: configuration `index` (see the module docstring); prints the peak of
    its resident set during two renders over the resident set before them (KiB)."""
    import gc

    scene, params = load(size, spp)
    _, key, mode = RUNS[index]
    gc.collect()
    before = status_kib("VmRSS")
    pathlib.Path("/proc/self/clear_refs").write_text("5")  # resets VmHWM
    for _ in range(3):
        run_one(scene, params, key, mode, spp)
    peak = status_kib("VmHWM")
    print(RESULT + json.dumps(max(0, peak - before)))


def child(args: list[str]) -> int:
    out = subprocess.run([sys.executable, __file__] + args, capture_output=True, text=True,
                         check=True).stdout
    return json.loads(out.split(RESULT)[-1])


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out")
    p.add_argument("--repeats", type=int, default=REPEATS)
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--spp", type=int, default=8)
    p.add_argument("--memory-child", type=int, default=None, help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.memory_child is not None:
        return peak_memory(a.memory_child, a.size, a.spp)
    load_before = os.getloadavg()
    start = time.perf_counter()
    times = time_all(a.size, a.spp, a.repeats)
    common = ["--size", str(a.size), "--spp", str(a.spp), "--memory-child"]
    memory = {name: child(common + [str(i)]) for i, (name, _, _) in enumerate(RUNS)}
    load_after = os.getloadavg()
    primal = {k: statistics.median(times["primal"][k]) for k in ("cpu", "wall")}
    rows = []
    for name, _, _ in RUNS:
        med = {k: statistics.median(times[name][k]) for k in ("cpu", "wall")}
        rows.append({"run": name, "cpu_s": med["cpu"], "wall_s": med["wall"],
                     "cpu_ratio": med["cpu"] / primal["cpu"],
                     "wall_ratio": med["wall"] / primal["wall"],
                     "render_peak_mib": memory[name] / 1024})
    result = {"date": datetime.datetime.now().isoformat(timespec="seconds"),
              "variant": VARIANT, "scene": "photoelastic_disk", "size": a.size, "spp": a.spp,
              "repeats": a.repeats, "cpus": os.cpu_count(), "load_before": load_before,
              "load_after": load_after, "rows": rows,
              "times": times, "seconds": time.perf_counter() - start}
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "gradients.json").write_text(json.dumps(result, indent=1))
    print(f"photoelastic disk, {a.size}x{a.size}, {a.spp} spp, {VARIANT}, default (symbolic) mode; "
          f"load {load_before[0]:.1f} -> {load_after[0]:.1f} on {os.cpu_count()} cpus")
    print(f"{'run':42s} {'cpu s':>7s} {'x primal':>9s} {'wall s':>7s} {'x primal':>9s} "
          f"{'peak MiB':>9s}")
    for r in rows:
        print(f"{r['run']:42s} {r['cpu_s']:7.2f} {r['cpu_ratio']:9.2f} {r['wall_s']:7.2f} "
              f"{r['wall_ratio']:9.2f} {r['render_peak_mib']:9.0f}")
    print("(peak MiB: the renders' peak resident set over the process's before them)")


if __name__ == "__main__":
    main()
