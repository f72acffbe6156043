"""Helpers of the gradient tests (tests/python/test_gradients*.py): a parameter moved along a
direction by a scalar `s`, Dr.Jit's forward- and reverse-mode derivatives with respect to `s`,
and central finite differences of the same evaluation (Richardson-extrapolated, in float32 as
Mitsuba returns it), compared where the derivative is not tiny.

The tested function is `weight * pdf` of `bsdf.sample` (the lobe: the selection probability
cancels), or `eval_null_transmission`, lane by lane; lanes whose sampled lobe differs between the
evaluations (the choice flips within the steps) are left out of the comparison.
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np

from jit_helpers import evaluated_mode

#: Relative tolerance of a derivative against the finite differences (the issue's bar), beside
#: an absolute floor of FLOOR times the largest derivative of the comparison ("not tiny").
RTOL = 1e-3
FLOOR = 1e-4


def moved(params, keys: str, direction, s):
    """Sets each of `params[key]` (keys separated by "+") to its value plus `direction * s` (a
    Float, Vector3f or TensorXf), then updates once. The new values are opaque (held in memory,
    as an optimiser's are), so that every step runs the same kernel: a literal value would be
    compiled into a kernel of its own."""
    for key in keys.split("+"):
        value = params[key]
        new = type(value)(value) + direction * s
        dr.make_opaque(new)
        params[key] = new
    params.update()


def step(value: float):
    """The parameter `s` of one evaluation: opaque and carrying gradients (as in the AD
    evaluations), so that the finite differences run the kernel the derivatives run."""
    s = dr.opaque(mi.Float, value)
    dr.enable_grad(s)
    return s


def evaluate(make, s, null: bool = False):
    """`make(s)` -> (bsdf, si, u, ctx); returns (lobe as a Dr.Jit array with gradients,
    component, wo) of every lane: weight * detach(pdf) (sample) or the null transmission."""
    with evaluated_mode():
        bsdf, si, u, ctx = make(s)
        if null:
            w = bsdf.eval_null_transmission(si)
            return w, None, None
        bs, w = bsdf.sample(ctx, si, u, mi.Point2f(0.5, 0.5))
        wo = np.array(dr.detach(bs.wo), dtype=np.float64)
        return w * dr.detach(bs.pdf), np.array(bs.sampled_component), wo


def as_numpy(x) -> np.ndarray:
    return np.array(x, dtype=np.float64)


def derivatives(make, h: float, null: bool = False, seed: int = 7):
    """(forward-mode AD, finite differences, reverse-mode AD, finite differences of the same
    random projection) of the lobe of every lane with respect to `s` at 0; the first two as
    (..., lanes) arrays with the lanes whose choice flips zeroed in both."""
    # Finite differences: s = +-h, +-2h, Richardson-extrapolated (error O(h^4)).
    vals = {}
    for k in (-2, -1, 1, 2):
        w, comp, pdf = evaluate(make, step(k * h), null)
        vals[k] = (as_numpy(w), comp, pdf)
    base, comp0, wo0 = evaluate(make, step(0.0), null)
    d1 = (vals[1][0] - vals[-1][0]) / (2 * h)
    d2 = (vals[2][0] - vals[-2][0]) / (4 * h)
    fd = (4 * d1 - d2) / 3
    # The same lobe: the same component, in nearly the same direction (a crystal's reflections
    # into o and e share component 0).
    keep = np.ones(fd.shape[-1], dtype=bool)
    if comp0 is not None:
        for k in vals:
            keep &= (vals[k][1] == comp0) & (np.abs(vals[k][2] - wo0).max(axis=0) < 0.05)
    fd = np.where(keep, fd, 0.0)
    # Forward mode.
    s = step(0.0)
    w, _, _ = evaluate(make, s, null)
    dr.forward(s)
    ad = np.where(keep, as_numpy(dr.grad(w)), 0.0)
    # Reverse mode: the gradient of a random projection of the lanes that keep their choice.
    rng = np.random.default_rng(seed)
    r = np.where(keep, rng.normal(size=fd.shape), 0.0)
    s = step(0.0)
    w, _, _ = evaluate(make, s, null)
    loss = projection(w, r)
    dr.backward(loss)
    reverse = float(dr.grad(s)[0])
    return ad, fd, reverse, float((fd * r).sum()), keep


def projection(w, r: np.ndarray):
    """Σ w ⊙ r over every entry and lane (w a Dr.Jit spectrum or Mueller matrix of lanes)."""
    total = mi.Float(0.0)
    if r.ndim == 4:  # (4, 4, channels, lanes)
        for i in range(4):
            for j in range(4):
                for c in range(r.shape[2]):
                    total += dr.sum(w[i, j][c] * mi.Float(r[i, j, c].astype(np.float32)))
    else:  # (channels, lanes)
        for c in range(r.shape[0]):
            total += dr.sum(w[c] * mi.Float(r[c].astype(np.float32)))
    return total


def check(ad: np.ndarray, fd: np.ndarray, reverse: float, reverse_fd: float, keep,
          rtol: float = RTOL, min_lanes: int = 8) -> None:
    """Forward mode agrees with the finite differences entry by entry and lane by lane, and
    reverse mode with the projection of the finite differences, within `rtol` where the
    derivative is not tiny."""
    assert keep.sum() >= min_lanes, f"only {keep.sum()} lanes keep their lobe"
    scale = np.abs(fd).max()
    assert scale > 1e-6, "the derivative is zero"
    err = np.abs(ad - fd)
    bound = rtol * np.abs(fd) + FLOOR * scale
    worst = np.unravel_index(np.argmax(err - bound), err.shape)
    assert np.all(err <= bound), (
        f"forward mode {ad[worst]} vs finite differences {fd[worst]} at {worst} "
        f"(largest derivative {scale})")
    assert abs(reverse - reverse_fd) <= rtol * abs(reverse_fd) + FLOOR * np.abs(fd).sum(), (
        f"reverse mode {reverse} vs {reverse_fd}")
