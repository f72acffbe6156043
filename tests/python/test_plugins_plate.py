"""The `thinbirefringent` plugin (birefringent plate) driven through Mitsuba.

Isotropic thick plate against `thindielectric`, a thin plate at normal incidence against
`retarder`, eval_null_transmission, energy and reciprocity, textures, flags and the variants.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import mitsuba as mi

from bfr_helpers import (
    POLARIZED,
    context,
    direction,
    random_directions,
    reciprocal,
    sample,
    surface_interaction,
    variant,
    wo_of,
)

# Plate vs Mitsuba's thindielectric and the closed form, in float32: measured |difference| 7.5e-9
# at normal incidence, 2.1e-8 off normal (the values' float32 rounding, half an ulp of 0.75 is
# 3e-8); bound a few times that.
ATOL = 1e-7


def plate(**kw):
    return mi.load_dict({"type": "thinbirefringent", **kw})


def r_and_t(bsdf, si, mode="radiance"):
    """(R, T) weight * pdf of components 0 and 1 (numpy, per channel / Mueller)."""
    out = []
    for c in (0, 1):
        bs, w = sample(bsdf, context(mode, c), si)
        out.append(w * float(bs.pdf))
    return out


def m00(x):
    return x[0, 0] if x.ndim == 3 else x


# ---- flags, components, eval/pdf -----------------------------------------------------------


def test_flags_and_components():
    variant(POLARIZED)
    F = mi.BSDFFlags
    p = plate(material="quartz", thickness=10.0)
    sides = F.FrontSide | F.BackSide | F.Anisotropic
    assert p.component_count() == 2
    assert p.flags(0) == F.DeltaReflection | sides
    assert p.flags(1) == F.Null | sides
    assert p.flags() == p.flags(0) | p.flags(1)
    q = plate(material="quartz", thickness=10.0, exit_ior=1.5)
    # Between different indices the Radiance weight carries the radiance factor: NonSymmetric
    # (the Null transmission of p is symmetric, like thindielectric's).
    assert q.flags(1) == F.DeltaTransmission | sides | F.NonSymmetric
    si = surface_interaction(direction(40, 10))
    w_r, w_i = (sample(q, context(m, 1), si)[1][0, 0, 0] for m in ("radiance", "importance"))
    assert w_r / w_i == pytest.approx((1.000277 / 1.5) ** 2, rel=1e-6)  # ext_ior "air"
    iso = plate(eta_o=1.5, eta_e=1.5)
    assert not iso.flags() & F.Anisotropic
    si = surface_interaction(direction(40, 10))
    for b in (p, q):
        for c in (0, 1):
            bs, _ = sample(b, context(component=c), si)
            assert int(bs.sampled_component) == c and float(bs.pdf) == 1.0
            assert float(b.pdf(context(), si, bs.wo)) == 0.0
            assert np.abs(np.array(b.eval(context(), si, bs.wo))).max() == 0.0
    bs, _ = sample(p, context(component=1), si)
    np.testing.assert_allclose(wo_of(bs), -direction(40, 10), atol=1e-6)
    assert int(bs.sampled_type) == +F.Null and float(bs.eta) == 1.0


# ---- isotropic thick plate vs thindielectric -----------------------------------------------

THICK = dict(eta_o=1.5, eta_e=1.5, ext_ior=1.0, thickness=1000.0)  # 1 mm
# With a 4 nm band in the spectral variants (the default, 0, is the exact coherent plate).
THICK_BAND = dict(THICK, filter_bandwidth=4.0)


@pytest.mark.parametrize("name", ["scalar_rgb", "scalar_spectral", POLARIZED])
def test_thick_isotropic_plate_equals_thindielectric_at_normal_incidence(name):
    """A 1 mm isotropic plate with a 4 nm band (spectral) or the RGB channel integration: the
    multiple-reflection fringes (optical path 3 mm) average out, and M00 of R and T equals
    thindielectric's incoherent sum r' = 2r/(1+r)."""
    variant(name)
    ours = plate(**THICK_BAND)
    theirs = mi.load_dict({"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0})
    for side in (1, -1):
        si = surface_interaction(direction(0, 0, side))
        for mode in ("radiance", "importance"):
            (r, t), (r_d, t_d) = r_and_t(ours, si, mode), r_and_t(theirs, si, mode)
            np.testing.assert_allclose(m00(r), m00(r_d), atol=ATOL)
            np.testing.assert_allclose(m00(t), m00(t_d), atol=ATOL)
    r0 = 0.04
    # Mitsuba's own thindielectric against the closed form: measured 1.0e-8 (float32).
    assert m00(r_d) == pytest.approx(np.full_like(m00(r_d), 2 * r0 / (1 + r0)), abs=1e-7)


def test_thick_isotropic_plate_exact_average_equals_thindielectric():
    """filter_bandwidth = 0 is the exact coherent plate: M00 oscillates with the wavelength
    (fringe period lambda^2 / (2 n d) ~ 0.1 nm) between the etalon's extremes, and its average
    over many fringes is thindielectric's incoherent value."""
    variant("scalar_spectral")
    exact = plate(filter_bandwidth=0.0, **THICK)
    grid = np.linspace(549.0, 551.0, 2001)  # ~20 fringes, ~100 samples per fringe
    r = []
    for k in range(0, len(grid), 4):
        si = surface_interaction(direction(0), wavelengths=grid[k:k + 4])
        r.extend(m00(r_and_t(exact, si)[0]))
    r = np.array(r)
    r0 = 0.04
    assert r.min() < 1e-3 and r.max() > 0.14  # etalon extremes: 0 and 4 r0 / (1 + r0)^2
    assert r.mean() == pytest.approx(2 * r0 / (1 + r0), abs=2e-3)


