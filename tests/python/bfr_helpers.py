"""Helpers of the plugin tests (tests/python/test_plugins*.py): surface interactions, contexts,
random directions and conversions of Mitsuba's spectra to numpy.

Importing this module imports mitsuba and mitsuba_birefringent (which registers the plugins).
"""

from __future__ import annotations

import math

import drjit as dr
import mitsuba as mi
import numpy as np

import mitsuba_birefringent  # noqa: F401  (registers thinbirefringent and birefringent)

POLARIZED = "scalar_spectral_polarized"
WAVELENGTHS = (450.0, 500.0, 550.0, 600.0)


def variant(name: str) -> None:
    mi.set_variant(name)


def surface_interaction(wi, wavelengths=WAVELENGTHS, uv=(0.5, 0.5)):
    """A local-frame surface interaction (normal +z) seen from ``wi`` (unit, local)."""
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.n = mi.Normal3f(0, 0, 1)
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = mi.Vector3f(*[float(x) for x in wi])
    si.uv = mi.Point2f(*uv)
    if mi.is_spectral:
        si.wavelengths = mi.UnpolarizedSpectrum(*[float(x) for x in wavelengths])
    return si


def context(mode: str = "radiance", component: int | None = None) -> mi.BSDFContext:
    ctx = mi.BSDFContext(mi.TransportMode.Radiance if mode == "radiance" else mi.TransportMode.Importance)
    if component is not None:
        ctx.component = component
    return ctx


def random_directions(n: int, seed: int, min_abs_cos: float = 1e-3) -> np.ndarray:
    """``n`` unit vectors uniform on the sphere (both hemispheres), avoiding grazing ones."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        v = rng.normal(size=3)
        v /= np.linalg.norm(v)
        if abs(v[2]) >= min_abs_cos:
            out.append(v)
    return np.array(out)


def direction(theta_deg: float, phi_deg: float = 0.0, side: int = 1) -> np.ndarray:
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), side * math.cos(t)])


def as_array(spectrum) -> np.ndarray:
    """Polarized: (4, 4, wavelengths) Mueller matrices [row, col, lambda]; else (channels,)."""
    return np.array(spectrum, dtype=np.float64)


def sample(bsdf, ctx, si, sample1: float = 0.5):
    """(bs, weight as numpy) of ``bsdf.sample``."""
    bs, w = bsdf.sample(ctx, si, float(sample1), mi.Point2f(0.5, 0.5))
    return bs, as_array(w)


def wo_of(bs) -> np.ndarray:
    return np.array([bs.wo.x, bs.wo.y, bs.wo.z], dtype=np.float64)


def lobes(bsdf, ctx, si):
    """Every lobe ``sample`` can return, as a list of (component, wo, weight * pdf, eta), found
    by walking ``sample1`` through the selection CDF: lobes are picked in a fixed order, each
    over an interval of length pdf. Lobes of probability below ~1e-6 may be missed."""
    found, acc, u = [], 0.0, 1e-7
    while u < 1.0:
        bs, w = sample(bsdf, ctx, si, u)
        p = float(bs.pdf)
        if not p > 0:
            break
        wo, m = wo_of(bs), w * p
        # The previous lobe again (float rounding at an interval boundary): step over it. Two
        # distinct lobes may share a component and a direction, not also their matrix.
        if any(c == bs.sampled_component and np.allclose(wo, d, atol=1e-6) and np.allclose(m, m2, atol=1e-9)
               for c, d, m2, _ in found):
            u += 1e-6
            continue
        found.append((int(bs.sampled_component), wo, m, float(bs.eta)))
        acc += p
        u = max(u, acc) + 1e-7
    return found


Q = np.diag([1.0, 1.0, -1.0, 1.0])


def reciprocal(m: np.ndarray) -> np.ndarray:
    """Q M^T Q, the matrix of the reversed path of a reciprocal element (per wavelength)."""
    return np.einsum("ij,kjl,km->iml", Q, m, Q)
