"""The `birefringent` plugin (surface of a bulk uniaxial crystal) driven through Mitsuba.

Isotropic limits against Mitsuba's own `dielectric` and `conductor` (Mueller matrices including
the S3 terms, both sides, both transport modes), flags and components, energy conservation and
reciprocity of a calcite surface, and the variant rules.
"""

from __future__ import annotations

import numpy as np
import pytest

import mitsuba as mi

from bfr_helpers import (
    POLARIZED,
    context,
    direction,
    lobes,
    random_directions,
    reciprocal,
    sample,
    surface_interaction,
    variant,
    wo_of,
)

N_DIRECTIONS = 1000
ATOL = 1e-5


def isotropic_pair():
    ours = mi.load_dict({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0})
    theirs = mi.load_dict({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0})
    return ours, theirs


def fresnel_t(cos_i: float, eta: float = 1.5) -> float:
    """Unpolarised power transmittance of a clear interface, light from the index-1 side at
    cos_i (f64 textbook formula; the same from the other side at the refracted angle)."""
    ct = np.sqrt(1 - (1 - cos_i * cos_i) / eta**2)
    rs = (cos_i - eta * ct) / (cos_i + eta * ct)
    rp = (eta * cos_i - ct) / (eta * cos_i + ct)
    return 1 - 0.5 * (rs * rs + rp * rp)


# Mitsuba's dielectric works in float32. Light refracted out of the glass at a grazing exterior
# angle left the glass near its critical angle, where T(cos) has an infinite slope: there the
# float32 rounding of Mitsuba's refracted direction alone changes its T by up to ~5e-5 (e.g.
# wi.z = 0.00253: f64 Fresnel 0.0064821029, this plugin 0.0064821029, dielectric 0.0064294).
# Those directions (|wi.z| < GRAZING) are compared to the f64 formula instead.
GRAZING = 0.02


@pytest.mark.parametrize("mode", ["radiance", "importance"])
def test_isotropic_crystal_equals_dielectric(mode):
    """eta_o = eta_e = 1.5: each component's weight * pdf equals `dielectric`'s (all 16 Mueller
    elements at 4 wavelengths, max abs difference <= 1e-5), with the same direction, eta and
    sampled type, over 1000 random directions on both sides: components forced (0, 1) and
    sampled freely (compared with dielectric forced to the component we sampled)."""
    variant(POLARIZED)
    ours, theirs = isotropic_pair()
    worst = {0: 0.0, 1: 0.0, None: 0.0}
    compared = {0: 0, 1: 0, None: 0}
    grazing = 0
    for k, wi in enumerate(random_directions(N_DIRECTIONS, seed=1 + (mode == "importance"))):
        si = surface_interaction(wi)
        u = (k + 0.5) / N_DIRECTIONS
        for component in (0, 1, None):
            bs, w = sample(ours, context(mode, component), si, u)
            if component is None:
                if not bs.pdf > 0:
                    continue
                # Same lobe forced in dielectric: weight * pdf cancels the selection probability.
                forced = int(bs.sampled_component)
            else:
                forced = component
            bs_d, w_d = sample(theirs, context(mode, forced), si, u)
            ours_m = w * float(bs.pdf)
            theirs_m = w_d * float(bs_d.pdf)
            if not bs.pdf > 0:
                # No lobe (total internal reflection): dielectric returns a zero matrix.
                assert np.abs(theirs_m).max() <= ATOL, (wi, component)
                continue
            assert int(bs.sampled_component) == forced
            assert int(bs.sampled_type) == int(bs_d.sampled_type)
            np.testing.assert_allclose(wo_of(bs), wo_of(bs_d), atol=1e-5)
            assert float(bs.eta) == pytest.approx(float(bs_d.eta), abs=1e-5)
            if abs(wi[2]) < GRAZING and forced == 1:
                grazing += 1
                cos_out = abs(wi[2]) if wi[2] > 0 else abs(wo_of(bs)[2])
                factor = {"radiance": (1 / 1.5 if wi[2] > 0 else 1.5) ** 2, "importance": 1.0}[mode]
                assert ours_m[0, 0] == pytest.approx(np.full(4, fresnel_t(cos_out) * factor), abs=1e-7)
                continue
            compared[component] += 1
            err = np.abs(ours_m - theirs_m).max()
            worst[component] = max(worst[component], err)
            assert err <= ATOL, (mode, component, wi, ours_m[..., 0], theirs_m[..., 0])
    print(f"{mode}: max |ours - dielectric| per component (None = sampled) {worst}, "
          f"lobes compared {compared}, grazing transmissions checked against f64 Fresnel {grazing}")
    # ~37 % of the inside directions are beyond the critical angle (no transmission)
    assert compared[0] == N_DIRECTIONS and compared[1] > 0.55 * N_DIRECTIONS


