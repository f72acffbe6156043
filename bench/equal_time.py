#!/usr/bin/env python3
"""The channel render and spectral sampling at equal render time, side by side (``make
bench-scenes`` runs it after bench/scenes.py).

    .venv/bin/python bench/equal_time.py [--out bench/out] [--results bench/results.json]
                                         [--figure bench/analytic_vs_spectral.png] [--quick]

For each scene of ``FRAMES`` (the photoelastic disk whole at 128x128 px, a 128x128 crop of the
Michel-Levy wedge's 384x128 image: its middle third, 40 to 80 um of quartz, first- and
second-order colours):

* the channel render, ``mitsuba_birefringent.render_analytic`` at ``SPP`` samples per pixel,
  with the scene's own (independent) sampler and with multijitter, timed as the whole call
  (three passes, each loading the scene in llvm_ad_mono_polarized; the second of two calls, the
  first compiles Dr.Jit's kernels: bench/scenes.py `analytic_curve`);
* exact per-wavelength sampling (``filter_bandwidth`` 0) in scalar_spectral_polarized and in
  llvm_ad_spectral_polarized (evaluated mode) at the number of samples that takes the
  independent channel render's time: their time per sample measured on a render of
  ``CALIBRATION_SPP`` spp, the count rounded (in llvm to a multiple of the passes of
  bench/scenes.py JIT_SAMPLES_PER_PASS above one pass) and corrected where the render's time
  misses by more than ``TOLERANCE``; each panel shows the time it took;
* the exact reference at ``REFERENCE_SPP`` (bench/scenes.py `reference`, cached in the output
  directory), with its own error estimated from its passes.

Every panel is labelled with its method, spp, time and mean CIEDE2000 against the reference
(bench/scenes.py `errors`), tone-mapped alike (Mitsuba's sRGB conversion, clipped). Writes the
figure to ``OUT/analytic_vs_spectral.png`` and a copy to ``FIGURE`` (which the README shows),
the measurements to ``OUT/equal_time.json`` and under ``"equal_time"`` into RESULTS (which
bench/readme.py reads; bench/scenes.py rewrites that file, so run this after it).
"""

from __future__ import annotations

import argparse
import json
import pathlib
import shutil
import sys
import warnings

import numpy as np

import scenes as bench

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: Frames of the figure: full image size and the crop (x, y, width, height) rendered.
FRAMES = {"photoelastic_disk": {"size": [128, 128], "crop": [0, 0, 128, 128]},
          "michel_levy": {"size": [384, 128], "crop": [128, 0, 128, 128]}}
#: The channel render's samples per pixel, the calibration render's, the reference's.
SPP, CALIBRATION_SPP, REFERENCE_SPP = 16, 16, 1024
#: Equal time: an exact render's time may differ from the channel render's by TOLERANCE; else
#: its spp is rescaled by the ratio of the times, at most REFINE times (the time per sample
#: at the calibration's spp includes a fixed cost per render, large in the llvm variant).
TOLERANCE, REFINE = 0.15, 2


def sample_count(estimate: float, jit: bool) -> int:
    """`estimate` rounded to a sample count (in llvm, to whole passes above one pass)."""
    spp = max(1, round(estimate))
    if jit and spp > bench.JIT_SAMPLES_PER_PASS:
        spp = bench.JIT_SAMPLES_PER_PASS * round(spp / bench.JIT_SAMPLES_PER_PASS)
    return spp


def exact_panel(name: str, module, ref: dict, variant: str, seconds: float) -> dict:
    """Exact sampling in `variant` at the spp that takes `seconds` (module docstring)."""
    jit = variant.startswith("llvm")
    mi = bench.set_variant(variant)
    d = bench.scene_dict(module, name, 1, FRAMES[name], filter_bandwidth=0.0)
    if jit:
        d["integrator"]["samples_per_pass"] = bench.JIT_SAMPLES_PER_PASS
    scene = mi.load_dict(d)
    timed = bench.render_evaluated if jit else bench.render
    timed(mi, scene, CALIBRATION_SPP, seed=800)  # warm-up (and Dr.Jit's kernels)
    per_spp = timed(mi, scene, CALIBRATION_SPP, seed=801)[1] / CALIBRATION_SPP
    spp = sample_count(seconds / per_spp, jit)
    print(f"  exact, {variant}: {per_spp * 1e3:.1f} ms per spp -> {spp} spp")
    for attempt in range(1 + REFINE):
        if jit:
            timed(mi, scene, spp, seed=802 + 2 * attempt)  # the kernels of this spp
        img, took = timed(mi, scene, spp, seed=803 + 2 * attempt)
        again = sample_count(spp * seconds / took, jit)
        if abs(took / seconds - 1) <= TOLERANCE or again == spp or attempt == REFINE:
            break
        print(f"    {spp} spp took {took:.2f} s -> {again} spp")
        spp = again
    row = bench.point(spp, took, img, ref)
    return dict(row, method=f"exact:{variant}", image=img, seconds_per_spp=per_spp,
                label=f"exact sampling\n{variant}")


