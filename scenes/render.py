"""Render a scene of this directory to EXR and PNG.

    .venv/bin/python scenes/render.py photoelastic_disk --out out [--spp 16] [--width 512]
        [--height 512] [--variant scalar_spectral_polarized] [--set load_n=800 --set ...]
        [--sampler multijitter] [--analytic [--weights srgb-d65]]

A scene module (`scenes/<name>.py`) has a docstring (what it shows, the physics, the check), a
constant `VARIANTS` (the Mitsuba variants it renders in, the first is the default) and
`scene(width=..., height=..., spp=..., filter_bandwidth=0.0, **physics_options) -> dict` for
`mi.load_dict` (the variant is set before it is called). `--set key=value` passes a physics
option (the value is read as a Python literal when it is one, else as a string).

Outputs: `<out>/<name>.exr` (every channel of the film, named as Mitsuba names them) and
`<out>/<name>.png` (`preview`: sRGB of the RGB channels; for a `stokes` render, the Stokes
vector as colours; for a one-channel monochromatic film, grey).

`--sampler` replaces the sensor's sampler type (default `multijitter`, which stratifies the
samples of each pixel, among them the number that chooses a plate's reflection or transmission:
at 16 spp it leaves less than half the brightness noise of the scenes' own `independent`
sampler; `--sampler scene` keeps the scene's own).

`--analytic` renders with `mitsuba_birefringent.render_analytic` instead (one
llvm_ad_mono_polarized pass per channel of `--weights`, every plate integrated over the channel in
closed form: no colour noise; the scene dict is built in the scene's first variant). Its EXR has
the channels R, G, B (linear sRGB) and, for a `stokes` integrator, S0..S3 of each; `--spp`
defaults to the scene's own sample count.
"""

from __future__ import annotations

import argparse
import ast
import importlib
import pathlib
import sys
import time

import mitsuba as mi
import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))


def scene_names() -> list[str]:
    """The scene modules of this directory: every module with `scene` and `VARIANTS`."""
    names = []
    for path in sorted(HERE.glob("*.py")):
        if path.stem.startswith("_") or path.stem in ("render", "gallery"):
            continue
        module = importlib.import_module(path.stem)
        if callable(getattr(module, "scene", None)) and hasattr(module, "VARIANTS"):
            names.append(path.stem)
    return names


def preview(image: np.ndarray) -> np.ndarray:
    """A displayable linear RGB image (H, W, 3) of a render: the RGB channels of an RGB film;
    grey for a one-channel film; for the 15 channels of the `stokes` integrator (RGB, then S0..S3
    as RGB) the normalised Stokes vector as a colour, (0.5 + 0.5 S1/S0, 0.5 + 0.5 S2/S0,
    0.5 + 0.5 S3/S0) (linear polarisation along x: red-ish, at +45 degrees: green-ish,
    right-circular: blue-ish; unpolarised: grey), scaled by S0 / max S0."""
    image = np.asarray(image, dtype=np.float64)
    if image.ndim == 2:
        image = image[..., None]
    channels = image.shape[-1]
    if channels == 1:
        return np.repeat(image, 3, axis=-1)
    if channels == 15:
        s = [image[..., 3 + 3 * i: 6 + 3 * i].sum(axis=-1) for i in range(4)]
        s0 = np.where(np.abs(s[0]) > 1e-12, s[0], 1e-12)
        colour = np.stack([0.5 + 0.5 * s[i] / s0 for i in (1, 2, 3)], axis=-1)
        level = np.clip(s[0] / max(float(s[0].max()), 1e-12), 0.0, 1.0)[..., None]
        return np.clip(colour, 0.0, 1.0) * level
    return image[..., :3]


#: The sampler `render` and `render_analytic` use unless told otherwise (module docstring).
SAMPLER = "multijitter"


def with_sampler(scene: dict, sampler: str) -> dict:
    """`scene` with its sensor's sampler of type `sampler` (`"scene"`: unchanged)."""
    if sampler != "scene":
        scene["sensor"]["sampler"]["type"] = sampler
    return scene


