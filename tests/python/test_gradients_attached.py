"""Attached sampling (issue 23): Mitsuba's own `test06_attached_sampling` pattern
(src/bsdfs/tests/test_dielectric.py of Mitsuba 3: a surface normal turned by an angle that
carries a gradient, `sample` at that surface, the forward-mode derivative of the weight) run on
the plugins in their isotropic limits against the built-ins, with the derivative of the sampled
direction too.

- `birefringent` with eta_o = eta_e = 1.5046 (Mitsuba's `bk7`, dielectric's default) under air
  against `dielectric`: reflection (sample1 = 0, the value of Mitsuba's own test,
  0.008912204764783382) and refraction (sample1 = 0.9), in llvm_ad_rgb and (every Mueller
  entry) llvm_ad_spectral_polarized.
- `thinbirefringent` of thickness 0 between air and 1.5046 (a bare interface) against
  `dielectric`, in llvm_ad_spectral and llvm_ad_spectral_polarized (the exact plate).
- `thinbirefringent` between equal media against `thindielectric`: the straight-through
  direction and its derivative. (The weights differ by design: `thindielectric` sums the
  plate's internal reflections incoherently, the exact plate coherently, so a thin
  dielectric plate is not `thindielectric`'s limit; the bare interface above is the exact
  isotropic limit with a built-in counterpart.)

Agreement to Mitsuba's own tolerance (`dr.allclose`: 1e-5 relative), with an absolute floor of
1e-6 of the largest entry for float32 rounding; the plugins' derivatives are Dr.Jit's AD
through their replayed programs (docs/gradients.md).
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import evaluated_mode

BK7 = 1.5046
AIR = 1.000277


def attached_sample(desc: dict, sample1: float):
    """Mitsuba's test06 set-up for `desc`: (weight, d weight / d angle, wo, d wo / d angle)."""
    bsdf = mi.load_dict(desc)
    angle = mi.Float(10 * dr.pi / 180)
    dr.enable_grad(angle)
    si = mi.SurfaceInteraction3f()
    si.p = [0, 0, 0]
    si.n = [dr.sin(angle), 0, dr.cos(angle)]
    si.sh_frame = mi.Frame3f(si.n)
    si.wi = si.sh_frame.to_local([0, 0, 1])
    if mi.is_spectral:
        si.wavelengths = [450.0, 500.0, 550.0, 600.0]
    with evaluated_mode():
        bs, weight = bsdf.sample(mi.BSDFContext(), si, sample1, [0, 0])
        attached = dr.grad_enabled(weight) and dr.grad_enabled(bs.wo)
        # Edges kept: both outputs' gradients are read after one propagation.
        dr.forward(angle, dr.ADFlag.ClearNone)
        out = [np.array(x, dtype=np.float64)
               for x in (weight, dr.grad(weight), bs.wo, dr.grad(bs.wo))]
    return attached, out


def assert_same(ours, theirs):
    """Equal to Mitsuba's tolerance (1e-5 relative), with an absolute floor of 1e-6 of each
    quantity's largest entry: the built-ins compute in float32, the core in double (a Mueller
    entry that is zero came out 2.3e-8 from `dielectric`'s float rotations)."""
    for name, a, b in zip(("weight", "d weight", "wo", "d wo"), ours, theirs):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6 * np.abs(b).max(), err_msg=name)


@pytest.mark.parametrize("variant", ["llvm_ad_rgb", "llvm_ad_spectral_polarized"])
@pytest.mark.parametrize("sample1", [0.0, 0.9])
def test_birefringent_samples_as_dielectric(variant, sample1):
    mi.set_variant(variant)
    attached, theirs = attached_sample({"type": "dielectric"}, sample1)
    assert attached
    ours_attached, ours = attached_sample(
        {"type": "birefringent", "eta_o": BK7, "eta_e": BK7, "ext_ior": AIR}, sample1)
    assert ours_attached
    if sample1 == 0.0:
        # The value of Mitsuba's own test (the unpolarised weight's derivative).
        assert np.allclose(theirs[1].reshape(-1)[0], 0.008912204764783382)
    assert np.abs(theirs[1]).max() > 1e-4 and np.abs(theirs[3]).max() > 0.1
    assert_same(ours, theirs)


@pytest.mark.parametrize("variant", ["llvm_ad_spectral", "llvm_ad_spectral_polarized"])
@pytest.mark.parametrize("sample1", [0.0, 0.9])
def test_bare_interface_plate_samples_as_dielectric(variant, sample1):
    mi.set_variant(variant)
    _, theirs = attached_sample({"type": "dielectric"}, sample1)
    attached, ours = attached_sample(
        {"type": "thinbirefringent", "eta_o": 1.3, "eta_e": 1.3, "thickness": 0.0,
         "ext_ior": AIR, "exit_ior": BK7}, sample1)
    assert attached
    assert_same(ours, theirs)


def test_plate_between_equal_media_passes_straight_as_thindielectric():
    mi.set_variant("llvm_ad_spectral_polarized")
    _, theirs = attached_sample({"type": "thindielectric"}, 0.99)
    attached, ours = attached_sample(
        {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5, "thickness": 1.0}, 0.99)
    assert attached
    np.testing.assert_allclose(ours[2], theirs[2], rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(ours[3], theirs[3], rtol=1e-5, atol=1e-7)
    assert np.abs(ours[3]).max() > 0.1
