"""One colour channel of a scene dict: the pass of a channel render (:mod:`.analytic`).

A channel render renders a scene once per channel of a weight set in ``llvm_ad_mono_polarized``.
In each pass the plugins integrate the plate over the channel's weight in closed form (their
``channel`` parameter), and everything else in the scene takes its value in that channel:

* RGB values (``rgb``/``srgb`` spectra, ``mi.ScalarColor3f``) and three-channel bitmaps become
  their channel value, ``A^-1 c`` with ``A`` the core's matrix from channel values to linear
  sRGB (identity up to the tables' rounding for ``srgb-d65``); one-channel bitmaps and floats are
  the same in every channel and stay as they are. Textures inside the plugins are physical
  scalars (thickness, birefringence, angle) and are never touched.
* Emitters: the illuminant enters through the weight. ``srgb-d65`` and ``xyz-d65`` include
  D65, so they take emitters whose spectrum is D65 times a colour, which is what Mitsuba's
  spectral variants make of a float, an ``rgb`` value, an RGB bitmap (``area``, ``constant``,
  ``point``, ``spot``, ``envmap``, ...) and a ``d65`` spectrum; ``xyz-e`` takes equal-energy
  ``uniform`` emitter spectra only. Any other emitter spectrum is refused.
* Refused, with the reason: other spectra (``spectrum``, ``regular``, ``irregular``,
  ``blackbody``, spectrum files), Mitsuba's named conductor materials (spectral data), a sensor
  response (``srf``) and a ``specfilm`` (the channel weight is the sensor's response).
"""

from __future__ import annotations

from typing import Any

import mitsuba as mi
import numpy as np

from .names import PLUGINS

#: Mitsuba 3.9.1's emitter plugins whose spectrum a scene gives (a texture or spectrum).
EMITTER_TYPES = ("area", "point", "spot", "constant", "envmap", "directional", "directionalarea",
                 "projector")

#: The properties of those emitters that hold their spectrum.
EMITTER_SPECTRA = ("radiance", "intensity", "irradiance")

#: Spectrum plugins whose values are RGB colours.
RGB_TYPES = ("rgb", "srgb")

#: Spectrum plugins a channel pass cannot represent.
SPECTRAL_TYPES = ("spectrum", "regular", "irregular", "blackbody")

#: Weight sets whose weights include D65 (a D65-based emitter is their white).
D65_SETS = ("srgb-d65", "xyz-d65")