def test_thick_isotropic_plate_off_normal():
    """Off normal incidence the plate sums the internal reflections per polarisation,
    R = (2 R_s / (1 + R_s) + 2 R_p / (1 + R_p)) / 2, while thindielectric averages R_s and R_p
    first (a 4 nm band averages the fringes). Checks the former and reports the difference to
    thindielectric."""
    variant("scalar_spectral")
    ours = plate(**THICK_BAND)
    theirs = mi.load_dict({"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0})
    report = []
    for theta in (20, 40, 60, 75, 85):
        si = surface_interaction(direction(theta, 30))
        r = m00(r_and_t(ours, si)[0])[0]
        r_d = m00(r_and_t(theirs, si)[0])[0]
        a_s, a_p, _, _, _ = mi.fresnel_polarized(math.cos(math.radians(theta)), 1.5)
        rs, rp = abs(complex(a_s.real, a_s.imag)) ** 2, abs(complex(a_p.real, a_p.imag)) ** 2
        expected = 0.5 * (2 * rs / (1 + rs) + 2 * rp / (1 + rp))
        assert r == pytest.approx(expected, abs=ATOL), theta
        report.append(f"{theta} deg: plate R {r:.5f}, thindielectric {r_d:.5f}, diff {r - r_d:+.5f}")
    print("\n".join(report))


# ---- thin plate vs retarder ----------------------------------------------------------------


@pytest.mark.parametrize("theta", [0.0, 30.0, 45.0, -60.0, 90.0])
@pytest.mark.parametrize("dn", [0.05, -0.03])
def test_thin_plate_equals_retarder_at_normal_incidence(theta, dn):
    """Normal incidence, Radiance, optic axis in the plate at `theta` degrees from s towards t,
    index-matched exterior (so the Fresnel reflectance is tiny: R_e = (dn / (2 n + dn))^2 <=
    2.7e-4) and no spectral filter: the normalised Mueller matrix is a linear retarder with
    retardance 2 pi (n_e - n_o) d / lambda. The optic axis is the slow axis when n_e > n_o
    (Mitsuba's `retarder` has its *fast* axis at theta: linear_retarder(phi) delays y by phi), so
    it equals retarder(theta, delta = -360 (n_e - n_o) d / lambda). Tolerance 2e-3: the residual
    etalon of the e wave changes its amplitude and phase by ~2 R_e (measured 5.3e-4 at worst)."""
    variant(POLARIZED)
    n_o, d_um = 1.5, 3.0
    n_e = n_o + dn
    t = math.radians(theta)
    ours = plate(eta_o=n_o, eta_e=n_e, ext_ior=n_o, thickness=d_um, filter_bandwidth=0.0,
                 optic_axis=[math.cos(t), math.sin(t), 0.0])
    worst = 0.0
    for lam in (420.0, 530.0, 640.0):
        delta = 360.0 * (n_e - n_o) * d_um * 1000.0 / lam
        ret = mi.load_dict({"type": "retarder", "theta": theta, "delta": -delta})
        for side in (1, -1):
            si = surface_interaction(direction(0, 0, side), wavelengths=[lam] * 4)
            bs, w = sample(ours, context(component=1), si)
            bs_r, w_r = sample(ret, context(), si)
            np.testing.assert_allclose(wo_of(bs), wo_of(bs_r), atol=1e-6)
            a = w[..., 0] / w[0, 0, 0]
            b = w_r[..., 0] / w_r[0, 0, 0]
            worst = max(worst, np.abs(a - b).max())
            assert np.abs(a - b).max() <= 2e-3, (lam, side, a, b)
    print(f"theta {theta}, dn {dn}: max |plate - retarder| (normalised) = {worst:.2e}")


@pytest.mark.parametrize("theta", [0.0, 30.0, 75.0])
def test_strongly_dichroic_plate_approaches_polarizer(theta):
    """A plate whose extraordinary wave is absorbed (kappa_e = 0.05 over 30 um: exp(-4 pi kappa d /
    lambda) < 1e-10) and index-matched ordinary wave transmits only light polarised
    perpendicular to its optic axis: a linear polariser. Mitsuba's `polarizer` transmits along
    cos(th) s - sin(th) t, i.e. at -th from s towards t, so an optic axis at `theta` (transmission
    at theta + 90) matches polarizer(90 - theta). Compared normalised by M00 at normal
    incidence, both sides; tolerance 1e-6 (the
    o wave's Fresnel factors are the same for every polarisation, so only float32 remains)."""
    variant(POLARIZED)
    t = math.radians(theta)
    ours = plate(eta_o=1.5, eta_e=1.5, kappa_e=0.05, ext_ior=1.5, thickness=30.0,
                 filter_bandwidth=0.0, optic_axis=[math.cos(t), math.sin(t), 0.0])
    pol = mi.load_dict({"type": "polarizer", "theta": 90.0 - theta})
    for side in (1, -1):
        si = surface_interaction(direction(0, 0, side), wavelengths=[550.0] * 4)
        bs, w = sample(ours, context(component=1), si)
        bs_p, w_p = sample(pol, context(), si)
        np.testing.assert_allclose(wo_of(bs), wo_of(bs_p), atol=1e-6)
        a = w[..., 0] / w[0, 0, 0]
        b = w_p[..., 0] / w_p[0, 0, 0]
        assert np.abs(a - b).max() <= 1e-6, (side, a, b)



@pytest.mark.parametrize("fwhm,d_um", [(4.0, 170.0), (4.0, 500.0), (10.0, 300.0)])
def test_filter_bandwidth_is_the_documented_gaussian(fwhm, d_um):
    """`filter_bandwidth` is the FWHM (nm, in wavelength) of a Gaussian band: written out here,
    sigma_lambda = FWHM / (2 sqrt(2 ln 2)), in wavenumber sigma_k = 2 pi sigma_lambda / lambda^2,
    and a fringe of path difference D keeps the contrast exp(-sigma_k^2 D^2 / 2). A retarder of
    D = 0.01 d (indices 1.5 / 1.51, no dispersion, normal incidence, index-matched exterior: the
    e wave reflects 1.1e-5 per face) shows that contrast as the norm of its Mueller matrix's
    lower 3x3 block: singular values 1, C, C, so C = sqrt((|B|^2 / M00^2 - 1) / 2), whatever
    the Stokes frames. 1.7 um and 5 um at 550 nm are plugin/README.md's 99.8 % and 98.5 %."""
    variant(POLARIZED)
    ours = plate(eta_o=1.5, eta_e=1.51, ext_ior=1.5, thickness=d_um, filter_bandwidth=fwhm,
                 optic_axis=[1.0, 0.0, 0.0])
    lams = np.array([450.0, 500.0, 550.0, 650.0])
    bs, w = sample(ours, context(component=1), surface_interaction(direction(0), wavelengths=lams))
    block = w[1:, 1:, :] / w[0, 0, :]
    got = np.sqrt(((block**2).sum(axis=(0, 1)) - 1.0) / 2.0)
    sigma_k = 2 * math.pi * (fwhm / (2 * math.sqrt(2 * math.log(2)))) / lams**2
    want = np.exp(-0.5 * (sigma_k * 0.01 * d_um * 1e3) ** 2)
    print(f"FWHM {fwhm} nm, D = {0.01 * d_um} um: contrast {got} (documented Gaussian {want})")
    # Measured |got - want| <= 3.3e-8 (float32 Mueller entries); bound 2e-7. A width off by 1 %
    # changes these contrasts by >= 1.8e-5 (4 nm, 1.7 um at 650 nm).
    np.testing.assert_allclose(got, want, atol=2e-7)

# ---- null transmission, energy, reciprocity ------------------------------------------------


@pytest.mark.parametrize("filter_bandwidth", [0.0, 4.0])
def test_eval_null_transmission_equals_sampled_transmission(filter_bandwidth):
    variant(POLARIZED)
    p = plate(material="quartz", thickness=25.0, optic_axis=[0.6, 0.3, 0.74],
              filter_bandwidth=filter_bandwidth)
    n = 50 if filter_bandwidth == 0.0 else 8  # band-integrated queries are slow off normal
    for wi in random_directions(n, seed=11, min_abs_cos=0.0 if filter_bandwidth == 0.0 else 0.7):
        si = surface_interaction(wi)
        bs, w = sample(p, context(component=1), si)
        null = np.array(p.eval_null_transmission(si))
        # The same core query behind both (and pdf 1 for a chosen component): measured
        # bitwise equal, so equality is required.
        np.testing.assert_array_equal(null, w * float(bs.pdf))


def max_energy_error(p, n=100, seed=12, min_abs_cos=1e-3):
    worst = 0.0
    for wi in random_directions(n, seed=seed, min_abs_cos=min_abs_cos):
        r, t = r_and_t(p, surface_interaction(wi), "importance")
        worst = max(worst, np.abs(m00(r) + m00(t) - 1.0).max())
    return worst


@pytest.mark.parametrize("name", ["scalar_spectral", POLARIZED])
def test_energy_of_a_clear_plate_exact(name):
    """Importance mode, clear plate, ext == exit, filter_bandwidth 0: R + T = 1 for unpolarised
    light (power fractions)."""
    variant(name)
    p = plate(material="calcite", thickness=7.0, optic_axis=[0.3, 0.5, 0.81], filter_bandwidth=0.0)
    # Measured 3.0e-8: the float32 rounding of R + T (the core conserves it to ~1e-13).
    assert max_energy_error(p) <= 1e-7


@pytest.mark.parametrize("name", ["scalar_rgb", "scalar_spectral"])
def test_energy_of_a_clear_plate_band_integrated(name):
    """The same with a 4 nm band (spectral) and the RGB channel integration, up to 60 degrees
    (few directions: band-integrated core queries are the slow ones)."""
    variant(name)
    p = plate(material="calcite", thickness=7.0, optic_axis=[0.3, 0.5, 0.81], filter_bandwidth=4.0)
    # The band: measured 3.0e-8, float32 rounding, as for the exact plate. The RGB channels are
    # integrated to a perceptual budget (src/quadrature/budget.rs: each approximation held to
    # 1e-5 of the light; a few add up in R + T): measured 2.3e-5, bound 1e-4 (a CIEDE2000 below
    # 0.1 on a bright plate).
    bound = 1e-4 if name == "scalar_rgb" else 1e-7
    assert max_energy_error(p, n=12, min_abs_cos=0.5) <= bound


# Near grazing incidence many internal reflections interfere: an isotropic 0.3 um plate (eta 1.5
# in vacuum) at 88 degrees, 600 nm, exact R = 0.920374, T = 0.079626. A 0.5 nm band cannot change
# a fringe of period ~300 nm, and the band-integrated plate must conserve energy (an earlier core
# gave R + T = 1.035 here).
def test_band_integration_conserves_energy_at_grazing_incidence():
    variant("scalar_spectral")
    kw = dict(eta_o=1.5, eta_e=1.5, ext_ior=1.0, thickness=0.3)
    si = surface_interaction(direction(88.0), wavelengths=[600.0] * 4)
    exact = r_and_t(plate(filter_bandwidth=0.0, **kw), si, "importance")
    band = r_and_t(plate(filter_bandwidth=0.5, **kw), si, "importance")
    # Measured: R + T - 1 = 0 in float32, band - exact = -1.9e-6 (the band's second-order
    # averaging of the fringe's curvature); bounds 1e-7 (float32) and 1e-5.
    assert band[0][0] + band[1][0] == pytest.approx(1.0, abs=1e-7)
    assert band[0][0] == pytest.approx(exact[0][0], abs=1e-5)


@pytest.mark.parametrize("exit_ior", [None, 1.33])
def test_plate_reciprocity(exit_ior):
    """M_importance(wi -> wo) = Q M_radiance(wi -> wo)^T Q, normalised by M00."""
    variant(POLARIZED)
    kw = {} if exit_ior is None else {"exit_ior": exit_ior}
    p = plate(material="quartz", thickness=15.0, optic_axis=[0.5, 0.2, 0.84], filter_bandwidth=0.0, **kw)
    worst = 0.0
    for wi in random_directions(100, seed=13):
        si = surface_interaction(wi)
        for c in (0, 1):
            bs_r, w_r = sample(p, context("radiance", c), si)
            bs_i, w_i = sample(p, context("importance", c), si)
            if not (bs_r.pdf > 0 and bs_i.pdf > 0):
                assert not bs_r.pdf > 0 and not bs_i.pdf > 0
                continue
            np.testing.assert_allclose(wo_of(bs_r), wo_of(bs_i), atol=1e-6)
            a = w_i / w_i[0, 0]
            b = reciprocal(w_r / w_r[0, 0])
            worst = max(worst, np.abs(a - b).max())
    print(f"plate reciprocity (exit_ior {exit_ior}): max error {worst:.2e}")
    # Measured 0 (exit_ior = ext_ior) and 1.5e-7 (exit_ior 1.33): float32 matrices normalised by
    # M00; bound a few times that.
    assert worst <= 1e-6


# ---- textures ------------------------------------------------------------------------------


def test_textures_drive_the_plate():
    """thickness (texture x thickness_scale), birefringence (added to eta_e) and axis_angle
    (degrees, rotating the optic axis about the normal from s towards t) from textures equal
    the plates with the same constant parameters."""
    variant(POLARIZED)
    # Mitsuba's checkerboard gives color1 at uv (0.25, 0.25) and color0 at (0.75, 0.25)
    si_a = surface_interaction(direction(35, 20), uv=(0.75, 0.25))
    si_b = surface_interaction(direction(35, 20), uv=(0.25, 0.25))

    def checker(a, b):
        return {"type": "checkerboard", "color0": a, "color1": b}

    def both(b, si):
        return np.concatenate([x.ravel() for x in r_and_t(b, si)])

    textured = plate(eta_o=1.5, eta_e=1.5, filter_bandwidth=0.0, optic_axis=[1, 0, 0],
                     thickness=checker(2.0, 3.0), thickness_scale=2.0,
                     birefringence=checker(0.01, 0.02), birefringence_scale=0.5,
                     axis_angle=checker(30.0, -50.0))
    for si, (d, dn, ang) in ((si_a, (4.0, 0.005, 30.0)), (si_b, (6.0, 0.01, -50.0))):
        a = math.radians(ang)
        const = plate(eta_o=1.5, eta_e=1.5 + dn, filter_bandwidth=0.0, thickness=d,
                      optic_axis=[math.cos(a), math.sin(a), 0.0])
        # Measured 6.0e-8: the float32 texture values (thickness 2 x 2.0, birefringence 0.5 x
        # 0.01) rounded before the core sees them.
        np.testing.assert_allclose(both(textured, si), both(const, si), atol=2e-7)
    assert np.abs(both(textured, si_a) - both(textured, si_b)).max() > 1e-3


SCALAR_TEXTURES = {"thickness": 30.0, "axis_angle": 45.0, "birefringence": 0.02}


@pytest.mark.parametrize("name", ["scalar_rgb", "scalar_spectral", POLARIZED])
@pytest.mark.parametrize("param", sorted(SCALAR_TEXTURES))
def test_grey_rgb_and_uniform_spectrum_are_the_number(name, param):
    """A physical scalar given as a grey rgb (dict or XML) or a uniform spectrum is that
    number, exactly, in every variant: the lobes equal those of the float (bit for bit). In the
    spectral variants Mitsuba itself would turn an rgb into a smooth reflectance spectrum
    bounded to [0, 1] (rgb 30 read as ~1 and a 30 um plate rendered as a 1 um one)."""
    variant(name)
    x = SCALAR_TEXTURES[param]
    base = dict(material="quartz", thickness=3.0, optic_axis=[1, 0, 0])
    si = surface_interaction(direction(35, 20))
    want = r_and_t(plate(**{**base, param: x}), si)
    thickness = "" if param == "thickness" else '<float name="thickness" value="3"/>'
    xml = mi.load_string(f"""
        <bsdf version="3.0.0" type="thinbirefringent">
            <string name="material" value="quartz"/> <vector name="optic_axis" x="1" y="0" z="0"/>
            {thickness} <rgb name="{param}" value="{x}, {x}, {x}"/>
        </bsdf>""")
    for b in (plate(**{**base, param: {"type": "rgb", "value": [x, x, x]}}),
              plate(**{**base, param: {"type": "spectrum", "value": x}}), xml):
        assert f"{param} = UniformSpectrum" in str(b)
        for got, ref in zip(r_and_t(b, si), want):
            np.testing.assert_array_equal(got, ref)
    other = r_and_t(plate(**{**base, param: 0.5 * x}), si)
    # The parameter matters here: halving it changes the lobes by at least 1.6e-4 (measured,
    # axis_angle in scalar_rgb, unpolarised); float rounding of these weights is ~1e-8.
    assert max(np.abs(o - w).max() for o, w in zip(other, want)) > 5e-5


def test_xml_and_traverse():
    variant(POLARIZED)
    p = mi.load_string("""
        <bsdf version="3.0.0" type="thinbirefringent">
            <string name="material" value="sapphire"/>
            <float name="thickness" value="12.5"/>
            <vector name="optic_axis" x="0" y="1" z="0"/>
            <string name="ext_ior" value="water"/>
            <float name="filter_bandwidth" value="2"/>
        </bsdf>""")
    text = str(p)
    for key in ("sapphire", "thickness", "optic_axis", "ext_ior", "filter_bandwidth"):
        assert key in text
    params = mi.traverse(p)
    for key in ("thickness.value", "thickness_scale", "ext_ior", "exit_ior", "optic_axis",
                "filter_bandwidth"):
        assert key in params
    assert params["ext_ior"] == pytest.approx(1.333, abs=1e-6)
    si = surface_interaction(direction(30))
    before = r_and_t(p, si)[1]
    params["thickness.value"] = 13.0
    params.update()
    after = r_and_t(p, si)[1]
    assert np.abs(before - after).max() > 1e-4


# ---- rendering -----------------------------------------------------------------------------


def test_render_through_a_null_plate():
    """volpath reaches a light behind a Null plate through eval_null_transmission and by BSDF
    sampling: an isotropic thick plate renders like thindielectric (T = 1 - 2r/(1+r) = 0.923)."""
    variant(POLARIZED)
    T = mi.ScalarTransform4f

    def render(bsdf):
        scene = mi.load_dict({
            "type": "scene",
            "integrator": {"type": "volpath", "max_depth": 4},
            "sensor": {"type": "perspective", "fov": 5.0,
                       "to_world": T().look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0]),
                       "film": {"type": "hdrfilm", "width": 4, "height": 4, "rfilter": {"type": "box"}},
                       "sampler": {"type": "independent", "sample_count": 32}},
            "light": {"type": "rectangle", "to_world": T().translate([0, 0, -2]).scale(3),
                      "flip_normals": False,
                      "emitter": {"type": "area", "radiance": {"type": "d65"}}},
            "plate": {"type": "rectangle", "bsdf": bsdf},
        })
        return np.array(mi.render(scene, seed=1))

    ours = render({"type": "thinbirefringent", **THICK})
    theirs = render({"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0})
    assert ours.mean() > 0.1
    np.testing.assert_allclose(ours.mean(), theirs.mean(), rtol=0.03)


def test_unpolarized_variants_give_the_polarized_m00():
    """scalar_spectral returns M00 of the polarized variant's Mueller matrix (same core, the
    bridge's intensity-only query)."""
    kw = dict(material="calcite", thickness=4.0, optic_axis=[0.3, 0.5, 0.81], filter_bandwidth=0.0)
    dirs = random_directions(40, seed=21)
    results = {}
    for name in ("scalar_spectral", POLARIZED):
        variant(name)
        p = plate(**kw)
        results[name] = [m00(x) for wi in dirs for mode in ("radiance", "importance")
                         for x in r_and_t(p, surface_interaction(wi), mode)]
    # Measured: bitwise equal in float32; bound 1e-7 (an ulp of the largest value).
    np.testing.assert_allclose(results["scalar_spectral"], results[POLARIZED], atol=1e-7)


def test_invalid_texture_value_at_render_time_gives_no_light():
    """A texture can hold values the core refuses (a negative thickness) where the load-time
    check (at the texture's mean) passes: those queries return no light (one warning), no
    exception in the middle of a render."""
    variant(POLARIZED)
    p = plate(material="quartz", thickness={"type": "checkerboard", "color0": -1.0, "color1": 3.0})
    bad = surface_interaction(direction(20), uv=(0.75, 0.25))
    good = surface_interaction(direction(20), uv=(0.25, 0.25))
    bs, w = sample(p, context(), bad)
    assert float(bs.pdf) == 0.0 and np.abs(w).max() == 0.0
    assert np.abs(np.array(p.eval_null_transmission(bad))).max() == 0.0
    bs, w = sample(p, context(), good)
    assert float(bs.pdf) > 0.0 and w[0, 0, 0] > 0.0


def srgb_d65_reference(kw, wi, mode, component, step=0.5):
    """Linear sRGB (D65) channel values of the exact plate's M00, by quadrature over 360-830 nm
    with Mitsuba's CIE 1931 matching functions and D65 spectrum, each channel normalised so
    that a flat response of 1 gives 1 (the contract of the bridge's sRGB channel set)."""
    variant("scalar_spectral")
    exact = plate(filter_bandwidth=0.0, **kw)
    d65 = mi.load_dict({"type": "d65"})
    grid = np.arange(360.0, 830.0 + 1e-9, step)
    grid = np.concatenate([grid, np.full((-len(grid)) % 4, grid[-1])])
    values, weights = [], []
    for k in range(0, len(grid), 4):
        si = surface_interaction(wi, wavelengths=grid[k:k + 4])
        bs, w = sample(exact, context(mode, component), si)
        values.extend(w * float(bs.pdf))
        illum = np.array(d65.eval(si))
        for j, lam in enumerate(grid[k:k + 4]):
            rgb = np.array(mi.xyz_to_srgb(mi.cie1931_xyz(float(lam))))
            weights.append(rgb * illum[j])
    values, weights = np.array(values), np.array(weights)
    return (weights * values[:, None]).sum(axis=0) / weights.sum(axis=0)


@pytest.mark.parametrize("thickness,theta", [(0.3, 0.0), (0.3, 60.0), (2.0, 30.0)])
def test_rgb_channels_integrate_the_exact_plate(thickness, theta):
    """scalar_rgb: each channel is the exact plate integrated over that channel's weight (thin
    films have colours: the channels differ). Tolerance 1e-3: the core fits the channel
    weights with Gaussians; measured 2.3e-4 at worst (0.3 um at 60 degrees, blue)."""
    kw = dict(material="calcite", thickness=thickness, optic_axis=[0.3, 0.5, 0.81])
    wi = direction(theta, 57)
    for component in (0, 1):
        expected = srgb_d65_reference(kw, wi, "importance", component)
        variant("scalar_rgb")
        bs, w = sample(plate(**kw), context("importance", component), surface_interaction(wi))
        got = w * float(bs.pdf)
        print(f"d {thickness} theta {theta} component {component}: rgb {got}, reference {expected}")
        np.testing.assert_allclose(got, expected, atol=1e-3)
    assert np.ptp(expected) > 1e-2 or thickness > 1.0


def test_light_sampling_through_the_plate_reduces_noise():
    """A diffuse floor lit by a small light through a plate above it (Null transmission). With
    volpath, shadow rays cross the plate through eval_null_transmission; with path they are
    blocked and only BSDF sampling finds the light. Same mean, far less noise with light
    sampling: the measured ratio of per-pixel standard deviations over 8 seeds is printed."""
    variant(POLARIZED)
    T = mi.ScalarTransform4f

    def renders(integrator):
        scene = mi.load_dict({
            "type": "scene",
            "integrator": {"type": integrator, "max_depth": 6},
            "sensor": {"type": "perspective", "fov": 60.0,
                       "to_world": T().look_at(origin=[0, 0, 0.5], target=[0, 0, 0], up=[0, 1, 0]),
                       "film": {"type": "hdrfilm", "width": 16, "height": 16, "rfilter": {"type": "box"}},
                       "sampler": {"type": "independent", "sample_count": 16}},
            "light": {"type": "rectangle", "to_world": T().translate([0, 0, 2]).scale(0.1)
                      @ T().rotate([1, 0, 0], 180),
                      "emitter": {"type": "area", "radiance": {"type": "d65", "scale": 50.0}}},
            "plate": {"type": "rectangle", "to_world": T().translate([0, 0, 1]).scale(5),
                      "bsdf": {"type": "thinbirefringent", "material": "quartz", "thickness": 30.0,
                               "optic_axis": [1, 1, 0], "filter_bandwidth": 0.0}},
            "floor": {"type": "rectangle", "to_world": T().scale(5),
                      "bsdf": {"type": "diffuse", "reflectance": 0.5}},
        })
        return np.array([np.array(mi.render(scene, seed=s))[..., :3].mean(axis=-1) for s in range(8)])

    nee, bsdf_only = renders("volpath"), renders("path")
    std = lambda x: x.std(axis=0, ddof=1).mean()
    ratio = std(bsdf_only) / std(nee)
    print(f"per-pixel std: path {std(bsdf_only):.4f}, volpath {std(nee):.4f} (ratio {ratio:.1f}); "
          f"means {bsdf_only.mean():.4f}, {nee.mean():.4f}")
    assert ratio > 3.0
    # Same expectation: the difference of the means is within 5 standard errors.
    se = np.sqrt(bsdf_only.mean(axis=(1, 2)).var(ddof=1) / 8 + nee.mean(axis=(1, 2)).var(ddof=1) / 8)
    assert abs(bsdf_only.mean() - nee.mean()) < 5 * se + 1e-6


@pytest.mark.parametrize("name", ["scalar_rgb", POLARIZED])
def test_absorbing_exit_keeps_only_the_front_reflection(name):
    """absorbing_exit: the reflection lobe alone (probability 1), equal to the reflection of
    the same plate without it (the exit medium's absorption changes nothing above the plate);
    from below no light (it cannot reach the plate through an absorbing medium)."""
    variant(name)
    kw = dict(material="quartz", thickness=0.7, optic_axis=[1, 1, 0], exit_ior=1.458)
    black, clear = plate(absorbing_exit=True, **kw), plate(**kw)
    assert mi.has_flag(black.flags(), mi.BSDFFlags.DeltaReflection)
    assert not mi.has_flag(black.flags(), mi.BSDFFlags.DeltaTransmission)
    assert not mi.has_flag(black.flags(), mi.BSDFFlags.BackSide)
    for theta in (0.0, 35.0, 70.0):
        si = surface_interaction(direction(theta, 20.0))
        for u in (0.05, 0.5, 0.95):
            bs, w = sample(black, context(), si, u)
            assert int(bs.sampled_component) == 0 and float(bs.pdf) == pytest.approx(1.0)
            r_clear = r_and_t(clear, si)[0]
            # Same core query (reflection only vs both): equal to rounding.
            np.testing.assert_allclose(w * float(bs.pdf), r_clear, rtol=1e-6, atol=1e-9)
        bs, w = sample(black, context(), surface_interaction(direction(theta, 20.0, side=-1)))
        assert not float(bs.pdf) > 0 and not np.any(w)
