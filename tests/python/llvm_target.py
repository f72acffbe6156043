"""Dr.Jit's LLVM code generation as the environment asks (BIREFRINGENT_LLVM_WIDTH, and optionally
BIREFRINGENT_LLVM_CPU and BIREFRINGENT_LLVM_FEATURES): a check that no test depends on the
machine it was written on. The vector width changes the summation order of Dr.Jit's reductions
and which approximations it emits (its `rsqrt` and `rcp` use the AVX instructions with a
Newton step at width 8 on AVX, the AVX-512 ones at width 16 on AVX-512, exact division
elsewhere), so a test tuned to one machine's rounding fails under another width.

Dr.Jit 1.5 does not expose this in Python; drjit-core exports `jit_llvm_set_target(cpu,
features, width)` (include/drjit-core/jit.h, C++ linkage), called here through ctypes once the
LLVM backend is initialised. The width must be a power of two, and at least 4 (Mitsuba's
Embree refuses 2). A width above the hardware's registers is emulated by LLVM and not sound in
Dr.Jit 1.5: at 16 on an AVX2 machine simple renders run, but a polarised scene of Mitsuba's own
plugins (a polariser and a retarder, no plugin of this package) crashes in a kernel's gather.
So on an AVX2 machine the useful check is width 4 (the exact rsqrt and another summation order
than width 8's); width 16 with the AVX-512 approximations needs an AVX-512 machine.

Applied by tests/python/conftest.py in the pytest process and by the worker scripts
(jit_worker.py, robustness_worker.py) in their subprocesses, e.g.

    BIREFRINGENT_LLVM_WIDTH=4 .venv/bin/python -m pytest tests/python
"""

from __future__ import annotations

import ctypes
import os
import pathlib

WIDTH = "BIREFRINGENT_LLVM_WIDTH"
CPU = "BIREFRINGENT_LLVM_CPU"
FEATURES = "BIREFRINGENT_LLVM_FEATURES"


def core():
    """drjit-core's shared library (the copy Dr.Jit has loaded) with the target functions typed."""
    import drjit

    lib = ctypes.CDLL(str(pathlib.Path(drjit.__file__).parent / "libdrjit-core.so"))
    for name in ("_Z19jit_llvm_target_cpuv", "_Z24jit_llvm_target_featuresv"):
        getattr(lib, name).restype = ctypes.c_char_p
    lib._Z21jit_llvm_vector_widthv.restype = ctypes.c_uint32
    lib._Z19jit_llvm_set_targetPKcS0_j.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_uint32]
    return lib


def current() -> tuple[str, str, int]:
    """(target CPU, features, vector width) of the LLVM backend now."""
    import drjit as dr

    dr.eval(dr.llvm.Float(0.0))  # initialises the LLVM backend
    lib = core()
    return (lib._Z19jit_llvm_target_cpuv().decode(), lib._Z24jit_llvm_target_featuresv().decode(),
            int(lib._Z21jit_llvm_vector_widthv()))


def apply() -> str | None:
    """Sets the LLVM target the environment asks for; returns a line saying what it set (None
    when nothing is asked). Raises if the backend does not take it."""
    width, cpu, features = os.environ.get(WIDTH), os.environ.get(CPU), os.environ.get(FEATURES)
    if not (width or cpu or features):
        return None
    cpu0, features0, width0 = current()
    w = int(width) if width else width0
    if w < 4 or w & (w - 1):
        raise ValueError(f"{WIDTH}={width}: the width must be a power of two, at least 4")
    core()._Z19jit_llvm_set_targetPKcS0_j((cpu or cpu0).encode(), (features or features0).encode(), w)
    got = current()
    if got[2] != w or got[0] != (cpu or cpu0):
        raise RuntimeError(f"Dr.Jit's LLVM backend did not take the target {cpu or cpu0!r} x {w}: {got}")
    return f"Dr.Jit LLVM target: cpu {got[0]}, vector width {got[2]} (was {cpu0} x {width0})"
