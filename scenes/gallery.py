"""Render every scene of this directory at gallery size and put them on one contact sheet.

    .venv/bin/python scenes/gallery.py [--out out/gallery] [--sheet scenes/gallery.png]
        [--width 320] [--spp 16] [--sampler multijitter] [--only NAME ...] [--reuse]

Scenes are the modules `render.scene_names()` finds (a `scene` function and `VARIANTS`), each
rendered in its default variant at `--width` pixels wide (the height keeps the aspect of the
scene's default width and height) with `--spp` samples per pixel and the sampler `--sampler`
(`render.SAMPLER`, multijitter: it stratifies the choice between a plate's reflection and
transmission), unless the module has a dict `GALLERY` of options for the gallery: the scene's
own options (e.g. `spp`), and `analytic` (render by colour channels, `render.render_analytic`:
no colour noise where one plate is on every path) and `sampler` (the sensor's sampler type for
that scene). Each goes to `<out>/<name>.exr` and `.png` (`render.render` or
`render.render_analytic`); the contact sheet has the images in a grid with the scene's name and
the first paragraph of its docstring under each. The examples of EXAMPLES (not scenes: e.g. an
optimisation through the renderer, a plot of rendered measurements) make their own figure with
their `gallery(out)` function. Every panel's method, samples per pixel and time go to
`<out>/gallery.json` and are printed. `--noise` renders each scene's panel a second time with
another seed (into `<out>/noise/`) and adds its noise per pixel (`noise`).
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import json
import math
import pathlib
import sys
import textwrap
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import render  # noqa: E402

#: Modules with a `gallery(out) -> png` function, shown after the scenes.
EXAMPLES = ("waveplate_spectra", "inverse_photoelastic")


def gallery_options(module, width: int, spp: int) -> dict:
    """The scene options of `module`'s panel: the gallery's size and spp, then its GALLERY dict
    (without the render settings `analytic` and `sampler`: see `render_settings`)."""
    defaults = inspect.signature(module.scene).parameters
    w0, h0 = defaults["width"].default, defaults["height"].default
    options = {"width": width, "height": max(1, round(width * h0 / w0)), "spp": spp}
    options.update({k: v for k, v in getattr(module, "GALLERY", {}).items()
                    if k not in ("analytic", "sampler")})
    return options


def render_settings(module, sampler: str) -> tuple[bool, str]:
    """(by colour channels?, the sampler) of `module`'s panel: its GALLERY dict's `analytic` and
    `sampler`, else spectral sampling with `sampler`."""
    settings = getattr(module, "GALLERY", {})
    return bool(settings.get("analytic", False)), settings.get("sampler", sampler)


def render_panel(name: str, module, out: pathlib.Path, width: int, spp: int, sampler: str,
                 seed: int = 0) -> tuple[pathlib.Path, dict]:
    """Renders scene `name`'s panel; returns its PNG and what it cost."""
    options = gallery_options(module, width, spp)
    analytic, sampler = render_settings(module, sampler)
    start = time.perf_counter()
    draw = render.render_analytic if analytic else render.render
    png = draw(name, out, sampler=sampler, seed=seed, **options)
    cost = {"method": "render_analytic (srgb-d65)" if analytic else f"{module.VARIANTS[0]}",
            "sampler": sampler, "spp": options["spp"], "size": [options["width"], options["height"]],
            "seconds": time.perf_counter() - start}
    return png, cost


def contact_sheet(entries: list[tuple[str, str, pathlib.Path]], path: pathlib.Path,
                  columns: int = 3) -> None:
    """entries: (name, caption, png). Writes a grid of the images, each labelled underneath."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    rows = math.ceil(len(entries) / columns)
    fig, axes = plt.subplots(rows, columns, figsize=(4.2 * columns, 3.9 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, (name, caption, png) in zip(axes.ravel(), entries):
        ax.imshow(mpimg.imread(str(png)))
        ax.set_anchor("N")
        ax.annotate(name, xy=(0.5, 0.0), xycoords="axes fraction", xytext=(0, -4),
                    textcoords="offset points", ha="center", va="top", fontsize=11,
                    weight="bold")
        ax.annotate("\n".join(textwrap.wrap(caption, 56)), xy=(0.5, 0.0),
                    xycoords="axes fraction", xytext=(0, -20), textcoords="offset points",
                    ha="center", va="top", fontsize=8)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path), dpi=80, facecolor="white")
    plt.close(fig)


def linear_rgb(exr: pathlib.Path):
    """The first three channels of a panel's EXR (linear RGB: render.py writes them first)."""
    import mitsuba as mi
    import numpy as np

    return np.array(mi.Bitmap(str(exr)), dtype=np.float64)[..., :3]


