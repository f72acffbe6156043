"""Birefringent BSDFs for Mitsuba 3: ``thinbirefringent`` (a birefringent plate),
``birefringentstack`` (a stack of such plates as layers) and ``birefringent`` (the surface of a
bulk uniaxial crystal).

Importing the package registers the plugins with Mitsuba's plugin manager::

    import mitsuba as mi
    import mitsuba_birefringent
    mi.set_variant("scalar_spectral_polarized")
    plate = mi.load_dict({"type": "thinbirefringent", "material": "quartz", "thickness": 20.0,
                          "optic_axis": [1, 1, 0]})

They work in the variants listed in :data:`VARIANTS`; in the JIT variants their physics runs
inside Mitsuba's kernels in its default mode, except a plate or stack integrated over colour
channels or a band, which needs :func:`evaluated_mode` (see its module, ``jit``) and is refused
in the cuda variants. Importing the
package also makes ``mi.render`` and ``mi.set_variant`` end with the plugins' own message where
Dr.Jit would hide it (:mod:`.messages`). The optics is computed by the Rust core linked into the plugin library; see
``plugin/README.md`` for the parameters. XML scenes render with the command
``mitsuba-birefringent`` (:mod:`mitsuba_birefringent.cli`); Mitsuba's own ``mitsuba`` command
cannot load these plugins.

The plugin library is ``libmitsuba_birefringent.so`` next to this file (``pip install .`` at the
repository root builds it, and so does ``make setup``); the environment variable
``MITSUBA_BIREFRINGENT_LIBRARY`` overrides its path.
"""

from __future__ import annotations

import importlib.metadata

from . import messages
from .jit import evaluated_mode
from .library import core_version, library_path, register, supported_variants
from .names import PLUGINS

__all__ = ["PLUGINS", "VARIANTS", "__version__", "library_path", "core_version", "register",
           "evaluated_mode", "render_analytic"]

try:
    #: The installed distribution's version (Cargo.toml's, written by the build backend).
    __version__ = importlib.metadata.version("mitsuba-birefringent")
except importlib.metadata.PackageNotFoundError:
    raise ImportError("mitsuba_birefringent is not installed (no distribution metadata): run "
                      "`pip install .` (or `make setup`) at the repository root") from None

register()

#: The Mitsuba variants the plugins work in (as the plugin library registers them).
VARIANTS = supported_variants()

# The plugins' messages as the last line of mi.render and mi.set_variant (see messages.py).
messages.install(VARIANTS)


def __getattr__(name: str):
    # render_analytic needs numpy, which the plugins alone do not: imported on first use.
    if name == "render_analytic":
        from .analytic import render_analytic

        return render_analytic
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
