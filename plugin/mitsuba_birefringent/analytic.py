"""Noise-free polarized colour: a scene rendered once per colour channel, each plate integrated
over the channel in closed form (docs/physics.md, section 7).

::

    import mitsuba as mi
    import mitsuba_birefringent as mb
    mi.set_variant("scalar_spectral_polarized")   # any variant: only the dict is used
    scene = {...}                                 # a dict for mi.load_dict
    out = mb.render_analytic(scene, spp=16)
    out["rgb"]      # (H, W, 3) linear sRGB
    out["stokes"]   # (H, W, 4, 3) S0..S3 per sRGB channel, with a `stokes` integrator

Each pass renders in ``llvm_ad_mono_polarized`` in evaluated mode; the variant that was set
before is set again afterwards. What each pass does with the rest of the scene, and which
emitter spectra are accepted, is in :mod:`.channel_scene`.

Exact when, along every path, the only factor that varies within a channel is one plate: the
pixel is then the channel's integral of that plate's Mueller matrix times the channel values of
everything else. Not exact: two plates on one path (the integral of a product is not the product
of the integrals; measured in docs/physics.md, section 7), and a bulk crystal, whose refraction
is evaluated at each channel's mean wavelength (its dispersion within a channel is neglected).
The render warns of both.
"""

from __future__ import annotations

import contextlib
import warnings
from typing import Any, Iterator

import mitsuba as mi

try:
    import numpy as np
except ImportError:  # the plugins need no numpy; channel renders do
    raise ImportError("mitsuba_birefringent.render_analytic needs numpy: pip install numpy") from None

from .channel_scene import ChannelScene
from .jit import evaluated_mode
from .library import channel_matrix
from .names import PLUGINS

#: The variant of the passes (the one polarized channel variant Mitsuba's wheel ships).
VARIANT = "llvm_ad_mono_polarized"

#: The channels of each weight set (the core's names).
CHANNELS = {"srgb-d65": "RGB", "xyz-d65": "XYZ", "xyz-e": "XYZ"}


def render_analytic(scene: dict, spp: int = 16, weights: str = "srgb-d65",
                    seed: int = 0) -> dict[str, Any]:
    """Renders ``scene`` (a dict for ``mi.load_dict``, as for scalar_spectral_polarized) with
    every plate integrated over each channel of ``weights`` (``"srgb-d65"``, ``"xyz-d65"`` or
    ``"xyz-e"``), ``spp`` samples per pixel and ``seed`` in every pass.

    Returns ``"rgb"``: linear sRGB, float32 (H, W, 3); ``"channels"``: the passes' channel
    values (H, W, 3) (normalised: the set's white is 1); and, when the scene's integrator is
    ``stokes``, ``"stokes"``: (H, W, 4, 3), S0..S3 per sRGB channel."""
    if not isinstance(scene, dict):
        raise TypeError(f"scene must be a dict for mi.load_dict, got {type(scene).__name__}")
    if not isinstance(spp, int) or spp < 1:
        raise ValueError(f"spp must be a positive integer, got {spp!r}")
    if weights not in CHANNELS:
        raise ValueError(f"weights must be one of {', '.join(CHANNELS)}, got {weights!r}")
    passes = channel_passes(scene, weights)  # every refusal before any render
    warn_where_inexact(scene)
    previous = mi.variant()
    mi.set_variant(VARIANT)
    try:
        with evaluated_mode():
            images = [render_pass(p, spp, seed, quiet=k > 0) for k, p in enumerate(passes)]
    finally:
        if previous is not None:
            mi.set_variant(previous)
    return assemble(images, np.array(channel_matrix(weights)))


def channel_passes(scene: dict, weights: str) -> list[dict]:
    """The scene dict of each channel's pass, in the order of ``CHANNELS[weights]``."""
    from_srgb = np.linalg.inv(np.array(channel_matrix(weights)))
    return [ChannelScene(weights, f"{weights}:{c}", k, from_srgb).rewrite(scene)
            for k, c in enumerate(CHANNELS[weights])]


def render_pass(scene: dict, spp: int, seed: int, quiet: bool = False) -> dict[str, np.ndarray]:
    """One pass: the film's channels by name, each (H, W). `quiet`: the scene is loaded without
    its warnings (those of the first pass's load: the passes differ only in their channel), so
    that each is printed once, not once per pass; errors are still raised."""
    with warnings_off() if quiet else contextlib.nullcontext():
        loaded = mi.load_dict(scene)
    mi.render(loaded, spp=spp, seed=seed)
    bitmap = loaded.sensors()[0].film().bitmap()
    names = [bitmap.struct_()[i].name for i in range(bitmap.channel_count())]
    data = np.array(bitmap, dtype=np.float64).reshape(bitmap.height(), bitmap.width(), len(names))
    return {name: data[..., i] for i, name in enumerate(names)}


@contextlib.contextmanager
def warnings_off() -> Iterator[None]:
    """Mitsuba's log at errors only, restored afterwards."""
    logger = mi.logger()
    level = logger.log_level()
    logger.set_log_level(mi.LogLevel.Error)
    try:
        yield
    finally:
        logger.set_log_level(level)


def stokes_component(image: dict[str, np.ndarray], s: int) -> np.ndarray | None:
    """S``s`` of a pass (a mono film's Stokes channels repeat one value under three names)."""
    for name, values in image.items():
        if name.startswith(f"S{s}."):
            return values
    return None


def assemble(images: list[dict[str, np.ndarray]], to_srgb: np.ndarray) -> dict[str, Any]:
    """The passes' channel values, and their linear sRGB."""
    channels = np.stack([img["Y"] for img in images], axis=-1)
    out: dict[str, Any] = {"channels": channels.astype(np.float32),
                           "rgb": (channels @ to_srgb.T).astype(np.float32)}
    if stokes_component(images[0], 0) is not None:
        stokes = np.stack([np.stack([stokes_component(img, s) for img in images], axis=-1)
                           for s in range(4)], axis=-2)
        out["stokes"] = (stokes @ to_srgb.T).astype(np.float32)
    return out


def plugin_nodes(node: Any) -> Iterator[dict]:
    """Every dict of the scene whose type is one of the package's plugins (a stack's layers are
    part of the stack, not plates of their own)."""
    if isinstance(node, dict):
        if node.get("type") in PLUGINS:
            yield node
            if node["type"] == "birefringentstack":
                return
        for value in node.values():
            yield from plugin_nodes(value)


def warn_where_inexact(scene: dict) -> None:
    """Warns when a path may meet two plates, or meets a bulk crystal (module docstring)."""
    nodes = list(plugin_nodes(scene))
    plates = sum(1 for n in nodes if n["type"] in ("thinbirefringent", "birefringentstack"))
    if plates > 1:
        warnings.warn(
            f"the scene has {plates} thinbirefringent plates or stacks: where a path passes "
            "through two of them, the channel render multiplies their channel integrals, which "
            "is not the integral of their product (two quartz plates stacked between crossed "
            "polarisers: CIEDE2000 0.16 for 5 + 60 um, 2-3 for 20 + 35 um, 8.3 for 50 + 50 um "
            "with parallel axes; docs/physics.md, section 7). Plates side by side are exact, and "
            "so are plates in contact given as the layers of one birefringentstack.",
            stacklevel=3)
    if any(n["type"] == "birefringent" for n in nodes):
        warnings.warn(
            "a birefringent crystal is evaluated at each channel's mean wavelength in a channel "
            "render: its dispersion within a channel is neglected (docs/physics.md, section 7)",
            stacklevel=3)