def scene_panels(name: str, module, out: pathlib.Path) -> dict:
    f = FRAMES[name]
    print(f"{name}: {f['crop'][2]}x{f['crop'][3]} px crop at ({f['crop'][0]}, {f['crop'][1]}) "
          f"of {f['size'][0]}x{f['size'][1]}")
    ref = bench.reference(name, module, "scalar_spectral_polarized", out, f, REFERENCE_SPP)
    images = {}
    channel = []
    for method, (sampler, _) in bench.CHANNEL_METHODS.items():
        print(f"  render_analytic, {sampler} sampler")
        rows, _ = bench.analytic_curve(module, name, sampler, (SPP,), 700, ref, f,
                                       keep_image=True)
        row = rows[0]
        images[method] = row.pop("image")
        channel.append(dict(row, method=method, label=f"render_analytic\n{sampler}"))
    budget = channel[0]["seconds"]  # the independent sampler's: the scene's own
    exact = []
    for variant in ("scalar_spectral_polarized", bench.JIT_VARIANT):
        row = exact_panel(name, module, ref, variant, budget)
        images[row["method"]] = row.pop("image")
        exact.append(row)
    noise = ref["noise"]
    print(f"  reference: {REFERENCE_SPP} spp, own mean CIEDE2000 {noise['mean_de2000']:.3f}")
    return {"frame": f, "reference": {"spp": REFERENCE_SPP, "seconds": ref["seconds"],
                                      "noise": noise, "cache": ref["cache"]},
            "panels": channel + exact, "images": dict(images, reference=ref["mean"])}


def srgb(image: np.ndarray) -> np.ndarray:
    """8-bit sRGB of a linear sRGB image (Mitsuba's conversion, as scenes/render.py's PNGs)."""
    import mitsuba as mi

    bitmap = mi.util.convert_to_bitmap(mi.Bitmap(np.ascontiguousarray(image, dtype=np.float32)))
    return np.array(bitmap)


def figure(results: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(results)
    columns = 1 + len(results[names[0]]["panels"])
    fig, axes = plt.subplots(len(names), columns, figsize=(2.3 * columns, 3.0 * len(names)),
                             dpi=100, squeeze=False)
    for row, name in zip(axes, names):
        r = results[name]
        ref = r["reference"]
        cells = [("reference", f"reference: exact sampling\n{ref['spp']} spp, "
                  f"{ref['seconds']:.0f} s\nown error ~{ref['noise']['mean_de2000']:.2f}")]
        cells += [(p["method"], f"{p['label']}\n{p['spp']} spp, {p['seconds']:.1f} s\n"
                   f"mean CIEDE2000 {p['mean_de2000']:.2f}") for p in r["panels"]]
        for ax, (key, title) in zip(row, cells):
            ax.imshow(srgb(r["images"][key]), interpolation="nearest")
            ax.set_title(title, fontsize=7.5)
            ax.set_xticks([])
            ax.set_yticks([])
        row[0].set_ylabel(name, fontsize=9)
    fig.suptitle("The channel render (render_analytic) and exact spectral sampling at equal "
                 "render time", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def figure_path(path: pathlib.Path) -> str:
    """`path` relative to the repository when it lies in it (as the README links it)."""
    path = path.resolve()
    return str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path)


def main() -> int:
    global SPP, CALIBRATION_SPP, REFERENCE_SPP
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out")
    p.add_argument("--results", type=pathlib.Path, default=ROOT / "bench" / "results.json")
    p.add_argument("--figure", type=pathlib.Path, default=None,
                   help="copy of the figure (default bench/analytic_vs_spectral.png; none with --quick)")
    p.add_argument("--quick", action="store_true",
                   help="tiny budgets to check that the script runs (figures meaningless)")
    a = p.parse_args()
    if a.quick:
        SPP, CALIBRATION_SPP, REFERENCE_SPP = 2, 2, 16
        for f in FRAMES.values():
            f["crop"][2:] = [32, 32]
    a.out.mkdir(parents=True, exist_ok=True)
    warnings.filterwarnings("ignore", module="colour")
    modules = bench.discover(list(FRAMES))
    results = {name: scene_panels(name, modules[name], a.out) for name in FRAMES}
    png = a.out / "analytic_vs_spectral.png"
    figure(results, png)
    if a.figure is None and not a.quick:
        a.figure = ROOT / "bench" / "analytic_vs_spectral.png"
    if a.figure is not None:
        shutil.copyfile(png, a.figure)
    summary = {name: {k: v for k, v in r.items() if k != "images"} for name, r in results.items()}
    (a.out / "equal_time.json").write_text(json.dumps(summary, indent=1))
    if a.results.exists():
        data = json.loads(a.results.read_text())
        data["equal_time"] = {"scenes": summary, "figure": figure_path(a.figure or png)}
        a.results.write_text(json.dumps(data, indent=2) + "\n")
    print(f"wrote {png}, {a.figure or 'no copy'}, {a.out / 'equal_time.json'}"
          + (f" and {a.results}" if a.results.exists() else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