class ChannelScene:
    """Rewrites scene dicts for channel ``index`` of ``weights`` (its name is ``channel``,
    e.g. ``"srgb-d65:R"``); ``from_srgb`` is the inverse of the core's matrix (a row per
    channel)."""

    def __init__(self, weights: str, channel: str, index: int, from_srgb: np.ndarray):
        self.weights, self.channel, self.index = weights, channel, index
        self.row = np.asarray(from_srgb, dtype=np.float64)[index]

    def rewrite(self, scene: dict) -> dict:
        """The scene dict of this channel's pass (the input is not modified)."""
        return self._node(scene, "scene", emitter=False)

    # -- nodes -------------------------------------------------------------------------------

    def _node(self, node: Any, path: str, emitter: bool) -> Any:
        if isinstance(node, dict):
            return self._dict(node, path, emitter)
        if mi.variant() is not None and isinstance(node, mi.ScalarColor3f):  # none without one
            return self._value(np.array(node), path, emitter)
        if emitter and isinstance(node, (int, float)) and not isinstance(node, bool):
            self._check_d65_emitter(path, "a float (D65 times the value)")
        return node

    def _dict(self, node: dict, path: str, emitter: bool) -> dict:
        kind = node.get("type")
        # The package's plugins: their parameters are physical scalars, never rewritten (a
        # stack's nested plates are its layers, which it integrates over the channel itself).
        if kind in PLUGINS:
            if "channel" in node:
                raise ValueError(f"{path}: \"channel\" is set by the channel render; remove it")
            return {**node, "channel": self.channel}
        if kind in RGB_TYPES:
            return self._value(np.asarray(node.get("value", 1.0), dtype=np.float64), path, emitter,
                               extra=node)
        if kind == "d65":
            self._check_d65_emitter(path, "a d65 spectrum")
            return {"type": "uniform", "value": float(node.get("scale", 1.0))}
        if kind == "uniform":
            if emitter and self.weights in D65_SETS:
                raise ValueError(
                    f"{path}: an equal-energy (uniform) emitter spectrum is not the white of the "
                    f"\"{self.weights}\" weights (they include D65); use weights=\"xyz-e\", or "
                    "give the emitter a float, rgb or d65 radiance")
            return node
        if kind in SPECTRAL_TYPES:
            raise ValueError(
                f"{path}: a \"{kind}\" spectrum cannot be split into colour channels by the "
                "channel render; give an rgb value (or render in scalar_spectral_polarized)")
        if kind in ("conductor", "roughconductor") and node.get("material", "none") != "none":
            raise ValueError(
                f"{path}: a named conductor material (\"{node['material']}\") is spectral data, "
                "which the channel render cannot split into channels; give eta and k as floats "
                "or rgb values")
        if kind == "bitmap":
            return self._bitmap(node, path, emitter)
        if kind == "envmap":
            return self._envmap(node, path)
        if kind == "sunsky":
            raise ValueError(f"{path}: a sunsky emitter's spectrum is not the white of any "
                             "channel weights; use an envmap or constant emitter")
        if kind == "specfilm":
            raise ValueError(f"{path}: a specfilm's bands are not colour channels; the channel "
                             "render needs an hdrfilm")
        if "film" in node and "srf" in node:
            raise ValueError(f"{path}: a sensor response (srf) is replaced by the channel "
                             "weights in a channel render; remove it")
        spectra = kind in EMITTER_TYPES
        out = {key: self._node(value, f"{path}.{key}", emitter or spectra and key in EMITTER_SPECTRA)
               for key, value in node.items()}
        if kind == "hdrfilm":
            out["pixel_format"] = "luminance"  # a mono variant's film has one channel
        return out

    # -- values ------------------------------------------------------------------------------

    def _value(self, rgb: np.ndarray, path: str, emitter: bool, extra: dict | None = None) -> Any:
        if emitter:
            self._check_d65_emitter(path, "an rgb value (D65 times the colour)")
        rgb = np.broadcast_to(rgb, (3,))
        value = float(self.row @ rgb)
        out = {"type": "uniform", "value": value}
        if extra is not None and "id" in extra:
            out["id"] = extra["id"]
        return out

    def _check_d65_emitter(self, path: str, what: str) -> None:
        if self.weights not in D65_SETS:
            raise ValueError(
                f"{path}: {what} emitter spectrum is D65-based in Mitsuba's spectral variants, "
                f"not the equal-energy white of the \"{self.weights}\" weights; use weights="
                "\"srgb-d65\" or \"xyz-d65\", or give the emitter a uniform spectrum")

    def _channel_image(self, bitmap: mi.Bitmap, raw: bool) -> np.ndarray | None:
        """The channel values of a three-channel bitmap (linear unless `raw`), or None for a
        one-channel one."""
        if bitmap.channel_count() in (1, 2):
            return None
        linear = bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32,
                                srgb_gamma=bitmap.srgb_gamma() if raw else False)
        rgb = np.array(linear, dtype=np.float64)
        return np.ascontiguousarray((rgb @ self.row)[..., None].repeat(3, axis=-1),
                                    dtype=np.float32)

    def _load_bitmap(self, node: dict, path: str) -> mi.Bitmap:
        if "bitmap" in node:
            return node["bitmap"]
        if "data" in node:
            return mi.Bitmap(np.asarray(node["data"], dtype=np.float32))
        if "filename" in node:
            resolved = mi.file_resolver().resolve(str(node["filename"]))
            return mi.Bitmap(str(resolved))
        raise ValueError(f"{path}: a bitmap needs \"filename\", \"bitmap\" or \"data\"")

    def _bitmap(self, node: dict, path: str, emitter: bool) -> dict:
        raw = bool(node.get("raw", False))
        image = self._channel_image(self._load_bitmap(node, path), raw)
        if image is None:
            return node
        if emitter:
            self._check_d65_emitter(path, "an RGB bitmap (D65 times the colour)")
        out = {k: v for k, v in node.items() if k not in ("filename", "bitmap", "data")}
        out.update({"bitmap": mi.Bitmap(image), "raw": True})
        return out

    def _envmap(self, node: dict, path: str) -> dict:
        self._check_d65_emitter(path, "an envmap's RGB image (D65 times the colour)")
        image = self._channel_image(self._load_bitmap(node, path), False)
        out = {k: v for k, v in node.items() if k not in ("filename", "bitmap")}
        if image is not None:
            out["bitmap"] = mi.Bitmap(image)
        elif "filename" in node:
            out["bitmap"] = self._load_bitmap(node, path)
        return out