def render(name: str, out: pathlib.Path, variant: str | None = None, seed: int = 0,
           sampler: str = SAMPLER, **options) -> pathlib.Path:
    """Renders scene `name` with `options` to `<out>/<name>.exr` and `.png`; returns the PNG."""
    module = importlib.import_module(name)
    mi.set_variant(variant or module.VARIANTS[0])
    import mitsuba_birefringent  # registers the plugins for the variant set

    scene = mi.load_dict(with_sampler(module.scene(**options), sampler))
    start = time.perf_counter()
    # The plugins work in the JIT variants in evaluated mode only (no-op in scalar variants).
    with mitsuba_birefringent.evaluated_mode():
        image = mi.render(scene, seed=seed)
    seconds = time.perf_counter() - start
    out.mkdir(parents=True, exist_ok=True)
    exr = out / f"{name}.exr"
    scene.sensors()[0].film().bitmap().write(str(exr))
    png = out / f"{name}.png"
    rgb = preview(np.array(image))
    mi.util.convert_to_bitmap(mi.Bitmap(rgb.astype(np.float32))).write(str(png))
    print(f"{name} ({mi.variant()}, {sampler} sampler): {exr} and {png} in {seconds:.1f} s")
    return png


def render_analytic(name: str, out: pathlib.Path, weights: str = "srgb-d65", seed: int = 0,
                    sampler: str = SAMPLER, **options) -> pathlib.Path:
    """Renders scene `name` by channels (module docstring) to `<out>/<name>.exr` and `.png`."""
    module = importlib.import_module(name)
    mi.set_variant(module.VARIANTS[0])
    import mitsuba_birefringent

    scene = with_sampler(module.scene(**options), sampler)
    spp = options.get("spp") or scene["sensor"].get("sampler", {}).get("sample_count", 16)
    start = time.perf_counter()
    result = mitsuba_birefringent.render_analytic(scene, spp=spp, weights=weights, seed=seed)
    seconds = time.perf_counter() - start
    names, planes = ["R", "G", "B"], [result["rgb"]]
    if "stokes" in result:
        names += [f"S{i}.{c}" for i in range(4) for c in "RGB"]
        planes.append(result["stokes"].reshape(*result["rgb"].shape[:2], 12))
    image = np.concatenate(planes, axis=-1).astype(np.float32)
    out.mkdir(parents=True, exist_ok=True)
    exr = out / f"{name}.exr"
    mi.Bitmap(image, mi.Bitmap.PixelFormat.MultiChannel, names).write(str(exr))
    png = out / f"{name}.png"
    mi.util.convert_to_bitmap(mi.Bitmap(preview(image).astype(np.float32))).write(str(png))
    print(f"{name} (by channels, {weights}, {spp} spp per pass, {sampler} sampler): {exr} and {png} "
          f"in {seconds:.1f} s")
    return png


def parse_value(text: str):
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", help="one of: " + ", ".join(scene_names()))
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out"))
    p.add_argument("--spp", type=int, default=None)
    p.add_argument("--width", type=int, default=None)
    p.add_argument("--height", type=int, default=None)
    p.add_argument("--variant", default=None, help="default: the scene's VARIANTS[0]")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="a physics option of the scene (repeatable)")
    p.add_argument("--sampler", default=SAMPLER,
                   help="the sensor's sampler type (default %(default)s; 'scene': the scene's own)")
    p.add_argument("--analytic", action="store_true",
                   help="render by colour channels (mitsuba_birefringent.render_analytic)")
    p.add_argument("--weights", default="srgb-d65", help="channels of --analytic: srgb-d65, "
                   "xyz-d65 or xyz-e (default srgb-d65)")
    a = p.parse_args()
    options = {k: v for k, v in (("spp", a.spp), ("width", a.width), ("height", a.height)) if v is not None}
    for item in a.set:
        key, sep, value = item.partition("=")
        if not sep:
            p.error(f"--set {item!r}: expected KEY=VALUE")
        options[key] = parse_value(value)
    if a.analytic:
        if a.variant:
            p.error("--analytic renders in llvm_ad_mono_polarized; --variant does not apply")
        render_analytic(a.scene, a.out, weights=a.weights, sampler=a.sampler, **options)
    else:
        render(a.scene, a.out, variant=a.variant, sampler=a.sampler, **options)


if __name__ == "__main__":
    main()