@pytest.mark.parametrize("mode", ["radiance", "importance"])
@pytest.mark.parametrize("eta,k", [(0.2, 3.0), (1.5, 0.5), (2.5, 0.05)])
def test_absorbing_isotropic_reflection_equals_conductor(mode, eta, k):
    """Complex eta_o = eta_e = eta + i k, exterior index 1: the reflected lobe equals
    `conductor` with the same eta and k (front side: the conductor is one-sided)."""
    variant(POLARIZED)
    ours = mi.load_dict({"type": "birefringent", "eta_o": eta, "eta_e": eta, "kappa_o": k,
                         "kappa_e": k, "ext_ior": 1.0})
    theirs = mi.load_dict({"type": "conductor", "eta": eta, "k": k})
    worst = 0.0
    for wi in random_directions(N_DIRECTIONS, seed=3):
        wi = wi * np.sign(wi[2])
        si = surface_interaction(wi)
        bs, w = sample(ours, context(mode, 0), si, 0.5)
        bs_c, w_c = sample(theirs, context(mode, 0), si, 0.5)
        np.testing.assert_allclose(wo_of(bs), wo_of(bs_c), atol=1e-5)
        err = np.abs(w * float(bs.pdf) - w_c * float(bs_c.pdf)).max()
        worst = max(worst, err)
        assert err <= ATOL, (wi, w[..., 0], w_c[..., 0])
    print(f"eta {eta} + {k}i, {mode}: max |ours - conductor| = {worst:.2e}")


def test_flags_and_components():
    variant(POLARIZED)
    b = mi.load_dict({"type": "birefringent", "material": "calcite", "optic_axis": [0.3, 0.2, 0.9]})
    F = mi.BSDFFlags
    sides = F.FrontSide | F.BackSide | F.Anisotropic
    assert b.component_count() == 3
    # Inside calcite a reflection that converts o into e is between different ray indices.
    assert b.flags(0) == F.DeltaReflection | sides | F.NonSymmetric
    assert b.flags(1) == F.DeltaTransmission | sides | F.NonSymmetric
    assert b.flags(2) == F.DeltaTransmission | sides | F.NonSymmetric
    assert b.flags() == b.flags(0) | b.flags(1) | b.flags(2)
    # eval and pdf of delta lobes are zero, like Mitsuba's delta BSDFs
    si = surface_interaction(direction(30, 20))
    bs, _ = sample(b, context(), si, 0.9)
    assert float(b.pdf(context(), si, bs.wo)) == 0.0
    assert np.abs(np.array(b.eval(context(), si, bs.wo))).max() == 0.0
    iso = mi.load_dict({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5})
    assert not iso.flags() & F.Anisotropic


@pytest.mark.parametrize("kind", ["isotropic", "calcite"])
def test_non_symmetric_flag_matches_the_transport_modes(kind):
    """A component is NonSymmetric exactly when the Radiance and Importance weights of one of
    its lobes differ (the radiance factor (n_wi / n_wo)^2 of a lobe between different ray
    indices: every refraction, and inside calcite the reflections that convert o into e), and
    the flags of an isotropic crystal are those of Mitsuba's `dielectric`. Every lobe from
    both sides at 30 degrees, matched by component and direction: a symmetric lobe's two
    weights agree to float rounding (< 1e-6 relative), a non-symmetric one's differ by more
    than 0.5 % here (the smallest: an o -> e reflection inside calcite, ratio 1.00996). An
    isotropic crystal has no component 2 lobe (its refraction is component 1) and is compared
    on components 0 and 1."""
    variant(POLARIZED)
    F = mi.BSDFFlags
    params = {"eta_o": 1.5, "eta_e": 1.5} if kind == "isotropic" else {"material": "calcite"}
    b = mi.load_dict({"type": "birefringent", "ext_ior": 1.0, "optic_axis": [0.3, 0.2, 0.9], **params})
    if kind == "isotropic":
        d = mi.load_dict({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0})
        assert [b.flags(c) for c in (0, 1)] == [d.flags(c) for c in (0, 1)]
    differs = {}
    for side in (1, -1):
        si = surface_interaction(direction(30, 20, side))
        rad, imp = lobes(b, context("radiance"), si), lobes(b, context("importance"), si)
        assert len(rad) == len(imp)
        for c, wo, m, _ in rad:
            (m_i,) = [m2 for c2, wo2, m2, _ in imp if c2 == c and np.allclose(wo, wo2, atol=1e-6)]
            ratio = m[0, 0, 0] / m_i[0, 0, 0]
            assert abs(ratio - 1.0) < 1e-6 or abs(ratio - 1.0) > 5e-3, ratio
            differs[c] = differs.get(c, False) or abs(ratio - 1.0) > 5e-3
    assert sorted(differs) == ([0, 1] if kind == "isotropic" else [0, 1, 2])
    assert differs == {c: mi.has_flag(b.flags(c), F.NonSymmetric) for c in differs}


