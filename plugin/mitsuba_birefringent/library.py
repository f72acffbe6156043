"""The plugin library (``libmitsuba_birefringent.so``): loading it, and its C entry points
(registration, versions, the colour matrix of channel renders)."""

from __future__ import annotations

import ctypes
import os
from pathlib import Path

import mitsuba  # loads libmitsuba (and its PluginManager) before the plugin library

LIBRARY_NAME = "libmitsuba_birefringent.so"
_lib = None


def library_path() -> Path:
    """Path of the plugin library that :func:`register` loads."""
    env = os.environ.get("MITSUBA_BIREFRINGENT_LIBRARY")
    return Path(env) if env else Path(__file__).resolve().parent / LIBRARY_NAME


def load() -> ctypes.CDLL:
    """The plugin library, loaded once (with the wheel's libmitsuba before it)."""
    global _lib
    if _lib is None:
        path = library_path()
        if not path.is_file():
            raise ImportError(
                f"mitsuba_birefringent: the plugin library {path} does not exist; "
                "install the package with `pip install .` (or `make setup`) at the repository root"
            )
        # Make sure this process's libmitsuba is the wheel's (the plugin library needs it loaded).
        ctypes.CDLL(str(Path(mitsuba.__file__).resolve().parent / "libmitsuba.so"),
                    mode=ctypes.RTLD_GLOBAL)
        lib = ctypes.CDLL(str(path), mode=ctypes.RTLD_GLOBAL)
        lib.bfr_mitsuba_register.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
        lib.bfr_mitsuba_register.restype = ctypes.c_int
        for name in ("bfr_mitsuba_version", "bfr_mitsuba_variants"):
            getattr(lib, name).argtypes = []
            getattr(lib, name).restype = ctypes.c_char_p
        lib.bfr_mitsuba_channel_matrix.argtypes = [ctypes.c_char_p, ctypes.POINTER(ctypes.c_double),
                                                   ctypes.c_char_p, ctypes.c_size_t]
        lib.bfr_mitsuba_channel_matrix.restype = ctypes.c_int
        _lib = lib
    return _lib


def register() -> None:
    """Registers (again) the three plugins in every variant. Called on import."""
    lib = load()
    buf = ctypes.create_string_buffer(1024)
    if lib.bfr_mitsuba_register(buf, len(buf)) != 0:
        raise ImportError("mitsuba_birefringent: registration failed: "
                          + buf.value.decode(errors="replace"))


def core_version() -> str:
    """Version of the Rust core linked into the plugin library."""
    return load().bfr_mitsuba_version().decode()


def supported_variants() -> tuple[str, ...]:
    """The Mitsuba variants the plugins work in (as the plugin library registers them)."""
    return tuple(load().bfr_mitsuba_variants().decode().split(", "))


def channel_matrix(weights: str) -> list[list[float]]:
    """The 3x3 matrix from the normalised channel values of the weight set ``weights``
    (``"srgb-d65"``, ``"xyz-d65"``, ``"xyz-e"``) to linear sRGB, from the core (raises
    ``ValueError`` with the core's message for another name)."""
    lib = load()
    out = (ctypes.c_double * 9)()
    buf = ctypes.create_string_buffer(512)
    if lib.bfr_mitsuba_channel_matrix(weights.encode(), out, buf, len(buf)) != 0:
        raise ValueError(buf.value.decode(errors="replace"))
    return [list(out[3 * i:3 * i + 3]) for i in range(3)]
