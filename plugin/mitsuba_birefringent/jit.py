"""Dr.Jit's evaluated mode, which the plugins' host queries need in the JIT variants.

In the JIT variants the plugins' physics runs inside Mitsuba's kernels, in its default
(symbolic) mode, except where a plate or stack is integrated over colour channels or a band
(``llvm_ad_rgb``, the mono variants, ``filter_bandwidth`` > 0): that query computes its lobes in
the package's native core on the host, so it needs the values of the lanes that hit it, real
arrays, not the symbolic variables Dr.Jit records loops and virtual calls with by default. Both
flags must be off; with either on, such a query raises an error that names them (its text holds
:data:`EVALUATED_ONLY`). Python integrators (Mitsuba's ``prb``, ``prb_basic``, ...) also record
their ``if`` statements on arrays symbolically, which makes the calls inside symbolic again (and
Dr.Jit 1.5.0 fails in ``prb`` with only loops and calls off), so conditionals are switched off
too. ``evaluated_mode()`` switches all three off around a render::

    import mitsuba as mi
    import mitsuba_birefringent
    mi.set_variant("llvm_ad_rgb")
    scene = mi.load_dict(...)
    with mitsuba_birefringent.evaluated_mode():
        image = mi.render(scene)

Evaluated mode is slower than symbolic mode for every BSDF (each loop iteration and call is a
kernel of its own) and keeps more memory. While an instance of these plugins that queries the
host exists in the process, Dr.Jit's symbolic calls trace it too, so a *symbolic* render of
another scene fails with the same error: render that scene inside ``evaluated_mode()`` as well,
or delete every such scene and BSDF first (``del scene``, and any exception a failed render
raised: its traceback holds the scene; then ``gc.collect()``), or use a separate process.
"""

from __future__ import annotations

import contextlib
from typing import Iterator

import drjit as dr

#: The Dr.Jit flags that must be off (conditionals for Python integrators such as ``prb``).
FLAGS = (dr.JitFlag.SymbolicLoops, dr.JitFlag.SymbolicCalls, dr.JitFlag.SymbolicConditionals)


#: Words of the plugins' error where a host query runs in Dr.Jit's symbolic mode
#: (cpp/src/bridge.h, ``require_evaluated_mode``).
EVALUATED_ONLY = "works in evaluated mode only"


@contextlib.contextmanager
def evaluated_mode() -> Iterator[None]:
    """Switches Dr.Jit's symbolic loops, calls and conditionals off, and restores them on exit."""
    saved = [dr.flag(f) for f in FLAGS]
    try:
        for f in FLAGS:
            dr.set_flag(f, False)
        yield
    finally:
        for f, value in zip(FLAGS, saved):
            dr.set_flag(f, value)