@pytest.mark.parametrize("side", [1, -1])
def test_calcite_components_and_energy(side):
    """Calcite seen from outside: one reflected, one ordinary, one extraordinary lobe, each
    selectable through ctx.component; from inside up to six lobes. In Importance mode the
    weights are power fractions: unpolarised light loses none (calcite is clear)."""
    variant(POLARIZED)
    b = mi.load_dict({"type": "birefringent", "material": "calcite",
                      "optic_axis": [0.42, 0.1, 0.9], "ext_ior": 1.0})
    for theta in (0, 20, 45, 70):
        # one wavelength in all 4 slots: no dispersion, every lobe keeps every slot
        si = surface_interaction(direction(theta, 35, side), wavelengths=[550.0] * 4)
        found = lobes(b, context("importance"), si)
        comps = sorted(c for c, _, _, _ in found)
        if side == 1:
            assert comps == [0, 1, 2], theta
            for c in (0, 1, 2):  # forcing a component returns that lobe alone, pdf 1
                bs, w = sample(b, context("importance", c), si, 0.5)
                assert int(bs.sampled_component) == c and float(bs.pdf) == 1.0
        total = sum(m[0, 0] for _, _, m, _ in found)
        np.testing.assert_allclose(total, 1.0, atol=1e-5, err_msg=f"theta {theta}, {comps}")


@pytest.mark.parametrize("side", [1, -1])
@pytest.mark.parametrize("mode", ["radiance", "importance"])
def test_dispersive_lobes_follow_the_hero_wavelength(mode, side):
    """Calcite is dispersive: the refracted directions differ per wavelength. A lobe follows
    the first (hero) wavelength's direction and every wavelength carries its own lobe's weight
    (M00, invariant under the frame rotation): compared with the same query at each wavelength
    alone. Per wavelength, the sum over lobes of weight * pdf is that wavelength's total."""
    variant(POLARIZED)
    b = mi.load_dict({"type": "birefringent", "material": "calcite",
                      "optic_axis": [0.42, 0.1, 0.9], "ext_ior": 1.0})
    wl = [430.0, 520.0, 610.0, 700.0]
    for theta in (10, 30, 50):
        wi = direction(theta, 35, side)
        found = lobes(b, context(mode), surface_interaction(wi, wavelengths=wl))
        alone = [lobes(b, context(mode), surface_interaction(wi, wavelengths=[x] * 4)) for x in wl]
        assert len(found) == len(alone[0])
        for k, x in enumerate(wl):
            total = sum(m[0, 0, k] for _, _, m, _ in found)
            expected = sum(m[0, 0, 0] for _, _, m, _ in alone[k])
            assert total == pytest.approx(expected, abs=1e-5), (theta, x)
        for c, d, m, eta in found:  # hero: the lobe of the first wavelength, exactly
            same = [m0 for c0, d0, m0, _ in alone[0] if c0 == c and np.allclose(d0, d, atol=1e-6)]
            assert len(same) == 1
            np.testing.assert_allclose(m[..., 0], same[0][..., 0], atol=1e-5)
            if c > 0 and side == 1:  # refraction into the crystal: dispersive, other wavelengths
                for k in (1, 2, 3):  # carry their own weight (their own direction differs)
                    own = [m0[0, 0, 0] for c0, _, m0, _ in alone[k] if c0 == c]
                    assert m[0, 0, k] == pytest.approx(own[0], abs=1e-5)


@pytest.mark.parametrize("seed", [5, 6])
def test_calcite_reciprocity(seed):
    """For each lobe, the Importance matrix from wi to wo equals Q M^T Q of the Radiance matrix
    of the same pair (normalised by M00: Radiance carries the (n_wi/n_wo)^2 factor)."""
    variant(POLARIZED)
    b = mi.load_dict({"type": "birefringent", "material": "calcite",
                      "optic_axis": [0.42, 0.1, 0.9], "ext_ior": 1.0})
    worst, pairs = 0.0, 0
    for wi in random_directions(40, seed=seed, min_abs_cos=0.05):
        si = surface_interaction(wi)
        rad = lobes(b, context("radiance"), si)
        imp = lobes(b, context("importance"), si)
        assert len(rad) == len(imp), (wi, [(c, d) for c, d, _, _ in rad], [(c, d) for c, d, _, _ in imp])
        for c, d, m_r, _ in rad:
            match = [m for c2, d2, m, _ in imp if c2 == c and np.allclose(d, d2, atol=1e-5)]
            assert len(match) == 1, (wi, c, d)
            m_i, m_r = match[0][..., :1], m_r[..., :1]  # the hero wavelength (dispersion)
            if m_r[0, 0, 0] < 1e-6:
                continue
            a = m_i / m_i[0, 0]
            r = reciprocal(m_r / m_r[0, 0])
            worst = max(worst, np.abs(a - r).max())
            pairs += 1
    print(f"calcite reciprocity: {pairs} lobe pairs, max error {worst:.2e}")
    assert worst <= 1e-4


