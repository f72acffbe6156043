"""Helpers of the gradient tests (tests/python/test_gradients*.py): a parameter moved along a
direction by a scalar `s`, Dr.Jit's forward- and reverse-mode derivatives with respect to `s`,
and central finite differences of the same evaluation (Richardson-extrapolated, in float32 as
Mitsuba returns it), compared where the derivative is not tiny.

The finite differences carry their own error, which the comparison adds to its tolerance
(:func:`fd_error`): the rounding of the float32 values they difference, divided by the step
(machine-dependent in its details: Dr.Jit's LLVM backend rounds differently at another vector
width, e.g. its approximate `rsqrt` is the AVX instruction with a Newton step at width 8, the
AVX-512 one at width 16, exact elsewhere), and their truncation error, estimated from the
extrapolation at twice the step. A tolerance that leaves them out holds on one machine only.

The tested function is `weight * pdf` of `bsdf.sample` (the lobe: the selection probability
cancels), or `eval_null_transmission`, lane by lane; lanes whose sampled lobe differs between the
evaluations (the choice flips within the steps) are left out of the comparison.
"""

from __future__ import annotations

from typing import NamedTuple

import drjit as dr
import mitsuba as mi
import numpy as np

from jit_helpers import evaluated_mode, floats

#: Relative tolerance of a derivative against the finite differences (the issue's bar), beside
#: an absolute floor of FLOOR times the largest derivative of the comparison ("not tiny"), and
#: beside the finite differences' own error (:func:`fd_error`).
RTOL = 1e-3
FLOOR = 1e-4

#: float32's unit roundoff.
U32 = 2.0 ** -24

#: Rounding error of a lobe's float32 value, in units of U32 times its size: the core's double
#: result rounded to float32, times the pdf rounded to float32, the product rounded.
LOBE_ULPS = 1.5

#: Rounding error of a moved direction `normalize(wi + t s)` in float32, in units of U32: the
#: sum (0.5) and Dr.Jit's normalisation (its approximate rsqrt with a Newton step, ~1.5; the
#: sum of squares, 1). A parameter moved by a power-of-two step (`x + k h`) is exact instead.
DIRECTION_ULPS = 3.0

#: The multiples of the step the finite differences evaluate at (the extrapolation at h and,
#: for its truncation error, at 2h).
STEPS = (-4, -2, -1, 1, 2, 4)


def richardson(values: dict, h: float, m: int = 1) -> np.ndarray:
    """Central differences of `values` (keyed by multiples of `h`) at steps m h and 2 m h,
    Richardson-extrapolated: `(4 D(mh) - D(2mh)) / 3`, error O(h^4)."""
    d1 = (values[m] - values[-m]) / (2 * m * h)
    d2 = (values[2 * m] - values[-2 * m]) / (4 * m * h)
    return (4 * d1 - d2) / 3


def fd_error(values: dict, h: float, rounding: np.ndarray) -> np.ndarray:
    """A bound of |richardson(values, h) - f'| where each value may be off by `rounding`
    (broadcast against the values): the extrapolation weighs the values by
    (4/3)/(2h) and (1/3)/(4h), twice each, so rounding costs at most 1.5 rounding / h; its
    truncation error c h^4 (+ O(h^6)) is |D_R(h) - D_R(2h)| / 15 to leading order, taken
    whole (a factor 15 for the higher orders, and the two extrapolations' rounding)."""
    return 1.5 * rounding / h + np.abs(richardson(values, h, 1) - richardson(values, h, 2))


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
            dr.eval(w)
            return w, None, None
        bs, w = bsdf.sample(ctx, si, u, mi.Point2f(0.5, 0.5))
        lobe = w * dr.detach(bs.pdf)
        # Every output in one kernel (the graph stays attached): read entry by entry, each
        # would be a kernel of its own, compiled anew.
        dr.eval(lobe, bs.wo, bs.sampled_component)
        wo = np.array(dr.detach(bs.wo), dtype=np.float64)
        return lobe, np.array(bs.sampled_component), wo


def as_numpy(x) -> np.ndarray:
    return np.array(x, dtype=np.float64)


class Derivatives(NamedTuple):
    """Derivatives with respect to `s` at 0 and their finite differences."""

    #: Forward-mode derivative.
    forward: np.ndarray
    #: Its finite differences (Richardson-extrapolated).
    fd: np.ndarray
    #: Reverse-mode derivative of a random projection (standard normal weights `r`).
    reverse: float
    #: Σ r fd.
    reverse_fd: float
    #: The lanes compared (a lobe's: those that keep their lobe within the steps).
    keep: np.ndarray
    #: A bound of |fd - f'| (:func:`fd_error`).
    fd_err: np.ndarray
    #: Σ |r| fd_err.
    reverse_fd_err: float


