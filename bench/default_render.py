#!/usr/bin/env python3
"""The default render (`make render`: photoelastic_disk by `render_analytic`) as the README
states it: its remaining noise with each sampler, and its time against spectral sampling.

    .venv/bin/python bench/default_render.py [--size 320] [--spp 16] [--seeds 4]
        [--out bench/out/default_render.json]

Methods, each at `--spp` samples per pixel on the scene at `--size` x `--size`:
`render_analytic` with the scene's `independent` sampler and with `multijitter` (what `make
render` uses, scenes/render.py), and spectral sampling in scalar_spectral_polarized with
multijitter, at `--spp` and at 4 x `--spp`. Each method renders with `--seeds` seeds, the
methods interleaved seed by seed; a method's time is the median of its calls (render_analytic:
the whole call, three passes each loading and rendering the scene; spectral sampling: `mi.render`
of the loaded scene).

Noise, over the lit pixels (mean luminance above a fifth of the 99th percentile; the dark fringes
have none to speak of): the brightness noise is the root mean square over them of a pixel's
standard deviation over the seeds of its luminance Y, divided by its mean (per pixel, at the
method's spp); the colour noise the root mean square of the standard deviation of its
chromaticity (r, g) = (R, G) / (R + G + B), the larger of the two.
The channel render's remaining noise is the choice each path makes between the plate's reflection
and transmission, which every channel pass shares (the same seed): brightness, not colour.
"""

from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "scenes"))

SCENE = "photoelastic_disk"
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # linear sRGB -> Y


def methods(spp: int) -> dict[str, tuple[str, str, int]]:
    """name -> (how, sampler, spp)."""
    return {"render_analytic, independent": ("analytic", "independent", spp),
            "render_analytic, multijitter": ("analytic", "multijitter", spp),
            "spectral sampling, multijitter": ("spectral", "multijitter", spp),
            f"spectral sampling, multijitter, {4 * spp} spp": ("spectral", "multijitter", 4 * spp)}


def render(how: str, sampler: str, spp: int, size: int, seed: int) -> tuple[np.ndarray, float]:
    """(linear sRGB image, seconds)."""
    import importlib

    import mitsuba as mi

    mi.set_variant("scalar_spectral_polarized")
    import mitsuba_birefringent as mb

    d = importlib.import_module(SCENE).scene(width=size, height=size, spp=spp)
    d["sensor"]["sampler"]["type"] = sampler
    if how == "analytic":
        start = time.perf_counter()
        rgb = mb.render_analytic(d, spp=spp, seed=seed)["rgb"]
        return np.asarray(rgb, dtype=np.float64), time.perf_counter() - start
    scene = mi.load_dict(d)
    start = time.perf_counter()
    image = np.array(mi.render(scene, seed=seed), dtype=np.float64)
    return image[..., :3], time.perf_counter() - start


def noise(images: list[np.ndarray]) -> dict[str, float]:
    """Root mean square over the lit pixels of each pixel's relative standard deviation of its
    luminance, and of its chromaticity's standard deviation (module docstring); the per-pixel
    variances over the seeds are unbiased (ddof 1), so their mean is too."""
    stack = np.stack(images)  # (seeds, H, W, 3)
    y = stack @ LUMINANCE
    mean_y = y.mean(axis=0)
    lit = mean_y > 0.2 * np.percentile(mean_y, 99)
    rel_var = y.var(axis=0, ddof=1)[lit] / mean_y[lit] ** 2
    total = np.clip(stack.sum(axis=-1, keepdims=True), 1e-12, None)
    chroma_var = (stack / total)[..., :2].var(axis=0, ddof=1)[lit]  # (pixels, 2)
    return {"brightness": float(np.sqrt(rel_var.mean())),
            "colour": float(np.sqrt(chroma_var.max(axis=-1).mean())),
            "lit_pixels": int(lit.sum())}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--size", type=int, default=320)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--seeds", type=int, default=4)
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out" / "default_render.json")
    a = p.parse_args()
    ms = methods(a.spp)
    images: dict[str, list[np.ndarray]] = {m: [] for m in ms}
    seconds: dict[str, list[float]] = {m: [] for m in ms}
    load_start, start = os.getloadavg(), time.time()
    # A first call of each kind compiles Dr.Jit's kernels and loads the textures: not timed.
    render("analytic", "multijitter", 1, 16, 0)
    for seed in range(a.seeds):
        for m, (how, sampler, spp) in ms.items():
            image, s = render(how, sampler, spp, a.size, seed)
            images[m].append(image)
            seconds[m].append(s)
            print(f"seed {seed}: {m}: {s:.1f} s", flush=True)
    out = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime(start)),
           "settings": {"scene": SCENE, "size": a.size, "spp": a.spp, "seeds": a.seeds},
           "load_average_start": load_start, "load_average_end": os.getloadavg(),
           "logical_cores": os.cpu_count(), "methods": {}}
    for m in ms:
        out["methods"][m] = {"spp": ms[m][2], "seconds": statistics.median(seconds[m]),
                             **noise(images[m])}
        r = out["methods"][m]
        print(f"{m} ({r['spp']} spp): {r['seconds']:.1f} s, brightness noise "
              f"{100 * r['brightness']:.1f} % per pixel, colour noise {r['colour']:.4f}")
    print(f"load average {load_start[0]:.2f} at the start, {out['load_average_end'][0]:.2f} at the end "
          f"({os.cpu_count()} cores)")
    a.out.parent.mkdir(parents=True, exist_ok=True)
    a.out.write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