def noise(a, b) -> dict:
    """Noise per pixel of a render, from two renders `a`, `b` (linear RGB) that differ only in the
    seed, over the lit pixels (luminance above a fifth of the 99th percentile of their mean):
    the RMS of |Y_a - Y_b| / sqrt(2) / Y (brightness) and of the difference of the
    chromaticities r and g / sqrt(2) (colour)."""
    import numpy as np

    luminance = lambda x: x @ np.array([0.2126, 0.7152, 0.0722])  # noqa: E731
    chromaticity = lambda x: (x / np.maximum(x.sum(-1, keepdims=True), 1e-12))[..., :2]  # noqa: E731
    y = luminance(0.5 * (a + b))
    lit = y > 0.2 * np.percentile(y, 99)
    brightness = (np.abs(luminance(a) - luminance(b)) / np.sqrt(2))[lit] / y[lit]
    colour = np.abs(chromaticity(a) - chromaticity(b))[lit] / np.sqrt(2)
    return {"brightness": float(np.sqrt(np.mean(brightness**2))),
            "colour": float(np.sqrt(np.mean(colour**2)))}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/gallery"))
    p.add_argument("--sheet", type=pathlib.Path, default=HERE / "gallery.png")
    p.add_argument("--width", type=int, default=320)
    p.add_argument("--spp", type=int, default=16)
    p.add_argument("--sampler", default=render.SAMPLER,
                   help="the sensor's sampler type (default %(default)s; 'scene': the scene's own)")
    p.add_argument("--only", nargs="*", default=None, help="render only these scenes")
    p.add_argument("--reuse", action="store_true",
                   help="use the PNGs already in --out where they exist (only redraw the sheet)")
    p.add_argument("--noise", action="store_true",
                   help="render each scene's panel again with another seed and state its noise")
    a = p.parse_args()
    entries, costs, start = [], {}, time.perf_counter()
    for name in render.scene_names():
        if a.only and name not in a.only:
            continue
        module = importlib.import_module(name)
        png = a.out / f"{name}.png"
        if not (a.reuse and png.exists()):
            png, costs[name] = render_panel(name, module, a.out, a.width, a.spp, a.sampler)
        if a.noise:
            render_panel(name, module, a.out / "noise", a.width, a.spp, a.sampler, seed=1)
            costs.setdefault(name, {})["noise"] = noise(linear_rgb(a.out / f"{name}.exr"),
                                                        linear_rgb(a.out / "noise" / f"{name}.exr"))
        caption = " ".join((module.__doc__ or "").strip().split("\n\n")[0].split())
        entries.append((name, caption, png))
    for name in EXAMPLES:
        if a.only and name not in a.only:
            continue
        module = importlib.import_module(name)
        png = a.out / f"{name}.png"
        if not (a.reuse and png.exists()):
            begun = time.perf_counter()
            png = module.gallery(a.out)
            costs[name] = {"method": "gallery()", "seconds": time.perf_counter() - begun}
        caption = " ".join((module.__doc__ or "").strip().split("\n\n")[0].split())
        entries.append((name, caption, png))
    contact_sheet(entries, a.sheet)
    total = time.perf_counter() - start
    for name, c in costs.items():
        said = (f"  {name:22s} {c.get('method', ''):28s} {c.get('sampler', ''):12s} "
                f"{c.get('spp', ''):>5} spp {c.get('seconds', float('nan')):7.1f} s")
        if "noise" in c:
            said += f"; noise: brightness {c['noise']['brightness']:.4f}, colour {c['noise']['colour']:.4f}"
        print(said)
    (a.out / "gallery.json").write_text(json.dumps({"panels": costs, "seconds": total,
                                                     "load_average": load_average()}, indent=1))
    print(f"contact sheet {a.sheet} ({len(entries)} scenes) in {total:.0f} s")


def load_average() -> list[float] | None:
    """1, 5 and 15 minute load averages (how busy the machine was while rendering)."""
    try:
        return [float(x) for x in open("/proc/loadavg", encoding="utf-8").read().split()[:3]]
    except OSError:
        return None


if __name__ == "__main__":
    main()
