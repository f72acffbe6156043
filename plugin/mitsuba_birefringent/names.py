"""The package's BSDF plugins, written once: the name a scene gives each (``type``) and the C++
class that implements it, whose name Mitsuba's ``Throw`` and ``Log`` put in front of its
messages (``[ThinBirefringent] ...``)."""

from __future__ import annotations

#: Plugin name -> its class (cpp/src/*.cpp, MI_DECLARE_CLASS), in the order the package
#: documents them.
CLASSES = {"thinbirefringent": "ThinBirefringent", "birefringentstack": "BirefringentStack",
           "birefringent": "Birefringent"}

#: The BSDF plugin names this package registers.
PLUGINS = tuple(CLASSES)

#: The prefixes of the plugins' messages.
TAGS = tuple(f"[{c}] " for c in CLASSES.values())


def listed(names: tuple[str, ...] = PLUGINS) -> str:
    """``a, b and c``."""
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]
