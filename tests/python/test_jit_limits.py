"""The limits where Mitsuba's own plugins must agree with ours hold in the llvm variants, lobe by
lobe on batches of 100,000 lanes (random directions on both sides, both transport modes, random
wavelengths in the spectral variants), as the scalar tests check them direction by direction
(test_plugins_crystal.py, test_plugins_plate.py, test_plugins_absorbing.py):

- an isotropic crystal (eta_o = eta_e = 1.5) is `dielectric`: weight * pdf of each component;
- an absorbing isotropic one (eta + i k) is `conductor` (its reflection, front side);
- a thick isotropic plate (1000 um, incoherent) at normal incidence is `thindielectric`;
- a thin index-matched plate at normal incidence is `retarder` (Mueller matrices normalised by
  M00);
- a strongly dichroic plate is `polarizer`.

Tolerances: 1e-5 absolute on Mueller elements up to 1 (float32 arithmetic on both sides,
measured worst printed) except where a test states otherwise.
"""

from __future__ import annotations

import math

import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import LLVM, POLARIZED, batch_si, context, random_directions, sample

N = 100_000
ATOL = 1e-5
# Mitsuba's dielectric works in float32. Where Fresnel's R and T have an infinite slope in the
# angle (light inside the glass within ~1e-3 of the critical angle, cos_c = 0.74536, reflected;
# or refracted, which puts the exterior direction within |z| < 0.05 of grazing), the float32
# rounding of a direction alone (~6e-8) changes them by up to a few 1e-4 (measured worst 2.9e-4
# over 100,000 lanes; test_plugins_crystal.py compares such lanes with the f64 formula
# instead). There the bound is SENSITIVE_ATOL; everywhere else ATOL.
GRAZING, NEAR_CRITICAL, COS_CRITICAL = 0.05, 1e-3, math.sqrt(1.0 - 1.0 / 1.5**2)
SENSITIVE_ATOL = 1e-3


def lanes(seed: int, side: int = 0):
    """Directions (side 0: both hemispheres, 1: front only), wavelengths, lobe numbers."""
    rng = np.random.default_rng(seed)
    wi = random_directions(N, rng)
    if side:
        wi[:, 2] = np.abs(wi[:, 2])
    waves = rng.uniform(400.0, 700.0, size=(N, 4)).astype(np.float32)
    return wi, waves, rng.uniform(size=N).astype(np.float32)


def forced(ours, theirs, ctx_mode, component, si, u):
    """weight * pdf of both with `component` forced, and the masks of lanes with a lobe."""
    a, wa = sample(ours, context(ctx_mode, component), si, u)
    b, wb = sample(theirs, context(ctx_mode, component), si, u)
    return a, wa * a["pdf"], b, wb * b["pdf"]


@pytest.mark.parametrize("variant", LLVM)
@pytest.mark.parametrize("mode", ["radiance", "importance"])
def test_isotropic_crystal_is_dielectric(variant, mode):
    mi.set_variant(variant)
    ours = mi.load_dict({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0})
    theirs = mi.load_dict({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0})
    wi, waves, u = lanes(seed=len(variant) + (mode == "radiance"))
    si = batch_si(wi, waves)
    report = []
    for component in (0, 1):
        a, ma, b, mb = forced(ours, theirs, mode, component, si, u)
        lobe = a["pdf"] > 0
        # No lobe of ours (total internal reflection): dielectric's forced lobe carries nothing.
        assert np.abs(mb[..., ~lobe]).max(initial=0.0) <= ATOL
        exterior_z = np.where(wi[:, 2] > 0, wi[:, 2], a["wo"][:, 2])
        near_critical = (np.abs(np.abs(wi[:, 2]) - COS_CRITICAL) < NEAR_CRITICAL) & (wi[:, 2] < 0)
        sensitive = near_critical | ((np.abs(exterior_z) < GRAZING) & (component == 1))
        keep = lobe & ~sensitive
        assert np.abs(a["wo"][lobe] - b["wo"][lobe]).max() <= 1e-5
        assert np.abs(a["eta"][lobe] - b["eta"][lobe]).max() <= 1e-5
        assert np.array_equal(a["type"][lobe], b["type"][lobe])
        diff = np.abs(ma - mb).reshape(-1, N).max(axis=0)
        err, err_s = diff[keep].max(), diff[lobe & sensitive].max(initial=0.0)
        report.append(f"component {component}: {keep.sum()} lanes worst {err:.1e}, "
                      f"{(lobe & sensitive).sum()} sensitive lanes worst {err_s:.1e}")
        assert err <= ATOL and err_s <= SENSITIVE_ATOL, (err, err_s)
    print(f"{variant} {mode} vs dielectric: " + "; ".join(report))


@pytest.mark.parametrize("variant", LLVM)
def test_absorbing_isotropic_crystal_is_conductor(variant):
    mi.set_variant(variant)
    eta, k = 0.2, 3.0
    ours = mi.load_dict({"type": "birefringent", "eta_o": eta, "eta_e": eta, "kappa_o": k,
                         "kappa_e": k, "ext_ior": 1.0})
    theirs = mi.load_dict({"type": "conductor", "eta": eta, "k": k})
    wi, waves, u = lanes(seed=3, side=1)
    si = batch_si(wi, waves)
    worst = 0.0
    for mode in ("radiance", "importance"):
        a, ma, b, mb = forced(ours, theirs, mode, 0, si, u)
        assert (a["pdf"] == 1).all() and (b["pdf"] == 1).all()
        assert np.abs(a["wo"] - b["wo"]).max() <= 1e-5
        worst = max(worst, float(np.abs(ma - mb).max()))
    print(f"{variant} vs conductor: worst {worst:.1e} over 2 x {N} lanes")
    assert worst <= ATOL