def finite_differences(values_at, h: float, ulps: float) -> tuple[np.ndarray, np.ndarray]:
    """(Richardson-extrapolated differences, their error bound) of `values_at(s)` (a numpy
    array of float32 values: an image) at the multiples STEPS of `h`, each value rounded by up
    to `ulps` U32 of the largest of them all."""
    values = {k: values_at(k * h) for k in STEPS}
    size = max(float(np.abs(v).max()) for v in values.values())
    return richardson(values, h), fd_error(values, h, np.asarray(ulps * U32 * size))


def derivatives(make, h: float, null: bool = False, seed: int = 7,
                direction: bool = False) -> Derivatives:
    """The derivatives of the lobe of every lane (arrays as (..., lanes), with the lanes whose
    choice flips zeroed). `direction`: `s` turns a unit vector (its float32 rounding moves the
    value by up to DIRECTION_ULPS U32 times the derivative)."""
    # Finite differences: s = +-h, +-2h, Richardson-extrapolated (error O(h^4)); +-4h for the
    # estimate of that error.
    vals = {}
    for k in STEPS:
        w, comp, pdf = evaluate(make, step(k * h), null)
        vals[k] = (as_numpy(w), comp, pdf)
    base, comp0, wo0 = evaluate(make, step(0.0), null)
    values = {k: v[0] for k, v in vals.items()}
    fd = richardson(values, h)
    size = np.max([np.abs(v) for v in values.values()], axis=0)
    err = fd_error(values, h, U32 * (LOBE_ULPS * size + (DIRECTION_ULPS if direction else 0.0) * np.abs(fd)))
    # The same lobe: the same component, in nearly the same direction (a crystal's reflections
    # into o and e share component 0).
    keep = np.ones(fd.shape[-1], dtype=bool)
    if comp0 is not None:
        for k in vals:
            keep &= (vals[k][1] == comp0) & (np.abs(vals[k][2] - wo0).max(axis=0) < 0.05)
    fd = np.where(keep, fd, 0.0)
    err = np.where(keep, err, 0.0)
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
    return Derivatives(ad, fd, reverse, float((fd * r).sum()), keep, err,
                       float((np.abs(r) * err).sum()))


def projection(w, r: np.ndarray):
    """Σ w ⊙ r over every entry and lane (w a Dr.Jit spectrum or Mueller matrix of lanes)."""
    total = mi.Float(0.0)
    if r.ndim == 4:  # (4, 4, channels, lanes)
        for i in range(4):
            for j in range(4):
                for c in range(r.shape[2]):
                    total += dr.sum(w[i, j][c] * floats(r[i, j, c]))
    else:  # (channels, lanes)
        for c in range(r.shape[0]):
            total += dr.sum(w[c] * floats(r[c]))
    return total


def check(d: Derivatives, rtol: float = RTOL, min_lanes: int = 8) -> None:
    """Forward mode agrees with the finite differences entry by entry and lane by lane, and
    reverse mode with the projection of the finite differences, within `rtol` where the
    derivative is not tiny, beyond the finite differences' own error (which must stay below
    RTOL of the largest derivative, else the step does not resolve the bar)."""
    assert d.keep.sum() >= min_lanes, f"only {d.keep.sum()} lanes keep their lobe"
    scale = np.abs(d.fd).max()
    assert scale > 1e-6, "the derivative is zero"
    assert d.fd_err.max() <= rtol * scale, (
        f"the finite differences' error {d.fd_err.max():.2e} exceeds {rtol} of the largest "
        f"derivative {scale:.2e}: the step does not resolve it")
    err = np.abs(d.forward - d.fd)
    bound = rtol * np.abs(d.fd) + FLOOR * scale + d.fd_err
    print(f"largest derivative {scale:.3g}; error bound of the finite differences "
          f"{d.fd_err.max() / scale:.1e} of it; forward mode's error {(err / bound).max():.3f} "
          "of its bound")
    worst = np.unravel_index(np.argmax(err - bound), err.shape)
    assert np.all(err <= bound), (
        f"forward mode {d.forward[worst]} vs finite differences {d.fd[worst]} at {worst} "
        f"(largest derivative {scale}, error of the differences {d.fd_err[worst]:.2e})")
    reverse_bound = rtol * abs(d.reverse_fd) + FLOOR * np.abs(d.fd).sum() + d.reverse_fd_err
    assert abs(d.reverse - d.reverse_fd) <= reverse_bound, (
        f"reverse mode {d.reverse} vs {d.reverse_fd}")
