"""Render a scene of this directory to EXR and PNG.

    .venv/bin/python scenes/render.py michel_levy --out out [--spp 16] [--width 384]

Each scene module has a `scene(**options)` returning a dict for `mi.load_dict` and a module
docstring saying what it shows and in which variant.
"""

from __future__ import annotations

import argparse
import importlib
import pathlib
import sys
import time

import mitsuba as mi

VARIANT = "scalar_spectral_polarized"


def render(name: str, out: pathlib.Path, **options) -> pathlib.Path:
    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins for the variant set)

    sys.path.insert(0, str(pathlib.Path(__file__).parent))
    module = importlib.import_module(name)
    scene = mi.load_dict(module.scene(**options))
    start = time.perf_counter()
    image = mi.render(scene)
    seconds = time.perf_counter() - start
    out.mkdir(parents=True, exist_ok=True)
    exr = out / f"{name}.exr"
    mi.Bitmap(image).write(str(exr))
    png = out / f"{name}.png"
    mi.util.convert_to_bitmap(image).write(str(png))
    print(f"{name}: {exr} and {png} in {seconds:.1f} s")
    return png


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene")
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out"))
    p.add_argument("--spp", type=int, default=None)
    p.add_argument("--width", type=int, default=None)
    p.add_argument("--height", type=int, default=None)
    a = p.parse_args()
    options = {k: v for k, v in (("spp", a.spp), ("width", a.width), ("height", a.height)) if v is not None}
    render(a.scene, a.out, **options)


if __name__ == "__main__":
    main()
