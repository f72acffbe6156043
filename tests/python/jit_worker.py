"""Subprocess side of tests/python/test_jit_robustness.py: llvm renders in a fresh process, so
that the thread pool, Dr.Jit's caches and the resident set belong to these renders alone.
Prints one JSON line.

    jit_worker.py threads --counts 1 2
    jit_worker.py memory --renders 10 [--leak]
    jit_worker.py symbolic
"""

from __future__ import annotations

import argparse
import gc
import hashlib
import json
import os

import drjit as dr
import mitsuba as mi
import numpy as np

VARIANT = "llvm_ad_spectral_polarized"


def rss_kib() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def scene(spp: int, size: tuple[int, int] = (48, 32)):
    """The plate and the calcite sphere of the scalar robustness test (robustness_worker.py)."""
    from robustness_worker import PLATE, scene_dict

    return mi.load_dict(scene_dict(PLATE, spp=spp, size=size))


def render(s, seed: int) -> np.ndarray:
    import mitsuba_birefringent

    with mitsuba_birefringent.evaluated_mode():
        return np.array(mi.render(s, seed=seed), dtype=np.float32)


def threads(counts: list[int]) -> dict:
    s = scene(spp=16)
    hashes, tasks = [], []
    for n in counts:
        dr.set_thread_count(n)
        img = render(s, seed=7)
        tasks.append(len(os.listdir("/proc/self/task")))
        hashes.append(hashlib.sha256(img.tobytes()).hexdigest())
    return {"thread_counts": counts, "hashes": hashes, "tasks": tasks, "mean": float(img.mean())}


def memory(renders: int, leak: bool) -> dict:
    """VmRSS after 3 warm-up renders and after `renders` more (each 32 x 24 pixels x 16 spp:
    12,288 camera lanes per BSDF call, more with the paths' bounces). `leak` leaves 16 bytes per
    camera lane behind after each render (malloc'd and written, never freed): a deliberate leak,
    to show that the bound sees one of that size."""
    import ctypes

    import mitsuba_birefringent

    libc = ctypes.CDLL(None)
    libc.malloc.restype = ctypes.c_void_p
    size = (32, 24)
    lanes = size[0] * size[1] * 16
    s = scene(spp=16, size=size)
    for seed in range(3):
        render(s, seed)
    gc.collect()
    warm = rss_kib()
    kept = []
    for seed in range(renders):
        with mitsuba_birefringent.evaluated_mode():
            dr.eval(mi.render(s, seed=100 + seed))
        if leak:
            block = libc.malloc(16 * lanes)
            ctypes.memset(block, 1, 16 * lanes)
            kept.append(block)
    gc.collect()
    end = rss_kib()
    return {"rss_warm_kib": warm, "rss_end_kib": end, "renders": renders,
            "lanes_per_render": lanes, "kept": len(kept)}


def symbolic() -> dict:
    """What the documentation says of symbolic mode (Mitsuba's default). A scene whose plugins
    run inside the kernels (an exact plate and a calcite sphere) renders in it, and so does
    another scene while it lives. A plate over a band (its query runs on the host) fails in it
    with a message naming the flags; while it lives, a symbolic render of another scene (a
    dielectric, no plugin of ours) fails too; deleted and collected, that render works."""
    from robustness_worker import PLATE, scene_dict

    import mitsuba_birefringent

    def attempt(s) -> str:
        """A symbolic render: "rendered", or the message of the error's cause (the exception
        itself is dropped: its traceback would keep the scene alive)."""
        try:
            mi.render(s, seed=0)
            return "rendered"
        except RuntimeError as e:
            return str(e.__cause__ or e)

    out = {}
    kernel = scene(spp=2, size=(8, 8))
    out["kernel_symbolic"] = attempt(kernel)
    other = mi.load_dict(scene_dict({"type": "dielectric"}, spp=2, crystal=None, size=(8, 8)))
    out["other_with_kernel_alive"] = attempt(other)
    del kernel
    host = mi.load_dict(scene_dict({**PLATE, "filter_bandwidth": 4.0}, spp=2, crystal=None,
                                   size=(8, 8)))
    out["ours_symbolic"] = attempt(host)
    out["other_with_ours_alive"] = attempt(other)
    with mitsuba_birefringent.evaluated_mode():
        out["other_in_evaluated_mode"] = float(np.array(mi.render(other, seed=0)).mean())
    out["flags_restored"] = [bool(dr.flag(f)) for f in mitsuba_birefringent.jit.FLAGS]
    del host
    gc.collect()
    out["other_after_delete"] = float(np.array(mi.render(other, seed=0)).mean())
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=["threads", "memory", "symbolic"])
    ap.add_argument("--counts", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--renders", type=int, default=10)
    ap.add_argument("--leak", action="store_true")
    a = ap.parse_args()
    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)
    import llvm_target

    llvm_target.apply()

    if a.what == "threads":
        r = threads(a.counts)
    elif a.what == "memory":
        r = memory(a.renders, a.leak)
    else:
        r = symbolic()
    print(json.dumps(r))


if __name__ == "__main__":
    main()
