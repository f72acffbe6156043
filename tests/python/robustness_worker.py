"""Subprocess side of tests/python/test_robustness.py: renders in a fresh process, so that the
thread pool size and the resident set belong to these renders alone. Prints one JSON line.

    robustness_worker.py threads --counts 1 2 8
    robustness_worker.py memory --renders 4 --loads 20000 [--retain]

Also imported by the test module for `scene_dict` (it sets the variant itself).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os

import drjit as dr
import mitsuba as mi
import numpy as np

VARIANT = "scalar_spectral_polarized"
WIDTH, HEIGHT = 48, 32


CALCITE = {"type": "birefringent", "material": "calcite", "optic_axis": [1, 1, 1],
           "optic_axis_space": "world"}


def scene_dict(plate_bsdf: dict, spp: int = 8, crystal: dict | None = CALCITE,
               size: tuple[int, int] = (WIDTH, HEIGHT)) -> dict:
    """A camera looking down at a plate (the rectangle [-1, 1]^2, filling the view) lit by a
    constant environment, with a crystal sphere (calcite: needs the polarized variant) above
    it: every camera ray queries the plate or the crystal, and paths through the sphere query
    both. `crystal=None` leaves the sphere out."""
    scene = {
        "type": "scene",
        # A fixed block size: by default Mitsuba halves its 32-pixel blocks until there are at
        # least as many blocks as threads, and the sampler is seeded per block, so the image
        # would change with the thread count for a reason that has nothing to do with the
        # plugins (measured: every pixel differs between 1 and 2 threads with the default).
        "integrator": {"type": "path", "max_depth": 5, "block_size": 8},
        "sensor": {
            "type": "perspective",
            "fov": 35,
            "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 3], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": size[0], "height": size[1], "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "env": {"type": "constant"},
        "plate": {"type": "rectangle", "bsdf": plate_bsdf},
    }
    if crystal is not None:
        scene["crystal"] = {"type": "sphere", "center": [0.3, 0.1, 0.6], "radius": 0.35, "bsdf": crystal}
    return scene


PLATE = {"type": "thinbirefringent", "material": "quartz", "optic_axis": [1, 1, 0], "thickness": 20.0,
         "filter_bandwidth": 0.0}


def rss_kib() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise RuntimeError("no VmRSS in /proc/self/status")


def threads(counts: list[int]) -> dict:
    scene = mi.load_dict(scene_dict(PLATE, spp=16))
    hashes, tasks, finite, mean = [], [], True, 0.0
    for n in counts:
        dr.set_thread_count(n)
        img = np.array(mi.render(scene, seed=7), dtype=np.float32)
        tasks.append(len(os.listdir("/proc/self/task")))  # the pool's workers exist
        hashes.append(hashlib.sha256(img.tobytes()).hexdigest())
        finite &= bool(np.isfinite(img).all())
        mean = float(img.mean())
    return {"thread_counts": counts, "hashes": hashes, "tasks": tasks, "finite": finite, "mean": mean}


def memory(renders: int, loads: int, retain: bool = False) -> dict:
    """VmRSS after a warm-up, after `renders` renders and after `loads` loads of each plugin.
    `retain` keeps every loaded BSDF alive: a deliberate leak, to show the bound catches one."""
    spp = 32
    scene = mi.load_dict(scene_dict(PLATE, spp=spp))
    for seed in range(2):  # warm-up: pools, caches, first-use allocations
        mi.render(scene, seed=seed)
    for _ in range(200):
        mi.load_dict(PLATE)
        mi.load_dict(CALCITE)
    warm = rss_kib()
    for seed in range(renders):
        mi.render(scene, seed=100 + seed)
    after_renders = rss_kib()
    kept = []
    for _ in range(loads):
        a, b = mi.load_dict(PLATE), mi.load_dict(CALCITE)
        if retain:
            kept += [a, b]
    end = rss_kib()
    return {"rss_warm_kib": warm, "rss_renders_kib": after_renders, "rss_end_kib": end,
            # camera samples, each a first hit on the plate or the sphere: a lower bound of the
            # BSDF queries
            "queries": renders * WIDTH * HEIGHT * spp, "loads": loads, "retained": len(kept)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("what", choices=["threads", "memory"])
    ap.add_argument("--counts", type=int, nargs="+", default=[1, 2, 8])
    ap.add_argument("--renders", type=int, default=4)
    ap.add_argument("--loads", type=int, default=20000)
    ap.add_argument("--retain", action="store_true", help="keep every loaded BSDF (a deliberate leak)")
    a = ap.parse_args()
    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)

    r = threads(a.counts) if a.what == "threads" else memory(a.renders, a.loads, a.retain)
    print(json.dumps(r))


if __name__ == "__main__":
    main()
