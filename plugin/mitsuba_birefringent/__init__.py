"""Birefringent BSDFs for Mitsuba 3: ``thinbirefringent`` (a birefringent plate) and
``birefringent`` (the surface of a bulk uniaxial crystal).

Importing the package registers both plugins with Mitsuba's plugin manager::

    import mitsuba as mi
    import mitsuba_birefringent
    mi.set_variant("scalar_spectral_polarized")
    plate = mi.load_dict({"type": "thinbirefringent", "material": "quartz", "thickness": 20.0})

They work in the variants listed in :data:`VARIANTS` (the cuda variants raise a clear error at
scene load); in the llvm variants, render inside :func:`evaluated_mode` (see its module,
``jit``). The optics is computed by the Rust core linked into the plugin library; see
``plugin/README.md`` for the parameters. XML scenes render with the command
``mitsuba-birefringent`` (:mod:`mitsuba_birefringent.cli`); Mitsuba's own ``mitsuba`` command
cannot load these plugins.

The plugin library is ``libmitsuba_birefringent.so`` next to this file (``pip install .`` at the
repository root builds it, and so does ``make setup``); the environment variable
``MITSUBA_BIREFRINGENT_LIBRARY`` overrides its path.
"""

from __future__ import annotations

import ctypes
import importlib.metadata
import os
from pathlib import Path

import mitsuba  # loads libmitsuba (and its PluginManager) before the plugin library

from .jit import evaluated_mode

__all__ = ["PLUGINS", "VARIANTS", "__version__", "library_path", "core_version", "register",
           "evaluated_mode"]

try:
    #: The installed distribution's version (Cargo.toml's, written by the build backend).
    __version__ = importlib.metadata.version("mitsuba-birefringent")
except importlib.metadata.PackageNotFoundError:
    raise ImportError("mitsuba_birefringent is not installed (no distribution metadata): run "
                      "`pip install .` (or `make setup`) at the repository root") from None

#: The BSDF plugin names this package registers.
PLUGINS = ("thinbirefringent", "birefringent")

_LIBRARY_NAME = "libmitsuba_birefringent.so"
_lib = None


def library_path() -> Path:
    """Path of the plugin library that :func:`register` loads."""
    env = os.environ.get("MITSUBA_BIREFRINGENT_LIBRARY")
    return Path(env) if env else Path(__file__).resolve().parent / _LIBRARY_NAME


def _load() -> ctypes.CDLL:
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
        _lib = lib
    return _lib


def register() -> None:
    """Registers (again) both plugins in every variant. Called on import."""
    lib = _load()
    buf = ctypes.create_string_buffer(1024)
    if lib.bfr_mitsuba_register(buf, len(buf)) != 0:
        raise ImportError("mitsuba_birefringent: registration failed: "
                          + buf.value.decode(errors="replace"))


def core_version() -> str:
    """Version of the Rust core linked into the plugin library."""
    return _load().bfr_mitsuba_version().decode()


register()

#: The Mitsuba variants the plugins work in (as the plugin library registers them).
VARIANTS = tuple(_load().bfr_mitsuba_variants().decode().split(", "))