@pytest.mark.parametrize("name", ["scalar_rgb", "scalar_spectral"])
def test_unpolarized_variants(name):
    """Double refraction needs the polarized variant: loading names the variants that work.
    An isotropic material works in every variant and gives dielectric's weight."""
    variant(name)
    with pytest.raises(RuntimeError, match="scalar_spectral_polarized"):
        mi.load_dict({"type": "birefringent", "material": "calcite"})
    with pytest.raises(RuntimeError, match="scalar_spectral_polarized"):
        mi.load_dict({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.6})
    ours, theirs = isotropic_pair()
    for wi in random_directions(200, seed=7):
        si = surface_interaction(wi)
        for mode in ("radiance", "importance"):
            for component in (0, 1):
                bs, w = sample(ours, context(mode, component), si)
                bs_d, w_d = sample(theirs, context(mode, component), si)
                np.testing.assert_allclose(w * float(bs.pdf), w_d * float(bs_d.pdf), atol=ATOL)


def test_optic_axis_in_world_space():
    """optic_axis_space = "world": the axis is converted into each hit's shading frame."""
    variant(POLARIZED)
    axis = np.array([0.42, 0.1, 0.9])
    world = mi.load_dict({"type": "birefringent", "material": "calcite", "optic_axis": list(axis),
                          "optic_axis_space": "world"})
    frame = mi.Frame3f(mi.Vector3f(0.3, -0.5, 0.81))
    local_axis = frame.to_local(mi.Vector3f(*axis))
    local = mi.load_dict({"type": "birefringent", "material": "calcite",
                          "optic_axis": [local_axis.x, local_axis.y, local_axis.z]})
    for wi in random_directions(20, seed=8):
        si = surface_interaction(wi)
        si.sh_frame = frame
        si_local = surface_interaction(wi)
        for c in (0, 1, 2):
            bs_w, w_w = sample(world, context(component=c), si)
            bs_l, w_l = sample(local, context(component=c), si_local)
            np.testing.assert_allclose(wo_of(bs_w), wo_of(bs_l), atol=1e-6)
            np.testing.assert_allclose(w_w, w_l, atol=1e-5)
    with pytest.raises(RuntimeError, match="optic_axis_space"):
        mi.load_dict({"type": "birefringent", "optic_axis_space": "object"})


def test_traverse_and_to_string():
    variant(POLARIZED)
    b = mi.load_dict({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0})
    text = str(b)
    for key in ("eta_o", "eta_e", "kappa_o", "ext_ior", "optic_axis"):
        assert key in text
    params = mi.traverse(b)
    for key in ("eta_o", "eta_e", "kappa_o", "kappa_e", "ext_ior", "optic_axis"):
        assert key in params
    si = surface_interaction(direction(0))
    _, before = sample(b, context(component=0), si)
    params["eta_o"] = 2.0
    params["eta_e"] = 2.0
    params.update()
    _, after = sample(b, context(component=0), si)
    assert before[0, 0, 0] == pytest.approx(0.04, abs=1e-6)
    assert after[0, 0, 0] == pytest.approx(1 / 9, abs=1e-6)


def test_render_a_calcite_block():
    """Smoke test: a calcite cube in front of a light renders finite, positive Stokes images
    with path tracing (double refraction inside the cube)."""
    variant(POLARIZED)
    T = mi.ScalarTransform4f
    scene = mi.load_dict({
        "type": "scene",
        "integrator": {"type": "stokes", "nested": {"type": "path", "max_depth": 10}},
        "sensor": {"type": "perspective", "fov": 30.0,
                   "to_world": T().look_at(origin=[0, 0, 6], target=[0, 0, 0], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": 8, "height": 8, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 8}},
        "light": {"type": "rectangle", "to_world": T().translate([0, 0, -3]).scale(4),
                  "emitter": {"type": "area", "radiance": {"type": "d65"}}},
        "block": {"type": "cube", "to_world": T().rotate([1, 1, 0], 30),
                  "bsdf": {"type": "birefringent", "material": "calcite",
                           "optic_axis": [0.42, 0.1, 0.9], "optic_axis_space": "world"}},
    })
    img = np.array(mi.render(scene, seed=2))
    assert np.all(np.isfinite(img))
    assert img[..., 0].mean() > 0.05  # R channel of the colour image
