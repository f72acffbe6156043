"""Helpers of the JIT-variant tests (tests/python/test_jit_*.py): the llvm variants and their
scalar counterparts, vectorised surface interactions, numpy views of batch results, and the
block-wise Welch statistic of the scene comparisons.

The llvm variants need Debian's libllvm19 (`make setup` installs it) and the plugins need
Dr.Jit's evaluated mode (`mitsuba_birefringent.evaluated_mode()`).
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401  (registers the plugins)
from mitsuba_birefringent import evaluated_mode  # noqa: F401  (re-exported for the tests)

#: The llvm variants the plugins work in.
LLVM = ("llvm_ad_rgb", "llvm_ad_mono", "llvm_ad_mono_polarized", "llvm_ad_spectral",
        "llvm_ad_spectral_polarized")
POLARIZED = ("llvm_ad_mono_polarized", "llvm_ad_spectral_polarized")


def scalar_counterpart(variant: str) -> str | None:
    """The scalar variant with the same spectrum type (none for the mono variants: the wheel
    has no scalar mono variant)."""
    name = "scalar_" + variant.removeprefix("llvm_ad_")
    return name if name in mi.variants() else None


def random_directions(n: int, rng: np.random.Generator, min_abs_cos: float = 1e-3) -> np.ndarray:
    """`n` unit vectors uniform on the sphere (both hemispheres), none within `min_abs_cos` of
    grazing, rounded to float32 and renormalised in float64."""
    d = rng.normal(size=(2 * n + 100, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    d = d[np.abs(d[:, 2]) >= min_abs_cos][:n].astype(np.float32)
    return d


def floats(x: np.ndarray):
    """A Dr.Jit Float of the values `x`, in memory Dr.Jit allocated and aligned. An array made
    from numpy's memory may be unaligned (a slice, a column), and Dr.Jit then compiles another
    kernel for that input's alignment (a large one per evaluation, about a second each on a
    recorded program): `dr.copy` and an identity gather keep the unaligned memory, building from
    Python numbers does not."""
    f = mi.Float(np.asarray(x, dtype=np.float32).ravel().tolist())
    dr.eval(f)
    return f


def batch_si(wi: np.ndarray, wavelengths: np.ndarray | None = None, uv: np.ndarray | None = None):
    """A surface interaction of len(wi) lanes in the local frame (normal +z), seen from `wi`;
    `wavelengths` (lanes x 4, nm) in spectral variants; `uv` (lanes x 2) for textures."""
    n = len(wi)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(*[floats(wi[:, k]) for k in range(3)])
    if uv is not None:
        si.uv = mi.Point2f(floats(uv[:, 0]), floats(uv[:, 1]))
    if mi.is_spectral:
        w = wavelengths if wavelengths is not None else np.tile([450.0, 500.0, 550.0, 600.0], (n, 1))
        si.wavelengths = mi.UnpolarizedSpectrum(*[floats(w[:, k]) for k in range(4)])
    return si


def context(mode: str = "radiance", component: int | None = None) -> mi.BSDFContext:
    ctx = mi.BSDFContext(mi.TransportMode.Radiance if mode == "radiance" else mi.TransportMode.Importance)
    if component is not None:
        ctx.component = component
    return ctx


def sample(bsdf, ctx, si, u: np.ndarray):
    """`bsdf.sample` of every lane with lobe numbers `u`, in evaluated mode: (dict of numpy
    arrays wo (lanes x 3), pdf, eta, component, type; the weight as numpy: polarized
    (4, 4, channels, lanes), else (channels, lanes)). Values Dr.Jit returns as one literal for
    all lanes are broadcast."""
    n = len(u)
    lanes = lambda x: np.broadcast_to(np.array(x), np.array(x).shape[:-1] + (n,))  # noqa: E731
    with evaluated_mode():
        bs, w = bsdf.sample(ctx, si, floats(u), mi.Point2f(0.5, 0.5))
        dr.eval(bs, w)  # one kernel for every output (read one by one: a kernel each)
        out = {"wo": lanes(bs.wo).T, "pdf": lanes(bs.pdf), "eta": lanes(bs.eta),
               "component": lanes(bs.sampled_component), "type": lanes(bs.sampled_type)}
        return out, lanes(w)


def m00(w: np.ndarray) -> np.ndarray:
    """The unpolarised part of a weight: (channels, lanes)."""
    return w[0, 0] if w.ndim == 4 else w


def max_z(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |Welch statistic| over the cells of two stacks of independent renders (axis 0)."""
    se2 = lambda x: x.var(axis=0, ddof=1) / len(x)
    return float(np.abs((a.mean(0) - b.mean(0)) / np.sqrt(se2(a) + se2(b) + 1e-30)).max())


def blocks(img: np.ndarray, block: int) -> np.ndarray:
    """Means of block x block pixel blocks of an (H, W, C) image: (H/block, W/block, C)."""
    h, w, c = img.shape
    return img.reshape(h // block, block, w // block, block, c).mean(axis=(1, 3))


def render_stack(scene, renders: int, seed0: int = 0, spp: int | None = None) -> np.ndarray:
    """`renders` independent renders of `scene` (seeds seed0, seed0 + 1, ...), in evaluated mode
    in the JIT variants: (renders, H, W, C)."""
    out = []
    with evaluated_mode():
        for s in range(renders):
            img = np.array(mi.render(scene, seed=seed0 + s, spp=spp or 0), dtype=np.float64)
            out.append(img if img.ndim == 3 else img[..., None])
    return np.array(out)