@pytest.mark.parametrize("variant", ["llvm_ad_rgb", "llvm_ad_mono", "llvm_ad_spectral"])
def test_thick_isotropic_plate_is_thindielectric_at_normal_incidence(variant):
    """A 1000 um plate of index 1.5 (its etalon averaged out by a 4 nm band in the spectral
    variant, by the channel integration in the others) at normal incidence from both sides:
    R = 2r/(1+r) and T = 1 - R as thindielectric's incoherent sum (0.0769); tolerance 1e-5
    (measured worst printed)."""
    mi.set_variant(variant)
    ours = mi.load_dict({"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0,
                         "thickness": 1000.0, "filter_bandwidth": 4.0})
    theirs = mi.load_dict({"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0})
    _, waves, u = lanes(seed=4)
    wi = np.zeros((N, 3), dtype=np.float32)
    wi[:, 2] = np.where(np.arange(N) % 2 == 0, 1.0, -1.0)
    si = batch_si(wi, waves)
    worst = 0.0
    for component in (0, 1):
        a, ma, b, mb = forced(ours, theirs, "radiance", component, si, u)
        assert np.abs(a["wo"] - b["wo"]).max() <= 1e-6
        worst = max(worst, float(np.abs(ma - mb).max()))
    print(f"{variant} vs thindielectric: worst {worst:.1e}")
    assert worst <= ATOL


def normalised(w: np.ndarray) -> np.ndarray:
    return w / w[0, 0]


def test_thin_plate_is_retarder_at_normal_incidence():
    """llvm_ad_spectral_polarized, normal incidence from both sides, optic axis at random
    angles in the plate, index-matched exterior, exact spectrum: the normalised Mueller matrix
    is retarder(theta, delta = -360 (n_e - n_o) d / lambda) (test_plugins_plate.py: the optic
    axis is the slow axis). Lanes of three wavelengths, one retarder each; tolerance 2e-3 (the
    residual etalon of the e wave, ~2 R_e = 2 (dn / (2 n + dn))^2)."""
    mi.set_variant("llvm_ad_spectral_polarized")
    n_o, dn, d_um = 1.5, 0.05, 3.0
    worst = 0.0
    for theta in (0.0, 30.0, -60.0):
        t = math.radians(theta)
        ours = mi.load_dict({"type": "thinbirefringent", "eta_o": n_o, "eta_e": n_o + dn,
                             "ext_ior": n_o, "thickness": d_um, "filter_bandwidth": 0.0,
                             "optic_axis": [math.cos(t), math.sin(t), 0.0]})
        for lam in (420.0, 530.0, 640.0):
            delta = 360.0 * dn * d_um * 1000.0 / lam
            ret = mi.load_dict({"type": "retarder", "theta": theta, "delta": -delta})
            wi = np.zeros((N // 9, 3), dtype=np.float32)
            wi[:, 2] = np.where(np.arange(len(wi)) % 2 == 0, 1.0, -1.0)
            si = batch_si(wi, np.full((len(wi), 4), lam, dtype=np.float32))
            u = np.random.default_rng(int(lam)).uniform(size=len(wi)).astype(np.float32)
            a, wa = sample(ours, context("radiance", 1), si, u)
            b, wb = sample(ret, context("radiance"), si, u)
            assert np.abs(a["wo"] - b["wo"]).max() <= 1e-6
            worst = max(worst, float(np.abs(normalised(wa) - normalised(wb)).max()))
    print(f"plate vs retarder: worst {worst:.2e}")
    assert worst <= 2e-3


@pytest.mark.parametrize("variant", POLARIZED)
def test_dichroic_plate_is_polarizer(variant):
    """kappa_e = 0.05 over 60 um (the e wave's amplitude attenuated by exp(-2 pi kappa d /
    lambda) < 2e-12 at 400-700 nm: at 30 um its coherence with the o wave, M33 = 1.4e-6 at
    700 nm, would be seen) and an index-matched o wave: a linear polariser transmitting
    perpendicular to the axis, i.e. Mitsuba's polarizer(90 - theta), at normal incidence from
    both sides (M00-normalised; tolerance 1e-6, float32)."""
    mi.set_variant(variant)
    worst = 0.0
    for theta in (0.0, 30.0, 75.0):
        t = math.radians(theta)
        ours = mi.load_dict({"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5, "kappa_e": 0.05,
                             "ext_ior": 1.5, "thickness": 60.0, "filter_bandwidth": 0.0,
                             "optic_axis": [math.cos(t), math.sin(t), 0.0]})
        pol = mi.load_dict({"type": "polarizer", "theta": 90.0 - theta})
        _, waves, u = lanes(seed=int(theta) + 7)
        wi = np.zeros((N, 3), dtype=np.float32)
        wi[:, 2] = np.where(np.arange(N) % 2 == 0, 1.0, -1.0)
        si = batch_si(wi, waves)
        a, wa = sample(ours, context("radiance", 1), si, u)
        b, wb = sample(pol, context("radiance"), si, u)
        assert np.abs(a["wo"] - b["wo"]).max() <= 1e-6
        worst = max(worst, float(np.abs(normalised(wa) - normalised(wb)).max()))
    print(f"{variant}: dichroic plate vs polarizer: worst {worst:.1e}")
    assert worst <= 1e-6
