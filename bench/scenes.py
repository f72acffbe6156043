#!/usr/bin/env python3
"""Scene-level benchmarks (``make bench-scenes``; ``make bench`` runs it after the core benchmark).

    .venv/bin/python bench/scenes.py [--out bench/out] [--results bench/results.json]
                                     [--scenes a,b] [--repeats N] [--quick]
                                     [--only overhead [--pairs KEY,KEY]]

Three parts, all measured here, in this process, with Mitsuba's default thread pool (every core
of the machine; wall time of ``mi.render`` only, the scene loaded and rendered once beforehand,
except for the channel render: see (d)):

1. **Error vs time, per scene.** Every module of ``scenes/`` with ``scene`` and ``VARIANTS`` is
   rendered small (``SIZES``), or as a small crop of its own resolution (``CROPS``). Its
   spectral variant is the first of ``VARIANTS`` whose name contains "spectral". Reference:
   that variant with exact per-wavelength evaluation (``filter_bandwidth = 0``) at
   ``REFERENCE_SPP`` samples per pixel (``SCENE_BUDGETS`` for some scenes), rendered in
   ``REFERENCE_PASSES`` independent passes (their spread estimates the reference's own noise),
   cached in ``bench/out/reference-<scene>-<hash>.npz``, the hash over the scene's source, the
   render parameters, Mitsuba's version and the plugin library's bytes. Methods:
   (a) ``exact``: the spectral variant, ``filter_bandwidth = 0``, at increasing spp;
   (b) ``filter``: the same with a 4 nm band (``filter_bandwidth = 4``; the default is 0);
   (c) ``rgb``: ``scalar_rgb`` (the plate integrated in closed form over the sRGB channels), if
   the scene's ``VARIANTS`` list it;
   and for the scenes of ``CHANNEL_SCENES``:
   (a') ``exact_llvm``: exact sampling as (a) in ``llvm_ad_spectral_polarized`` in evaluated mode
   (``JIT_SAMPLES_PER_PASS`` spp per pass);
   (d) the channel render, ``mitsuba_birefringent.render_analytic`` (one llvm_ad_mono_polarized
   pass per sRGB channel, each plate integrated over the channel in closed form), with the
   scene's own independent sampler (``analytic``) and with multijitter
   (``analytic_multijitter``); its time is the whole call (three passes, each loading the scene).
   In the llvm variants each point's time is that of the second of two renders at its spp (the
   first, whose time is kept as ``first_seconds``, compiles Dr.Jit's kernels).
   Errors against the reference: relative RMSE in linear RGB, ``sqrt(mean((x - r)^2) - v_r) /
   sqrt(mean(r^2))`` with ``v_r`` the reference's own variance per pixel (estimated from its
   passes; this removes the reference's noise from the estimate), and the mean CIEDE2000 over
   pixels of the images converted linear sRGB -> XYZ (D65) -> CIE Lab with the white's Y = the
   99th percentile of the reference's luminance (colour-science's implementations).
   **At equal error**: for a point (t_m, e_m) of method (b) or (c), the time (a) needs to reach
   e_m is interpolated linearly in (log e, log t) between the two points of curve (a) that
   bracket e_m (extrapolated along the last (or first) segment of (a) when e_m lies outside its
   measured range, and flagged ``extrapolated``); the ratio is t_a(e_m) / t_m. The scene's
   headline figure is that ratio (mean CIEDE2000) at the method's highest-spp point whose error
   lies within the range of (a), else at its highest-spp point (flagged). The channel render's
   figures (`channel_render`): at each spp of ``CHANNEL_RATIO_SPP``, the time (a) and (a') need
   to reach its mean CIEDE2000, over its time. The reference's own error (`reference_noise`) is
   estimated from the two halves of its passes.

2. **Overhead against Mitsuba's own plugins**: a room (diffuse walls, ceiling light), ``path``
   with max_depth 8, with our plugin against the same room with the Mitsuba plugin a user would
   use instead (``OVERHEAD_PAIRS``; the rooms in ``CONFIGS``). Isotropic rows (the core's fast
   path): three glass panes (``thinbirefringent`` eta_o = eta_e = 1.5, 1000 um, against
   ``thindielectric`` int_ior 1.5), a glass sphere and cube (``birefringent`` eta_o = eta_e =
   1.5 against ``dielectric`` int_ior 1.5). Anisotropic rows: the three panes as quartz plates
   (``material`` quartz) of each thickness of ``QUARTZ_UM`` between crossed ``polarizer``
   rectangles, against ``thindielectric`` int_ior 1.544 between the same polarisers; the panes
   as 3 mm photoelastic plates (eta_o = 1.5, ``birefringence`` 2e-4) between them, against
   ``thindielectric`` 1.5; a calcite sphere and cube against ``dielectric`` 1.658 (polarised
   variants only: a bulk crystal needs one); a glass and a calcite sphere on the floor, light
   bouncing inside them. In scalar_rgb, llvm_ad_rgb, scalar_spectral_polarized and
   llvm_ad_spectral_polarized, same spp; the quartz plates also as one pass of a channel render
   (``CHANNEL_PASS``: the room rewritten for sRGB's green as ``render_analytic`` rewrites it, in
   llvm_ad_mono_polarized), against the same pass with ``thindielectric``. Every configuration
   of a variant is loaded and rendered once at the timed spp (this compiles the llvm variants'
   kernels), then all are rendered in turn, ``repeats`` rounds (interleaved), with fresh seeds
   (a render during which Dr.Jit compiled a kernel is repeated at once with its seed, and the
   repeat timed: `compiled_none`); figure = median time of ours / median time of Mitsuba's,
   each against its goal (``OVERHEAD_GOALS``). In the llvm variants ours render in Dr.Jit's
   evaluated mode (they need it), and so must every render while one of ours exists: the rounds
   run both in evaluated mode, then ours are deleted and Mitsuba's timed in evaluated against
   symbolic mode (its default), interleaved; the figure against Mitsuba's symbolic mode is the
   product of the two ratios (`overhead`). The same loop times the isotropic fast path at scene
   level (``FAST_PATH_PAIRS``): the glass scenes with eta_e = 1.5 + 1e-9 (optically identical,
   anisotropic to the core) against eta_e = 1.5, in scalar_spectral_polarized.
   ``--only overhead`` measures this part alone and merges it into the existing results;
   ``--pairs`` with it measures only the named rows of ``OVERHEAD_PAIRS`` and merges those rows,
   each with its own date, load and command (``measured``), keeping every other figure.

3. **Shortcuts**: the core-level ratios of ``examples/bench_shortcuts.rs`` (read from
   ``bench/out/shortcuts.json``, which ``make bench-scenes`` writes first) plus the scene-level
   isotropic ratios of part 2: every case (``shortcut_cases``) and one headline case each
   (``shortcuts``).

Writes ``bench/results.json`` (the summary: ``overhead`` with its own date and load,
``analytic_speedup_at_equal_error``, ``channel_render``, ``reference_noise``, ``shortcuts``,
``shortcut_cases``, the machine and the date),
``bench/out/scenes.json`` (every measurement) and one PNG per scene
(``bench/out/error_vs_time-<scene>.png``). ``bench/readme.py`` turns the results into the README
section.
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import importlib
import json
import math
import os
import pathlib
import platform
import statistics
import sys
import time
import typing
import warnings

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
SCENES_DIR = ROOT / "scenes"

#: Image size per scene (small: the benchmark must stay within minutes); default for others.
SIZES = {"michel_levy": (72, 24)}
DEFAULT_SIZE = (32, 32)
#: Scenes rendered at their own resolution, of which only a crop (x, y, width, height) is
#: computed: the thin film's colours change within a pixel of a 32x32 frame (~22 nm of film
#: thickness per pixel), so antialiasing noise, common to every method, dominates every error
#: there (measured in the first run of this benchmark: analytic RGB 0.31x of exact sampling's
#: speed at 32x32); a 32x32 crop of the 256x256 image (the scene's default size, the gallery's)
#: costs the same and has the pixel footprint a user renders.
CROPS = {"thin_film": ((256, 256), (112, 112, 32, 32))}


def frame(name: str) -> dict:
    """How scene `name` is rendered: full image size and the crop computed (the whole image if
    it has no entry in CROPS)."""
    if name in CROPS:
        full, crop = CROPS[name]
        return {"size": list(full), "crop": list(crop)}
    size = list(SIZES.get(name, DEFAULT_SIZE))
    return {"size": size, "crop": [0, 0, *size]}


def scene_dict(module, name: str, spp: int, fr: dict | None = None, **options) -> dict:
    """The dict of scene `name` at frame `fr` (default: its benchmark frame, see `frame`)."""
    f = fr or frame(name)
    d = module.scene(width=f["size"][0], height=f["size"][1], spp=spp, **options)
    x, y, w, h = f["crop"]
    d["sensor"]["film"].update(crop_offset_x=x, crop_offset_y=y, crop_width=w, crop_height=h)
    return d


def load(mi, module, name: str, spp: int, fr: dict | None = None, **options):
    """The scene `name` at frame `fr` (default: its benchmark frame), loaded."""
    return mi.load_dict(scene_dict(module, name, spp, fr, **options))
#: Samples per pixel of the curves, per method; the reference has REFERENCE_SPP.
SPP = {"exact": (1, 4, 16, 64, 256), "filter": (2, 8, 32), "rgb": (1, 2, 4, 8, 16)}
REFERENCE_SPP, REFERENCE_PASSES = 2048, 8
#: Larger budgets for scenes whose methods reach errors the defaults cannot resolve: the thin
#: film's analytic RGB falls below the error of exact sampling at 256 spp (CIEDE2000 0.95) from
#: 4 spp on, and a 2048-spp reference is itself that noisy (~0.3); exact sampling there costs
#: ~3 us per sample, so 4096 spp and a 32768-spp reference take about two minutes.
SCENE_BUDGETS = {"thin_film": {"exact": (1, 4, 16, 64, 256, 1024, 4096), "reference_spp": 32768}}
#: The scenes of the channel render's study (``render_analytic``; see `channel_render`).
CHANNEL_SCENES = ("photoelastic_disk", "michel_levy", "train_window", "waveplates")
#: The channel render's curves: method -> (sampler type, samples per pixel). ``analytic`` keeps
#: the scenes' own sampler (independent). Its remaining noise is the plate's choice between
#: reflection and transmission (and the pixel footprint), which a stratified sampler reduces:
#: ``analytic_multijitter`` is the same render with Mitsuba's multijitter sampler (it keeps
#: 1, 2, 4, 8, 16 and 36 samples exactly; 32 it rounds up to 35).
CHANNEL_METHODS = {"analytic": ("independent", (1, 2, 4, 8, 16, 32)),
                   "analytic_multijitter": ("multijitter", (1, 2, 4, 8, 16, 36))}
#: The channel render's points at which the time of exact sampling at equal error is reported.
CHANNEL_RATIO_SPP = (4, 16)
#: Exact sampling and its reference for those scenes: the channel render at 16 spp has the
#: error of exact sampling at 50 to 2400 spp (measured, bench/results.json: photoelastic_disk
#: mean CIEDE2000 4.1 with the independent sampler, ~50 spp of exact sampling; 1.8 with
#: multijitter, ~270 spp; waveplates 0.74 with multijitter, ~2400 spp, the one point beyond
#: 1024 spp), so exact sampling runs to 1024 spp; a reference of 8192 spp has an own error of
#: 0.18 to 0.39 there (the spread of its passes, reported per scene).
for _name in CHANNEL_SCENES:
    SCENE_BUDGETS[_name] = {"exact": (1, 4, 16, 64, 256, 1024), "reference_spp": 8192}
#: The llvm variant of exact sampling (evaluated mode), in passes of at most this many spp (a
#: whole 1024-spp render in one wavefront would hold every lane's state at once).
JIT_VARIANT, JIT_SAMPLES_PER_PASS = "llvm_ad_spectral_polarized", 64
#: Overhead scene: size, spp, rounds (each render a few tenths of a second or more, well above
#: the timer's and the thread pool's noise). 32 px rather than the 48 px of the scalar-only table:
#: with the llvm variants in evaluated mode (~6 s per render of ours at 48 px on 2 loaded cores)
#: the table would take over 20 minutes.
OVERHEAD_SIZE, OVERHEAD_SPP, OVERHEAD_REPEATS = 32, 32, 5


def budget(name: str) -> tuple[dict, int]:
    """Samples per pixel of the curves per method, and of the reference, for scene `name`
    (``exact_llvm``, exact sampling in the llvm variant, has the list of ``exact``)."""
    b = SCENE_BUDGETS.get(name, {})
    spp = {m: tuple(b.get(m, v)) for m, v in SPP.items()}
    spp["exact_llvm"] = tuple(b.get("exact_llvm", spp["exact"]))
    return spp, b.get("reference_spp", REFERENCE_SPP)
#: The variants (the overhead table's columns, in order). In the llvm variants ours render in
#: Dr.Jit's evaluated mode, the one they run in (``mitsuba_birefringent.evaluated_mode``); the
#: figure is against Mitsuba's plugins in their default symbolic mode (`overhead`).
OVERHEAD_VARIANTS = ("scalar_rgb", "llvm_ad_rgb", "scalar_spectral_polarized",
                     "llvm_ad_spectral_polarized", "llvm_ad_mono_polarized")
#: The variants whose rooms are one pass of a channel render (``render_analytic``): the room
#: rewritten for one colour channel as its pass does (``ChannelScene``; our plates integrate
#: over the channel), here sRGB's green, and rendered in the variant of its passes.
CHANNEL_PASS = {"llvm_ad_mono_polarized": "srgb-d65:G"}


def load_average() -> list[float] | None:
    """1, 5 and 15 minute load averages (/proc/loadavg): how busy the machine was."""
    try:
        return [float(x) for x in open("/proc/loadavg", encoding="utf-8").read().split()[:3]]
    except OSError:
        return None


def machine() -> dict:
    model, cores = "unknown", 0
    try:
        for line in open("/proc/cpuinfo", encoding="utf-8"):
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                cores += 1
    except OSError:
        pass
    return {"cpu": model, "logical_cores": cores or os.cpu_count(), "system": platform.platform(),
            "python": platform.python_version()}


def set_variant(variant: str):
    import mitsuba as mi

    mi.set_variant(variant)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins for this variant)

    return mi


def discover(names: list[str] | None) -> dict:
    """Scene modules of scenes/ that define `scene` and `VARIANTS`."""
    sys.path.insert(0, str(SCENES_DIR))
    import mitsuba as mi

    mi.set_variant("scalar_rgb")  # scene modules import mitsuba at import time
    found = {}
    for path in sorted(SCENES_DIR.glob("*.py")):
        if names and path.stem not in names:
            continue
        module = importlib.import_module(path.stem)
        if callable(getattr(module, "scene", None)) and hasattr(module, "VARIANTS"):
            found[path.stem] = module
    return found


def render(mi, scene, spp: int, seed: int) -> tuple[np.ndarray, float]:
    start = time.perf_counter()
    image = mi.render(scene, spp=spp, seed=seed)
    seconds = time.perf_counter() - start
    return np.array(image, dtype=np.float64)[..., :3], seconds


def plugin_digest() -> str:
    import mitsuba_birefringent

    lib = pathlib.Path(mitsuba_birefringent.__file__).parent / "libmitsuba_birefringent.so"
    return hashlib.sha256(lib.read_bytes()).hexdigest() if lib.exists() else "none"


def reference(name: str, module, variant: str, out: pathlib.Path, fr: dict | None = None,
              total: int | None = None) -> dict:
    """The exact per-wavelength reference of scene `name` at frame `fr` (default: its benchmark
    frame) with `total` spp (default: its budget's), cached; ``"noise"`` is its own error
    (`reference_noise`)."""
    mi = set_variant(variant)
    fr = fr or frame(name)
    total = total or budget(name)[1]
    key = json.dumps({"scene": name, "source": hashlib.sha256(
        pathlib.Path(module.__file__).read_bytes()).hexdigest(), "variant": variant,
        "frame": fr, "spp": total, "passes": REFERENCE_PASSES, "format": 2,
        "mitsuba": mi.__version__, "plugin": plugin_digest()}, sort_keys=True)
    digest = hashlib.sha256(key.encode()).hexdigest()[:16]
    cache = out / f"reference-{name}-{digest}.npz"
    if cache.exists():
        data = np.load(cache)
        print(f"  reference: cached {cache.name}")
        ref = {"mean": data["mean"], "var": data["var"], "halves": data["halves"],
               "seconds": float(data["seconds"]), "cache": cache.name, "cached": True}
        return dict(ref, noise=reference_noise(ref))
    scene = load(mi, module, name, total, fr, filter_bandwidth=0.0)
    spp = total // REFERENCE_PASSES
    passes, seconds = [], 0.0
    for p in range(REFERENCE_PASSES):
        img, dt = render(mi, scene, spp, seed=1_000_003 + p)
        passes.append(img)
        seconds += dt
    passes = np.array(passes)
    mean = passes.mean(axis=0)
    var = passes.var(axis=0, ddof=1) / REFERENCE_PASSES  # variance of the mean, per pixel
    half = REFERENCE_PASSES // 2
    halves = np.array([passes[:half].mean(axis=0), passes[half:].mean(axis=0)])
    np.savez(cache, mean=mean, var=var, halves=halves, seconds=seconds)
    print(f"  reference: {total} spp in {seconds:.1f} s -> {cache.name}")
    ref = {"mean": mean, "var": var, "halves": halves, "seconds": seconds,
           "cache": cache.name, "cached": False}
    return dict(ref, noise=reference_noise(ref))


def reference_noise(ref: dict) -> dict:
    """The reference's own error, from its passes. ``mean_de2000_halves``: mean CIEDE2000
    between the means of its two halves of passes; each half has twice the variance of the
    whole, their difference four times, so the whole's own error is about half of it
    (``mean_de2000``; CIEDE2000 is close to linear in small differences). ``rel_rmse``:
    sqrt(mean(v_r)) / sqrt(mean(r^2)), v_r its variance per pixel."""
    a, b = ref["halves"]
    halves = errors(b, {"mean": a, "var": np.zeros_like(a)})["mean_de2000"]
    rel = math.sqrt(float(np.mean(ref["var"])) / float(np.mean(ref["mean"] ** 2)))
    return {"mean_de2000_halves": halves, "mean_de2000": halves / 2, "rel_rmse": rel}


def lab(rgb: np.ndarray, white_y: float) -> np.ndarray:
    import colour

    xyz = colour.RGB_to_XYZ(np.maximum(rgb, 0.0), "sRGB", apply_cctf_decoding=False)
    illuminant = colour.CCS_ILLUMINANTS["CIE 1931 2 Degree Standard Observer"]["D65"]
    return colour.XYZ_to_Lab(xyz / white_y, illuminant)


def errors(img: np.ndarray, ref: dict) -> dict:
    import colour

    r = ref["mean"]
    mse = float(np.mean((img - r) ** 2) - np.mean(ref["var"]))
    rel_rmse = math.sqrt(max(mse, 0.0) / float(np.mean(r ** 2)))
    y = r @ np.array([0.2126, 0.7152, 0.0722])
    white = max(float(np.percentile(y, 99)), 1e-6)
    de = colour.delta_E(lab(img, white), lab(r, white), method="CIE 2000")
    return {"rel_rmse": rel_rmse, "mean_de2000": float(np.mean(de))}


def render_evaluated(mi, scene, spp: int, seed: int) -> tuple[np.ndarray, float]:
    """`render` in an llvm variant, in evaluated mode; the time includes reading the image
    back (which waits for Dr.Jit's last kernels)."""
    import mitsuba_birefringent

    with mitsuba_birefringent.evaluated_mode():
        start = time.perf_counter()
        image = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)[..., :3]
        seconds = time.perf_counter() - start
    return image, seconds


def curve_with(mi, module, name, spp_list, seed0, ref, jit: bool = False, **options) -> list[dict]:
    """Error and time of scene `name` rendered at each of `spp_list` in the current variant
    (with `jit`: an llvm variant, in evaluated mode, JIT_SAMPLES_PER_PASS spp per pass)."""
    d = scene_dict(module, name, 1, **options)
    if jit:
        d["integrator"]["samples_per_pass"] = JIT_SAMPLES_PER_PASS
    scene = mi.load_dict(d)
    timed = render_evaluated if jit else render
    timed(mi, scene, 1, seed=0)  # warm-up (first queries, caches)
    rows = []
    for k, spp in enumerate(spp_list):
        first = timed(mi, scene, spp, seed=seed0 + 50 + k)[1] if jit else None
        img, seconds = timed(mi, scene, spp, seed=seed0 + k)
        rows.append(point(spp, seconds, img, ref, first))
    return rows


def point(spp: int, seconds: float, img: np.ndarray, ref: dict,
          first: float | None = None) -> dict:
    """A point of a curve. `first`: in a JIT variant, the time of the first render at this spp
    in the process (Dr.Jit compiles the kernels it has not seen: their code depends on the spp
    for some samplers); the point's own time is that of a second render, with compiled
    kernels."""
    row = {"spp": spp, "seconds": seconds, **errors(img, ref)}
    if first is not None:
        row["first_seconds"] = first
    print(f"    spp {spp:5d}: {seconds:8.2f} s  rel RMSE {row['rel_rmse']:.4f}  "
          f"mean CIEDE2000 {row['mean_de2000']:.3f}"
          + (f"  (first render {first:.2f} s)" if first is not None else ""))
    return row


def analytic_curve(module, name, sampler: str, spp_list, seed0, ref, fr: dict | None = None,
                   keep_image: bool = False) -> tuple[list[dict], list[str]]:
    """Error and time of ``mitsuba_birefringent.render_analytic`` on scene `name` with sampler
    `sampler`, at each of `spp_list` (frame `fr`, default its benchmark frame; with `keep_image`
    each row holds its ``"image"``); and the warnings it gave. The time is the whole call: its
    three passes, each loading the scene in llvm_ad_mono_polarized and rendering it; at each spp
    the second of two calls (`point`: the first compiles Dr.Jit's kernels)."""
    import mitsuba_birefringent

    set_variant("scalar_spectral_polarized")  # the dict is the spectral scene's
    d = scene_dict(module, name, 1, fr, filter_bandwidth=0.0)
    d["sensor"]["sampler"]["type"] = sampler
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mitsuba_birefringent.render_analytic(d, spp=1, seed=0)  # the warnings it gives
    rows = []
    for k, spp in enumerate(spp_list):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            times = []
            for seed in (seed0 + 50 + k, seed0 + k):  # the first compiles, the second is timed
                start = time.perf_counter()
                out = mitsuba_birefringent.render_analytic(d, spp=spp, seed=seed)
                times.append(time.perf_counter() - start)
        rgb = np.asarray(out["rgb"], dtype=np.float64)
        rows.append(point(spp, times[1], rgb, ref, times[0]))
        if keep_image:
            rows[-1]["image"] = rgb
    said = sorted({str(w.message) for w in caught})
    return rows, said


def channel_render(curves: dict) -> dict:
    """The channel render's curves against exact sampling, at equal mean CIEDE2000: per method
    and each spp of CHANNEL_RATIO_SPP, the time each exact curve (``exact``: the spectral
    variant; ``exact_llvm``: llvm_ad_spectral_polarized, evaluated) needs to reach the channel
    render's error (`time_at_error`: extrapolated along the curve's last measured segment
    where it does not reach it, and flagged), and that time over the channel render's; and the
    samples per pixel that curve needs for that error (the same interpolation in log spp): the
    ratio is the channel render's saving in samples times the ratio of the costs per sample."""
    out = {}
    for method, (sampler, _) in CHANNEL_METHODS.items():
        rows = {r["spp"]: r for r in curves[method]}
        entries = []
        for spp in CHANNEL_RATIO_SPP:
            r = rows[spp]
            entry = {"spp": spp, "sampler": sampler, "mean_de2000": r["mean_de2000"],
                     "seconds": r["seconds"]}
            for exact in ("exact", "exact_llvm"):
                t, extrapolated = time_at_error(curves[exact], "mean_de2000", r["mean_de2000"])
                n, _ = time_at_error([dict(x, seconds=x["spp"]) for x in curves[exact]],
                                     "mean_de2000", r["mean_de2000"])
                entry[exact] = {"seconds_at_error": t, "ratio": t / r["seconds"],
                                "spp_at_error": n, "extrapolated": extrapolated}
            entries.append(entry)
            print(f"  {method} at {spp} spp: mean CIEDE2000 {r['mean_de2000']:.3f} in "
                  f"{r['seconds']:.2f} s; " + "; ".join(
                      f"{e} needs {entry[e]['seconds_at_error']:.2f} s (ratio "
                      f"{entry[e]['ratio']:.3g}{', extrapolated' if entry[e]['extrapolated'] else ''})"
                      for e in ("exact", "exact_llvm")))
        out[method] = entries
    return out


def time_at_error(exact: list[dict], metric: str, target: float) -> tuple[float, bool]:
    """Time curve (a) needs to reach `target` (log-log interpolation; see the module doc)."""
    pts = sorted((r["seconds"], r[metric]) for r in exact)
    lt = [math.log(t) for t, _ in pts]
    le = [math.log(max(e, 1e-12)) for _, e in pts]
    x = math.log(max(target, 1e-12))
    inside = min(le) <= x <= max(le)
    best = None
    for i in range(len(pts) - 1):
        lo, hi = sorted((le[i], le[i + 1]))
        if lo <= x <= hi and le[i] != le[i + 1]:
            best = i
            break
    if best is None:  # extrapolate along the first or last segment
        best = len(pts) - 2 if x < le[-1] else 0
    i = best
    if le[i + 1] == le[i]:
        return math.exp(lt[i]), not inside
    s = (lt[i + 1] - lt[i]) / (le[i + 1] - le[i])
    return math.exp(lt[i] + s * (x - le[i])), not inside


def equal_error(exact, method_rows, metric) -> list[dict]:
    out = []
    for r in method_rows:
        t_a, extrapolated = time_at_error(exact, metric, r[metric])
        out.append({"spp": r["spp"], "error": r[metric], "seconds": r["seconds"],
                    "exact_seconds_at_error": t_a, "ratio": t_a / r["seconds"],
                    "extrapolated": extrapolated})
    return out


def headline(ratios: list[dict]) -> dict:
    inside = [r for r in ratios if not r["extrapolated"]]
    pick = max(inside or ratios, key=lambda r: r["spp"])
    return pick


def plot(name: str, result: dict, path: pathlib.Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), dpi=110)
    styles = {"exact": ("C0", "o", "(a) exact per wavelength (filter 0)"),
              "exact_llvm": ("C2", "D", "(a) exact, llvm_ad_spectral_polarized (evaluated)"),
              "filter": ("C1", "s", "(b) band filter 4 nm"),
              "rgb": ("C3", "*", "(c) analytic RGB (scalar_rgb)"),
              "analytic": ("C4", "^", "(d) render_analytic, independent (whole call)"),
              "analytic_multijitter": ("C5", "v", "(d) render_analytic, multijitter (whole call)")}
    for ax, metric, label in ((axes[0], "mean_de2000", "mean CIEDE2000"),
                              (axes[1], "rel_rmse", "relative RMSE (linear RGB)")):
        for method, rows in result["curves"].items():
            c, m, lab_ = styles[method]
            ax.plot([r["seconds"] for r in rows], [max(r[metric], 1e-6) for r in rows],
                    color=c, marker=m, label=lab_)
            for r in rows:
                ax.annotate(str(r["spp"]), (r["seconds"], max(r[metric], 1e-6)), fontsize=6,
                            textcoords="offset points", xytext=(3, 3), color=c)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("render time (s, wall, all cores)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", lw=0.3)
    axes[0].legend(fontsize=7)
    head = result.get("headline")
    txt = (f"; {head['method']} at equal CIEDE2000: {head['ratio']:.3g}x less time"
           + (" (extrapolated)" if head["extrapolated"] else "")) if head else ""
    channel = result.get("channel_render")
    if channel:
        e = next(x for x in channel["analytic"] if x["spp"] == max(CHANNEL_RATIO_SPP))
        txt += (f"\nrender_analytic at {e['spp']} spp: exact sampling needs "
                f"{e['exact']['ratio']:.3g}x its time (llvm: {e['exact_llvm']['ratio']:.3g}x)"
                + (" (extrapolated)" if e["exact"]["extrapolated"] or e["exact_llvm"]["extrapolated"]
                   else ""))
    x, y, w, h = result["frame"]["crop"]
    full = result["frame"]["size"]
    where = (f"{w}x{h} px" if [w, h] == full else
             f"{w}x{h} px crop at ({x}, {y}) of {full[0]}x{full[1]}")
    fig.suptitle(f"{name}: error vs time, {where}, "
                 f"{result['spectral_variant']}{txt}", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def error_vs_time(name: str, module, out: pathlib.Path) -> dict:
    f = frame(name)
    spp, reference_spp = budget(name)
    spectral = next(v for v in module.VARIANTS if "spectral" in v)
    print(f"{name}: {f['crop'][2]}x{f['crop'][3]} px (crop of {f['size'][0]}x{f['size'][1]}), "
          f"spectral variant {spectral}")
    ref = reference(name, module, spectral, out)
    mi = set_variant(spectral)
    curves = {}
    print("  (a) exact")
    curves["exact"] = curve_with(mi, module, name, spp["exact"], 100, ref, filter_bandwidth=0.0)
    print("  (b) filter 4 nm")
    curves["filter"] = curve_with(mi, module, name, spp["filter"], 200, ref, filter_bandwidth=4.0)
    if "scalar_rgb" in module.VARIANTS:
        mi = set_variant("scalar_rgb")
        print("  (c) scalar_rgb")
        curves["rgb"] = curve_with(mi, module, name, spp["rgb"], 300, ref)
    said = {}
    if name in CHANNEL_SCENES:
        mi = set_variant(JIT_VARIANT)
        print(f"  (a) exact, {JIT_VARIANT} (evaluated mode)")
        curves["exact_llvm"] = curve_with(mi, module, name, spp["exact_llvm"], 400, ref,
                                          jit=True, filter_bandwidth=0.0)
        for k, (method, (sampler, spp_list)) in enumerate(CHANNEL_METHODS.items()):
            print(f"  (d) render_analytic, {sampler} sampler")
            curves[method], said[method] = analytic_curve(module, name, sampler, spp_list,
                                                          500 + 100 * k, ref)
    ratios = {m: {metric: equal_error(curves["exact"], curves[m], metric)
                  for metric in ("mean_de2000", "rel_rmse")}
              for m in curves if m != "exact"}
    method = "rgb" if "rgb" in curves else "filter"
    h = dict(headline(ratios[method]["mean_de2000"]), method=method, metric="mean_de2000")
    print(f"  reference's own error: mean CIEDE2000 {ref['noise']['mean_de2000']:.3f} "
          f"(its halves differ by {ref['noise']['mean_de2000_halves']:.3f}), "
          f"rel RMSE {ref['noise']['rel_rmse']:.4f}")
    result = {"size": f["crop"][2:], "frame": f, "spectral_variant": spectral,
              "reference": {"spp": reference_spp, "passes": REFERENCE_PASSES,
                            "seconds": ref["seconds"], "cache": ref["cache"],
                            "noise": ref["noise"]},
              "curves": curves, "equal_error": ratios, "headline": h}
    if name in CHANNEL_SCENES:
        result["channel_render"] = dict(channel_render(curves), warnings=said)
    print(f"  headline: {method} reaches mean CIEDE2000 {h['error']:.3f} in {h['seconds']:.2f} s; "
          f"(a) needs {h['exact_seconds_at_error']:.2f} s: ratio {h['ratio']:.3g}"
          + (" (extrapolated)" if h["extrapolated"] else ""))
    plot(name, result, out / f"error_vs_time-{name}.png")
    return result


def channel_summary(result: dict) -> dict:
    """What results.json keeps of a scene's channel-render study: every point of the channel
    render's and exact sampling's curves (spp, seconds, errors), the ratios at equal error, the
    reference and its own error."""
    keep = ("exact", "exact_llvm", *CHANNEL_METHODS)
    return {"frame": result["frame"], "reference": result["reference"],
            "curves": {m: result["curves"][m] for m in keep},
            "at_equal_error": {m: result["channel_render"][m] for m in CHANNEL_METHODS},
            "warnings": result["channel_render"]["warnings"]}


def room(mi, objects: dict) -> dict:
    """A closed diffuse room with a ceiling light, and `objects`."""
    T = mi.ScalarTransform4f
    wall = lambda rgb: {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8},
        "sensor": {"type": "perspective", "fov": 50,
                   "to_world": T().look_at(origin=[0, -3.4, 1.0], target=[0, 0, 0.9], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": OVERHEAD_SIZE, "height": OVERHEAD_SIZE,
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": OVERHEAD_SPP}},
        "floor": {"type": "rectangle", "to_world": T().scale(2), "bsdf": wall([0.7, 0.7, 0.7])},
        "ceiling": {"type": "rectangle", "to_world": T().translate([0, 0, 2]).rotate([1, 0, 0], 180).scale(2),
                    "bsdf": wall([0.7, 0.7, 0.7])},
        "back": {"type": "rectangle", "to_world": T().translate([0, 2, 1]).rotate([1, 0, 0], 90).scale([2, 1, 1]),
                 "bsdf": wall([0.6, 0.6, 0.6])},
        "left": {"type": "rectangle", "to_world": T().translate([-2, 0, 1]).rotate([0, 1, 0], 90).scale([1, 2, 1]),
                 "bsdf": wall([0.7, 0.2, 0.2])},
        "right": {"type": "rectangle", "to_world": T().translate([2, 0, 1]).rotate([0, 1, 0], -90).scale([1, 2, 1]),
                  "bsdf": wall([0.2, 0.6, 0.2])},
        "lamp": {"type": "rectangle", "to_world": T().translate([0, 0, 1.99]).rotate([1, 0, 0], 180).scale(0.5),
                 "emitter": {"type": "area", "radiance": {"type": "d65", "scale": 8.0}}},
    }
    d.update(objects)
    return d


#: Where the three panes of `panes` stand: centre (x, y) and rotation about z (degrees).
PANES = ((-0.9, 0.3, 20), (0.0, -0.4, -10), (0.9, 0.5, 35))


def pane_frame(mi, i: int):
    """World transform of pane `i`: a rectangle 1 x 1.4 standing upright, its normal (local z)
    towards the camera's side, its local x axis (the shading frame's dp/du) horizontal."""
    T = mi.ScalarTransform4f
    x, y, a = PANES[i]
    return T().translate([x, y, 0.8]).rotate([0, 0, 1], a).rotate([1, 0, 0], 90).scale([0.5, 0.7, 1])


def panes(mi, bsdf: dict) -> dict:
    return {f"pane{i}": {"type": "rectangle", "bsdf": bsdf, "to_world": pane_frame(mi, i)}
            for i in range(len(PANES))}


def between_polarizers(mi, bsdf: dict) -> dict:
    """The three panes of `panes` with `bsdf`, each between crossed linear polarisers: Mitsuba's
    `polarizer` on rectangles 3 cm in front of and behind the pane, in its frame moved along
    its normal (so the same local x axis). They transmit at -45 and +45 degrees to that axis,
    along which a plate's optic axis lies by default ([1, 0, 0]): the arrangement of strongest
    interference colours. In unpolarised variants a `polarizer` is a grey filter of 0.5."""
    T = mi.ScalarTransform4f
    d = panes(mi, bsdf)
    for i in range(len(PANES)):
        # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
        for side, offset, theta in (("front", 0.03, 45.0), ("back", -0.03, -45.0)):
            d[f"{side}_polarizer{i}"] = {"type": "rectangle", "bsdf": {"type": "polarizer", "theta": theta},
                                         "to_world": pane_frame(mi, i) @ T().translate([0, 0, offset])}
    return d


def solids(mi, bsdf: dict) -> dict:
    T = mi.ScalarTransform4f
    return {"sphere": {"type": "sphere", "center": [-0.6, 0.0, 0.6], "radius": 0.55, "bsdf": bsdf},
            "cube": {"type": "cube", "bsdf": bsdf,
                     "to_world": T().translate([0.7, 0.3, 0.45]).rotate([0, 0, 1], 30).scale(0.42)}}


def bouncing_sphere(mi, bsdf: dict) -> dict:
    """One sphere (radius 0.8) resting on the floor in front of the camera, about half the frame:
    most camera paths enter it, and light bounces inside it (``path`` with max_depth 8), so the
    surface is queried several times per path (the crystal's cost at its most visible)."""
    return {"sphere": {"type": "sphere", "center": [0.0, -1.2, 0.8], "radius": 0.8, "bsdf": bsdf}}


def plate(**params) -> dict:
    return {"type": "thinbirefringent", "ext_ior": 1.0, **params}


def crystal(**params) -> dict:
    return {"type": "birefringent", "ext_ior": 1.0, **params}


def mitsuba_bsdf(plugin: str, int_ior: float) -> dict:
    return {"type": plugin, "int_ior": int_ior, "ext_ior": 1.0}


#: Thicknesses (um) of the quartz plates between crossed polarisers.
QUARTZ_UM = (0, 5, 20, 50, 100, 150)
#: The index Mitsuba's plugins get in place of quartz (its ordinary index, 1.544 at 589 nm) and
#: of calcite (1.658); a user picks these for the isotropic stand-in.
QUARTZ_N_O, CALCITE_N_O = 1.544, 1.658

#: Every room configuration of the overhead benchmark: name -> the room's objects (given `mi`).
#: "aniso_1e-9": eta_e = 1.5 + 1e-9, optically the same glass but anisotropic to the core.
CONFIGS = {
    "glass_panes/thindielectric": lambda mi: panes(mi, mitsuba_bsdf("thindielectric", 1.5)),
    "glass_panes/thinbirefringent": lambda mi: panes(mi, plate(eta_o=1.5, eta_e=1.5, thickness=1000.0)),
    "glass_panes/thinbirefringent_aniso_1e-9": lambda mi: panes(
        mi, plate(eta_o=1.5, eta_e=1.5 + 1e-9, thickness=1000.0)),
    "glass_solids/dielectric": lambda mi: solids(mi, mitsuba_bsdf("dielectric", 1.5)),
    "glass_solids/birefringent": lambda mi: solids(mi, crystal(eta_o=1.5, eta_e=1.5)),
    "glass_solids/birefringent_aniso_1e-9": lambda mi: solids(mi, crystal(eta_o=1.5, eta_e=1.5 + 1e-9)),
    "quartz_plates/thindielectric": lambda mi: between_polarizers(mi, mitsuba_bsdf("thindielectric", QUARTZ_N_O)),
    **{f"quartz_plates/thinbirefringent_{d}um": (lambda d: lambda mi: between_polarizers(
        mi, plate(material="quartz", thickness=float(d))))(d) for d in QUARTZ_UM},
    "photoelastic_plates/thindielectric": lambda mi: between_polarizers(mi, mitsuba_bsdf("thindielectric", 1.5)),
    "photoelastic_plates/thinbirefringent_3mm": lambda mi: between_polarizers(
        mi, plate(eta_o=1.5, eta_e=1.5, birefringence=2e-4, thickness=3000.0)),
    "calcite_solids/dielectric": lambda mi: solids(mi, mitsuba_bsdf("dielectric", CALCITE_N_O)),
    "calcite_solids/birefringent": lambda mi: solids(
        mi, crystal(material="calcite", optic_axis=[1.0, 1.0, 1.0], optic_axis_space="world")),
    "bouncing_glass/dielectric": lambda mi: bouncing_sphere(mi, mitsuba_bsdf("dielectric", 1.5)),
    "bouncing_glass/birefringent": lambda mi: bouncing_sphere(mi, crystal(eta_o=1.5, eta_e=1.5)),
    "bouncing_calcite/dielectric": lambda mi: bouncing_sphere(mi, mitsuba_bsdf("dielectric", CALCITE_N_O)),
    "bouncing_calcite/birefringent": lambda mi: bouncing_sphere(
        mi, crystal(material="calcite", optic_axis=[1.0, 1.0, 1.0], optic_axis_space="world")),
    "cellophane/birefringentstack": lambda mi: cellophane_scene("birefringentstack"),
    "cellophane/thindielectric": lambda mi: cellophane_scene("thindielectric"),
}


#: The configurations (their scene part before the "/") that are whole scenes, not rooms.
WHOLE_SCENES = ("cellophane",)


def cellophane_scene(plugin: str) -> dict:
    """Not a room: the gallery's cellophane scene (scenes/cellophane.py) at the overhead's size
    (3:2), spp and independent sampler; with "birefringentstack" as it is (one rectangle, a
    stack of 4 layers whose thicknesses and axes are textures), with "thindielectric" each strip
    a rectangle of its own with `thindielectric` of the film's ordinary index (what one builds
    without birefringent layers: paths meet 0 to 4 films)."""
    if str(SCENES_DIR) not in sys.path:
        sys.path.insert(0, str(SCENES_DIR))
    import cellophane

    d = cellophane.scene(width=OVERHEAD_SIZE, height=round(OVERHEAD_SIZE * 2 / 3), spp=OVERHEAD_SPP)
    if plugin == "thindielectric":
        del d["cellophane"]
        d.update(cellophane.strips_as_shapes({"type": "thindielectric", "int_ior": cellophane.INDEX}))
    return d


class Pair(typing.NamedTuple):
    """Two configurations (keys of CONFIGS) timed against each other, interleaved: the figure is
    the median time of `ours` over that of `theirs`, in each of `variants`."""
    kind: str  # of `ours`: "isotropic" (eta_o == eta_e: the core's fast path) or "anisotropic"
    ours: str
    theirs: str
    variants: tuple[str, ...]
    what: str  # the scene, in words (the README's row)

    @property
    def plugin(self) -> str:
        """Our plugin in `ours` (configuration names are "<scene>/<plugin>[_<detail>]")."""
        return self.ours.split("/")[1].split("_")[0]


#: Plates and isotropic solids: in the rgb and spectral polarized variants, scalar and llvm.
BOTH = ("scalar_rgb", "llvm_ad_rgb", "scalar_spectral_polarized", "llvm_ad_spectral_polarized")
#: A bulk birefringent crystal needs a polarised variant (plugin/README.md).
POLARIZED = ("scalar_spectral_polarized", "llvm_ad_spectral_polarized")
#: The quartz plates also as one pass of a channel render.
PLATES = (*BOTH, *CHANNEL_PASS)
#: The rows of the overhead table: ours against the Mitsuba plugin a user would use instead, in
#: the same room, with the same spp and variant.
OVERHEAD_PAIRS = {
    "isotropic/glass_panes": Pair(
        "isotropic", "glass_panes/thinbirefringent", "glass_panes/thindielectric", BOTH,
        "3 glass panes (eta_o = eta_e = 1.5, 1000 um) vs `thindielectric` 1.5"),
    "isotropic/glass_solids": Pair(
        "isotropic", "glass_solids/birefringent", "glass_solids/dielectric", BOTH,
        "glass sphere and cube (eta_o = eta_e = 1.5) vs `dielectric` 1.5"),
    **{f"anisotropic/quartz_plates_{d}um": Pair(
        "anisotropic", f"quartz_plates/thinbirefringent_{d}um", "quartz_plates/thindielectric", PLATES,
        f"3 quartz plates of {d} um between crossed polarisers vs `thindielectric` {QUARTZ_N_O}")
       for d in QUARTZ_UM},
    "anisotropic/photoelastic_plates_3mm": Pair(
        "anisotropic", "photoelastic_plates/thinbirefringent_3mm", "photoelastic_plates/thindielectric", BOTH,
        "3 photoelastic plates (eta_o = 1.5, birefringence 2e-4, 3 mm) between crossed polarisers "
        "vs `thindielectric` 1.5"),
    "anisotropic/calcite_solids": Pair(
        "anisotropic", "calcite_solids/birefringent", "calcite_solids/dielectric", POLARIZED,
        f"calcite sphere and cube (optic axis [1, 1, 1] in world space) vs `dielectric` {CALCITE_N_O}"),
    "isotropic/bouncing_glass_sphere": Pair(
        "isotropic", "bouncing_glass/birefringent", "bouncing_glass/dielectric", BOTH,
        "a glass sphere on the floor filling half the frame, light bouncing inside it "
        "(eta_o = eta_e = 1.5) vs `dielectric` 1.5"),
    "anisotropic/cellophane": Pair(
        "anisotropic", "cellophane/birefringentstack", "cellophane/thindielectric", PLATES,
        "the cellophane scene (scenes/cellophane.py: 8 strips between crossed polarisers, one "
        "`birefringentstack` of 4 textured layers) vs the same strips as `thindielectric` "
        "rectangles (int_ior 1.5)"),
    "anisotropic/bouncing_calcite_sphere": Pair(
        "anisotropic", "bouncing_calcite/birefringent", "bouncing_calcite/dielectric", POLARIZED,
        "a calcite sphere on the floor filling half the frame, light bouncing inside it (optic axis "
        f"[1, 1, 1] in world space) vs `dielectric` {CALCITE_N_O}"),
}
#: The isotropic fast path at scene level: ours with eta_e = 1.5 + 1e-9 against ours with 1.5.
FAST_PATH_PAIRS = {
    "isotropic_fast_path_thin": Pair(
        "anisotropic", "glass_panes/thinbirefringent_aniso_1e-9", "glass_panes/thinbirefringent",
        ("scalar_spectral_polarized",), "3 glass panes, eta_e = 1.5 + 1e-9 vs 1.5"),
    "isotropic_fast_path_bulk": Pair(
        "anisotropic", "glass_solids/birefringent_aniso_1e-9", "glass_solids/birefringent",
        ("scalar_spectral_polarized",), "glass sphere and cube, eta_e = 1.5 + 1e-9 vs 1.5"),
}


#: The goals of the overhead table (issue 20), in one place: per kind of row, what it covers and
#: the largest ratio ours / Mitsuba's it allows. results.json gives each row's goal per variant
#: (`overhead_goal`), and docs/benchmarks.md prints them from there.
OVERHEAD_GOALS = {
    "isotropic": ("isotropic parameters (eta_o = eta_e), every variant", 1.3),
    "plate_rgb": ("birefringent plates in scalar_rgb and llvm_ad_rgb", 4.0),
    "plate_spectral": ("birefringent plates in the spectral polarized variants", 2.0),
    "plate_channel_pass": ("birefringent plates, one pass of a channel render", 3.0),
    "crystal": ("birefringent bulk crystals", 2.0),
}


def overhead_goal(pair: Pair, variant: str) -> str:
    """The key of OVERHEAD_GOALS that `pair` is judged by in `variant`."""
    if pair.kind == "isotropic":
        return "isotropic"
    if pair.plugin == "birefringent":
        return "crystal"
    if variant in CHANNEL_PASS:
        return "plate_channel_pass"
    return "plate_spectral" if "spectral" in variant else "plate_rgb"


def overhead_room(mi, name: str, variant: str) -> dict:
    """The room of configuration `name` for `variant`: in a variant of CHANNEL_PASS, the pass of
    its channel as ``render_analytic`` renders it (``analytic.channel_passes``)."""
    objects = CONFIGS[name](mi)
    d = objects if objects.get("type") == "scene" else room(mi, objects)
    if variant not in CHANNEL_PASS:
        return d
    from mitsuba_birefringent.analytic import CHANNELS, channel_passes

    weights, channel = CHANNEL_PASS[variant].split(":")
    return channel_passes(d, weights)[CHANNELS[weights].index(channel)]


def evaluated(variant: str) -> bool:
    """Whether the timed rounds of `variant` render in Dr.Jit's evaluated mode: in the llvm
    variants where our plates query the host (colour channels: llvm_ad_rgb, the mono passes),
    ours because they need it, and Mitsuba's plugins too, since while such a scene of ours
    exists in the process a symbolic render of any scene fails (plugin/mitsuba_birefringent/jit.py);
    Mitsuba's default, symbolic mode is timed after ours are deleted (`symbolic_factor`). In the
    spectral llvm variants every plugin runs inside Mitsuba's kernels: all in default mode."""
    return variant.startswith("llvm_") and "_spectral" not in variant


def render_in_mode(mi, scene, spp: int, seed: int, evaluated_mode: bool) -> float:
    """Wall time of `render` (the image read back, which waits for Dr.Jit's kernels), in
    evaluated mode if `evaluated_mode`, else in the flags' defaults (symbolic)."""
    import mitsuba_birefringent

    if not evaluated_mode:
        return render(mi, scene, spp, seed)[1]
    with mitsuba_birefringent.evaluated_mode():
        return render(mi, scene, spp, seed)[1]


class KernelCount:
    """Dr.Jit kernels launched, and compiled (not found in its cache) with their compile time in
    ms, while in the block (a JIT variant; none in a scalar one)."""

    def __enter__(self):
        import drjit as dr

        self.dr = dr
        self.was = dr.flag(dr.JitFlag.KernelHistory)
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        dr.kernel_history()  # clears it
        return self

    def __exit__(self, *exc):
        dr = self.dr
        history = [k for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT]
        compiled = [k for k in history if not k.get("cache_hit")]
        self.launched, self.compiled = len(history), len(compiled)
        self.compile_ms = sum(k.get("codegen_time", 0.0) + k.get("backend_time", 0.0) for k in compiled)
        dr.set_flag(dr.JitFlag.KernelHistory, self.was)


def compiled_none(mi, scene, seed: int, evaluated_mode: bool, log: dict) -> float:
    """The time of a render of `scene` (`render_in_mode`) during which Dr.Jit compiled no kernel:
    a render that compiled one (in evaluated mode a kernel's code can depend on how many lanes
    reach a call, so a new seed may need a new kernel) is repeated at once with the same seed,
    whose kernels are then cached, up to twice. `log` counts the kernels of the kept renders and
    of the repeated ones."""
    for _ in range(3):
        with KernelCount() as k:
            seconds = render_in_mode(mi, scene, OVERHEAD_SPP, seed, evaluated_mode)
        if not k.compiled:
            break
        log["repeated_renders"] += 1
        log["repeated_compile_ms"] += k.compile_ms
    log["launched"] += k.launched
    log["compiled"] += k.compiled  # in the kept renders: 0 unless three attempts compiled
    return seconds


def timed_rounds(mi, scenes: dict, modes: dict, repeats: int) -> tuple[dict, dict]:
    """Each of `scenes` rendered once at OVERHEAD_SPP in its mode (`modes`: evaluated or not;
    in an llvm variant this compiles Dr.Jit's kernels), then `repeats` rounds rendering each in
    turn with fresh seeds (`compiled_none`): the times per scene, and the kernels of the rounds."""
    for name, scene in scenes.items():
        render_in_mode(mi, scene, OVERHEAD_SPP, 0, modes[name])
    times = {name: [] for name in scenes}
    log = {"launched": 0, "compiled": 0, "repeated_renders": 0, "repeated_compile_ms": 0.0}
    for rep in range(repeats):
        for name, scene in scenes.items():
            times[name].append(compiled_none(mi, scene, 10 * rep + 1, modes[name], log))
    return times, log


def symbolic_factor(mi, scenes: dict, repeats: int) -> dict:
    """Mitsuba's `scenes` (no plugin of ours left in the process) rendered in evaluated and in
    symbolic mode, interleaved: per scene the two lists of times, their medians' ratio
    evaluated / symbolic, and the kernels of the rounds."""
    both = {(name, mode): scene for name, scene in scenes.items() for mode in ("evaluated", "symbolic")}
    times, kernels = timed_rounds(mi, both, {k: k[1] == "evaluated" for k in both}, repeats)
    out = {name: {mode: times[(name, mode)] for mode in ("evaluated", "symbolic")} for name in scenes}
    for t in out.values():
        t["factor"] = statistics.median(t["evaluated"]) / statistics.median(t["symbolic"])
    return {"scenes": out, "kernels_while_timed": kernels}


def overhead(repeats: int, only: list[str] | None = None) -> dict:
    """Every pair of OVERHEAD_PAIRS and FAST_PATH_PAIRS in each of OVERHEAD_VARIANTS: every
    configuration a variant needs loaded and rendered once at the timed spp, then `repeats`
    interleaved rounds (`timed_rounds`); ratios ours / Mitsuba's of the median times. In the
    llvm variants every configuration renders in evaluated mode (`evaluated`); then ours are
    deleted and Mitsuba's timed in evaluated against symbolic mode (`symbolic_factor`): the
    ratio against Mitsuba's default mode is the product of the two interleaved ratios."""
    import gc

    pairs = {**OVERHEAD_PAIRS, **FAST_PATH_PAIRS}
    if only is not None:
        pairs = {k: pairs[k] for k in only}
    out = {}
    for variant in OVERHEAD_VARIANTS:
        here = {k: p for k, p in pairs.items() if variant in p.variants}
        if not here:
            continue
        mi = set_variant(variant)
        names = list(dict.fromkeys(n for p in here.values() for n in (p.theirs, p.ours)))
        scenes = {name: mi.load_dict(overhead_room(mi, name, variant)) for name in names}
        times, kernels = timed_rounds(mi, scenes, dict.fromkeys(names, evaluated(variant)), repeats)
        med = {name: statistics.median(t) for name, t in times.items()}
        ratios = {k: med[p.ours] / med[p.theirs] for k, p in here.items()}
        result = {"median_seconds": med, "seconds": times, "ratios": ratios,
                  "evaluated_mode": evaluated(variant), "kernels_while_timed": kernels}
        print(f"overhead, {variant} (median s; kernels while timed: {kernels}):")
        for name, t in med.items():
            print(f"  {name:48s} {t:8.3f}")
        if result["evaluated_mode"]:
            theirs = {p.theirs for p in here.values()}
            for name in names:
                if name not in theirs:
                    del scenes[name]  # no plugin of ours may exist during a symbolic render
            gc.collect()
            sym = symbolic_factor(mi, scenes, repeats)
            result["mitsuba_evaluated_over_symbolic"] = sym
            result["ratios_vs_evaluated"] = ratios
            ratios = {k: r * sym["scenes"][here[k].theirs]["factor"] for k, r in ratios.items()}
            result["ratios"] = ratios
            print(f"  Mitsuba's, evaluated / symbolic mode (kernels while timed: "
                  f"{sym['kernels_while_timed']}):")
            for name, t in sym["scenes"].items():
                print(f"  {name:48s} {t['factor']:8.2f}")
        print("  ratios" + (" (against Mitsuba's symbolic mode)" if result["evaluated_mode"] else "") + ":")
        for k, r in ratios.items():
            print(f"  {k:48s} {r:8.2f}")
        out[variant] = result
        del scenes
        gc.collect()
    return out


def now() -> str:
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")


def overhead_rows(over: dict, keys) -> dict:
    """Per row of OVERHEAD_PAIRS in `keys`: its kind, scene and ratio ours / Mitsuba's per
    variant (results.json's "overhead" "rows")."""
    return {k: {"kind": p.kind, "plugin": p.plugin, "what": p.what, "ours": p.ours, "theirs": p.theirs,
                "ratio": {v: over[v]["ratios"][k] for v in p.variants},
                "goal": {v: OVERHEAD_GOALS[overhead_goal(p, v)][1] for v in p.variants},
                "ratio_vs_evaluated": {v: over[v]["ratios_vs_evaluated"][k] for v in p.variants
                                       if "ratios_vs_evaluated" in over[v]}}
            for k, p in OVERHEAD_PAIRS.items() if k in keys}


def overhead_summary(over: dict, repeats: int, measured: dict) -> dict:
    """results.json's "overhead": how it was measured, and every row (`overhead_rows`)."""
    rows = overhead_rows(over, OVERHEAD_PAIRS)
    settings = {"size": OVERHEAD_SIZE, "spp": OVERHEAD_SPP, "repeats": repeats,
                "integrator": "path, max_depth 8", "variants": list(OVERHEAD_VARIANTS),
                "channel_pass": CHANNEL_PASS,
                "goals": {g: {"what": what, "at_most": bound} for g, (what, bound) in OVERHEAD_GOALS.items()},
                "evaluated_mode": [v for v in OVERHEAD_VARIANTS if over[v]["evaluated_mode"]],
                "kernels_while_timed": {v: over[v]["kernels_while_timed"] for v in OVERHEAD_VARIANTS},
                "mitsuba_evaluated_over_symbolic": {
                    v: {n: t["factor"] for n, t in over[v]["mitsuba_evaluated_over_symbolic"]["scenes"].items()}
                    for v in OVERHEAD_VARIANTS if over[v]["evaluated_mode"]}}
    return {"measured": measured, "settings": settings, "rows": rows}


def scene_shortcuts(over: dict) -> dict:
    """The scene-level ratios of FAST_PATH_PAIRS, keyed as results.json's "shortcut_cases"."""
    polarized = over["scalar_spectral_polarized"]["ratios"]
    return {"isotropic_fast_path/scene_thin": polarized["isotropic_fast_path_thin"],
            "isotropic_fast_path/scene_bulk": polarized["isotropic_fast_path_bulk"]}


def shortcut_summary(core_shortcuts: dict | None, over: dict) -> tuple[dict, dict]:
    """results.json's "shortcuts" (one headline case each) and "shortcut_cases" (every case):
    the core's, from examples/bench_shortcuts.rs, and the scene-level ones of `over`."""
    scene = scene_shortcuts(over)
    shortcuts = dict(core_shortcuts["headline"]) if core_shortcuts else {}
    shortcuts["isotropic_fast_path_scene_thin"] = scene["isotropic_fast_path/scene_thin"]
    shortcuts["isotropic_fast_path_scene_bulk"] = scene["isotropic_fast_path/scene_bulk"]
    cases = {k: c["ratio"] for k, c in core_shortcuts["cases"].items()} if core_shortcuts else {}
    return shortcuts, {**cases, **scene}


def merge_overhead(results_path: pathlib.Path, detail_path: pathlib.Path, over: dict,
                   summary: dict) -> tuple[dict, dict]:
    """`--only overhead`: the existing results and detail with the overhead figures (and the
    scene-level shortcut ratios they contain) replaced; everything else is kept as measured."""
    if not results_path.exists():
        raise SystemExit(f"{results_path}: no results to merge into; run without --only first")
    results = json.loads(results_path.read_text())
    results["overhead"] = summary
    shortcuts, cases = shortcut_summary(None, over)  # the scene-level ones only
    results["shortcuts"] = {**results.get("shortcuts", {}), **shortcuts}
    results["shortcut_cases"] = {**results.get("shortcut_cases", {}), **cases}
    detail = json.loads(detail_path.read_text()) if detail_path.exists() else {}
    detail["overhead"] = over
    return results, detail


def merge_overhead_rows(results_path: pathlib.Path, detail_path: pathlib.Path, over: dict,
                        keys: list[str], repeats: int, measured: dict) -> tuple[dict, dict]:
    """`--only overhead --pairs`: the existing results with the rows `keys` replaced (or added),
    each carrying `measured` (its own date, load and command); the table's settings must be
    those the rows were measured with."""
    if not results_path.exists():
        raise SystemExit(f"{results_path}: no results to merge into; run without --only first")
    results = json.loads(results_path.read_text())
    settings = results["overhead"]["settings"]
    if (settings["size"], settings["spp"], settings["repeats"]) != (OVERHEAD_SIZE, OVERHEAD_SPP, repeats):
        raise SystemExit("--pairs: the table was measured with other settings; measure it whole")
    rows = overhead_rows(over, keys)
    for row in rows.values():
        row["measured"] = measured
    results["overhead"]["rows"].update(rows)
    detail = json.loads(detail_path.read_text()) if detail_path.exists() else {}
    detail.setdefault("overhead_pairs", {})[",".join(keys)] = over
    return results, detail


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=ROOT / "bench" / "out")
    p.add_argument("--results", type=pathlib.Path, default=ROOT / "bench" / "results.json")
    p.add_argument("--shortcuts", type=pathlib.Path, default=None,
                   help="JSON of examples/bench_shortcuts.rs (default OUT/shortcuts.json)")
    p.add_argument("--scenes", default=None, help="comma-separated scene names (default: all)")
    p.add_argument("--only", choices=("overhead",), default=None,
                   help="measure the overhead table alone and merge it into RESULTS (and "
                        "OUT/scenes.json), keeping the other figures")
    p.add_argument("--pairs", default=None,
                   help="with --only overhead: comma-separated keys of OVERHEAD_PAIRS to measure "
                        "and merge, keeping the other rows")
    p.add_argument("--repeats", type=int, default=OVERHEAD_REPEATS)
    p.add_argument("--quick", action="store_true",
                   help="tiny budgets to check that the script runs (figures meaningless)")
    a = p.parse_args()
    if a.quick:
        global SPP, REFERENCE_SPP, REFERENCE_PASSES, OVERHEAD_SIZE, OVERHEAD_SPP, SCENE_BUDGETS
        global CHANNEL_METHODS, CHANNEL_RATIO_SPP
        SPP = {"exact": (2, 4, 8), "filter": (2, 4), "rgb": (1, 2)}
        SCENE_BUDGETS = {}
        CHANNEL_METHODS = {m: (sampler, (1, 4)) for m, (sampler, _) in CHANNEL_METHODS.items()}
        CHANNEL_RATIO_SPP = (1, 4)
        REFERENCE_SPP, REFERENCE_PASSES, OVERHEAD_SIZE, OVERHEAD_SPP = 64, 4, 16, 2
        a.repeats = 1
    a.out.mkdir(parents=True, exist_ok=True)
    warnings.filterwarnings("ignore", module="colour")
    started = time.perf_counter()
    load_before = load_average()
    import mitsuba as mi

    scenes = {}
    if a.only is None:
        modules = discover(a.scenes.split(",") if a.scenes else None)
        scenes = {name: error_vs_time(name, m, a.out) for name, m in modules.items()}
    pairs = a.pairs.split(",") if a.pairs else None
    if pairs is not None and (a.only != "overhead" or not set(pairs) <= set(OVERHEAD_PAIRS)):
        p.error(f"--pairs needs --only overhead and keys of OVERHEAD_PAIRS: {', '.join(OVERHEAD_PAIRS)}")
    overhead_started, overhead_load = time.perf_counter(), load_average()
    over = overhead(a.repeats, pairs)
    measured = {
        "date": now(), "cpu": machine()["cpu"], "logical_cores": machine()["logical_cores"],
        "load_average_start": overhead_load, "load_average_end": load_average(),
        "seconds": time.perf_counter() - overhead_started,
        "command": "bench/scenes.py" + (" --only overhead" if a.only else "")
        + (f" --pairs {a.pairs}" if a.pairs else "")}
    detail_path = a.out / "scenes.json"
    if pairs is not None:
        results, detail = merge_overhead_rows(a.results, detail_path, over, pairs, a.repeats, measured)
    elif a.only == "overhead":
        summary = overhead_summary(over, a.repeats, measured)
        results, detail = merge_overhead(a.results, detail_path, over, summary)
    else:
        shortcuts_path = a.shortcuts or a.out / "shortcuts.json"
        core_shortcuts = json.loads(shortcuts_path.read_text()) if shortcuts_path.exists() else None
        shortcuts, shortcut_cases = shortcut_summary(core_shortcuts, over)
        summary = overhead_summary(over, a.repeats, measured)
        results = {
            "date": now(),
            "machine": dict(machine(), load_average_start=load_before, load_average_end=load_average()),
            "mitsuba": mi.__version__,
            "overhead": summary,
            "analytic_speedup_at_equal_error": {n: r["headline"]["ratio"] for n, r in scenes.items()},
            "equal_error_detail": {n: r["headline"] for n, r in scenes.items()},
            "reference_noise": {n: dict(r["reference"]["noise"], spp=r["reference"]["spp"])
                                for n, r in scenes.items()},
            "channel_render": {n: channel_summary(r) for n, r in scenes.items()
                               if "channel_render" in r},
            "shortcuts": shortcuts,
            "shortcut_cases": shortcut_cases,
            "settings": {"reference_spp": REFERENCE_SPP, "spp": SPP, "scene_budgets": SCENE_BUDGETS,
                         "channel_methods": CHANNEL_METHODS, "channel_ratio_spp": CHANNEL_RATIO_SPP,
                         "jit": {"variant": JIT_VARIANT, "samples_per_pass": JIT_SAMPLES_PER_PASS},
                         "frames": {n: frame(n) for n in scenes}},
            "bench_seconds": time.perf_counter() - started,
        }
        detail = {"scenes": scenes, "overhead": over, "core_shortcuts": core_shortcuts}
    detail_path.write_text(json.dumps(detail, indent=1))
    a.results.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {a.results} and {detail_path} in {time.perf_counter() - started:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
