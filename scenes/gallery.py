"""Render every scene of this directory at gallery size and put them on one contact sheet.

    .venv/bin/python scenes/gallery.py [--out out/gallery] [--sheet scenes/gallery.png]
        [--width 320] [--spp 16] [--sampler multijitter] [--only NAME ...] [--reuse]

Scenes are the modules `render.scene_names()` finds (a `scene` function and `VARIANTS`), each
rendered in its default variant at `--width` pixels wide (the height keeps the aspect of the
scene's default width and height) with `--spp` samples per pixel and the sampler `--sampler`
(`render.SAMPLER`, multijitter: it stratifies the choice between a plate's reflection and
transmission), unless the module has a dict
`GALLERY` of options for the gallery (e.g. fewer samples for a costly scene). Each goes to
`<out>/<name>.exr` and `.png` (`render.render`); the contact sheet has the images in a grid with
the scene's name and the first paragraph of its docstring under each.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import math
import pathlib
import sys
import textwrap
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import render  # noqa: E402


def gallery_options(module, width: int, spp: int) -> dict:
    defaults = inspect.signature(module.scene).parameters
    w0, h0 = defaults["width"].default, defaults["height"].default
    options = {"width": width, "height": max(1, round(width * h0 / w0)), "spp": spp}
    options.update(getattr(module, "GALLERY", {}))
    return options


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
    a = p.parse_args()
    entries, start = [], time.perf_counter()
    for name in render.scene_names():
        if a.only and name not in a.only:
            continue
        module = importlib.import_module(name)
        png = a.out / f"{name}.png"
        if not (a.reuse and png.exists()):
            png = render.render(name, a.out, sampler=a.sampler,
                                **gallery_options(module, a.width, a.spp))
        caption = " ".join((module.__doc__ or "").strip().split("\n\n")[0].split())
        entries.append((name, caption, png))
    contact_sheet(entries, a.sheet)
    print(f"contact sheet {a.sheet} ({len(entries)} scenes) in {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
