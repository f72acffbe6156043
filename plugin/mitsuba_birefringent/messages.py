"""The plugins' own messages as the last line of two Mitsuba entry points that would otherwise
hide them. Installed on import of the package (:func:`install`); nothing else changes.

* ``mi.render`` in a JIT variant runs the integrator inside ``drjit.custom``, which replaces any
  exception by ``drjit.custom(...): error while performing a custom differentiable operation.
  (see above)``: the plugins' message (a render in Dr.Jit's symbolic mode, which names the two
  flags and ``evaluated_mode()``) was only in the chained exception above it. The wrapped
  ``mi.render`` raises that message itself (a ``RuntimeError``; Dr.Jit's exception stays in its
  ``__context__``).
* ``mi.set_variant("cuda_...")`` on a machine without a CUDA device fails inside Dr.Jit
  (``jit_init_thread_state(): the CUDA backend hasn't been initialized``) before any plugin can
  refuse the variant. The wrapped ``mi.set_variant`` raises the same exception type with the
  plugins' refusal (the llvm variant to use), and Dr.Jit's text after it. (With a CUDA device
  the variant is set, and loading a plugin refuses it: ``cpp/src/plugins.h``.)
"""

from __future__ import annotations

import functools
import importlib
from typing import Any, Callable

import mitsuba

from .names import TAGS, listed

#: Marks the wrappers, so that installing twice (a reload) does not wrap them again.
MARK = "_mitsuba_birefringent_wrapper"


def plugin_message(error: BaseException | None) -> str | None:
    """The first message of a plugin in ``error``'s chain of causes, or None."""
    seen = set()
    while error is not None and id(error) not in seen:
        seen.add(id(error))
        text = str(error)
        if text.startswith(TAGS):
            return text
        error = error.__cause__ or error.__context__
    return None


def cuda_refusal(variant: str, supported: tuple[str, ...]) -> str:
    """What the plugins say where `mi.set_variant` of a CUDA variant fails: no CUDA device."""
    return (f'variant "{variant}" needs a CUDA device and Dr.Jit found none on this machine; '
            f'{listed()} render in it on a machine with an NVIDIA GPU; here use '
            f'"llvm{variant[4:]}", or any of ' + ", ".join(v for v in supported if not v.startswith("cuda_")))


def wrap_render(render: Callable[..., Any]) -> Callable[..., Any]:
    @functools.wraps(render)
    def wrapped(*args, **kwargs):
        try:
            return render(*args, **kwargs)
        except RuntimeError as e:
            text = plugin_message(e)
            if text is None or text == str(e):
                raise
            raise RuntimeError(text) from None

    setattr(wrapped, MARK, True)
    return wrapped


def wrap_set_variant(set_variant: Callable[..., Any], supported: tuple[str, ...]) -> Callable[..., Any]:
    @functools.wraps(set_variant)
    def wrapped(*variants, **kwargs):
        try:
            return set_variant(*variants, **kwargs)
        except Exception as e:
            cuda = [v for v in variants if isinstance(v, str) and v.startswith("cuda_")]
            if not cuda:
                raise
            text = f"{cuda_refusal(cuda[0], supported)} (and Mitsuba could not set it: {e})"
            try:
                refusal = type(e)(text)
            except Exception:  # an exception type that takes other arguments
                refusal = RuntimeError(text)
            raise refusal from None

    setattr(wrapped, MARK, True)
    return wrapped


def install(supported: tuple[str, ...]) -> None:
    """Replaces ``mitsuba.render`` and ``mitsuba.set_variant`` by the wrappers above (once)."""
    if not getattr(mitsuba.set_variant, MARK, False):
        mitsuba.set_variant = wrap_set_variant(mitsuba.set_variant, supported)
    render = importlib.import_module("mitsuba.python.util").render
    if not getattr(mitsuba.__dict__.get("render"), MARK, False):
        mitsuba.render = wrap_render(render)
