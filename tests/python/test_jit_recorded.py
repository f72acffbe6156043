"""The plugins' recorded programs (docs/architecture.md, "The physics inside Mitsuba's
kernels"): in the JIT variants a plate at exact wavelengths runs inside Mitsuba's kernels as
the core's recorded program, replayed with Dr.Jit arrays, in Mitsuba's default (symbolic) mode.

Lane for lane against the scalar variant (the core in f64, one query per lane): random
directions on both sides, both transport modes, lobe numbers, wavelengths and texture values,
named and constant, birefringent, isotropic, dichroic and absorbing plates from 0 to 1000 um,
eval_null_transmission. The program runs in double precision inside the kernel (the phases of a
1 mm plate reach 2e4 rad); what remains are single-precision steps outside it: the inputs and
outputs of the kernel (float32, 6e-8 relative each) and the rotation of each Mueller matrix into
Mitsuba's Stokes frames (R_out M R_in^T in float32: two products of 4-term sums and the angles'
cosines, about 20 roundings of the largest entry). So each weight entry agrees to
TOL = 4e-6 times the largest entry of its matrix (about 30 float32 roundings), directions and
pdfs to 1e-6. A lane may choose another lobe where its lobe number lies within float32 rounding
of a boundary of the cumulative weights (|u - boundary| < 1e-6): those lanes are counted and
left out of the comparison.
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import batch_si, context, floats, random_directions

TOL = 4e-6
DIR_TOL = 1e-6


def checker(a: float, b: float) -> dict:
    return {"type": "checkerboard", "color0": a, "color1": b,
            "to_uv": mi.ScalarTransform4f().scale([5, 5, 1])}


#: (id, plugin description built in the current variant, lanes, null transmission too)
def plates():
    return [
        ("quartz-textured", {"type": "thinbirefringent", "material": "quartz",
                             "optic_axis": [1, 0.3, 0.2], "thickness": checker(0.0, 300.0),
                             "birefringence": checker(0.0, 0.004),
                             "axis_angle": checker(10.0, 70.0), "exit_ior": 1.33}),
        ("dichroic", {"type": "thinbirefringent", "eta_o": 2.4, "eta_e": 2.6, "kappa_e": 0.02,
                      "thickness": 5.0, "optic_axis": [0.3, -0.5, 0.8]}),
        ("photoelastic", {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5,
                          "thickness": 3000.0, "birefringence": checker(0.0, 2e-4),
                          "axis_angle": checker(0.0, 45.0)}),
        ("calcite-1mm", {"type": "thinbirefringent", "material": "calcite", "thickness": 1000.0,
                         "optic_axis": [0.2, 0.1, 1.0], "ext_ior": 1.0, "exit_ior": 1.5}),
        ("film-on-black", {"type": "thinbirefringent", "material": "rutile", "thickness": 0.3,
                           "optic_axis": [1, 0, 0], "absorbing_exit": True}),
        ("bare-interfaces", {"type": "thinbirefringent", "material": "sapphire",
                             "thickness": 0.0, "exit_ior": 1.7}),
    ]


def stacks():
    tape = {"type": "thinbirefringent", "eta_o": 1.47, "eta_e": 1.478}
    return [
        ("quartz-and-tapes", {"type": "birefringentstack", "ext_ior": 1.0, "exit_ior": 1.2,
                              "quartz": {"type": "thinbirefringent", "material": "quartz",
                                         "thickness": 12.0, "axis_angle": checker(0.0, 60.0)},
                              "tape_1": dict(tape, thickness=checker(20.0, 40.0),
                                             birefringence=checker(0.0, 0.002)),
                              "tape_2": dict(tape, thickness=35.0,
                                             axis_angle=checker(30.0, 100.0))}),
        ("zero-order-qwp", {"type": "birefringentstack",
                            "a": {"type": "thinbirefringent", "material": "quartz",
                                  "thickness": 1000.0, "optic_axis": [1, 0, 0]},
                            "b": {"type": "thinbirefringent", "material": "quartz",
                                  "thickness": 983.6, "optic_axis": [0, 1, 0]}}),
        ("absorbing-dichroic", {"type": "birefringentstack", "exit_ior": 1.5,
                                "film": {"type": "thinbirefringent", "eta_o": 2.0, "eta_e": 2.0,
                                         "kappa_o": 0.3, "kappa_e": 0.3, "thickness": 0.02},
                                "polariser": {"type": "thinbirefringent", "eta_o": 1.5,
                                              "eta_e": 1.55, "kappa_e": 0.05,
                                              "thickness": 8.0, "optic_axis": [1, 1, 0]}}),
    ]


def crystals():
    return [
        ("calcite", {"type": "birefringent", "material": "calcite",
                     "optic_axis": [0.3, 0.5, 0.8], "ext_ior": 1.0}),
        ("calcite-world-axis", {"type": "birefringent", "material": "calcite",
                                "optic_axis": [0.2, -0.4, 0.9], "optic_axis_space": "world"}),
        ("constant-birefringent", {"type": "birefringent", "eta_o": 1.55, "eta_e": 1.65,
                                   "optic_axis": [1, 0, 0.3], "ext_ior": 1.2}),
        ("glass", {"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5}),
        ("metal", {"type": "birefringent", "eta_o": 0.2, "eta_e": 0.2, "kappa_o": 3.0,
                   "kappa_e": 3.0}),
    ]


def isotropic_crystals():
    return [c for c in crystals() if c[0] in ("glass", "metal")]


def lanes(seed: int, n: int):
    rng = np.random.default_rng(seed)
    wi = random_directions(n, rng, min_abs_cos=2e-3)  # to 89.9 degrees
    uv = rng.uniform(size=(n, 2)).astype(np.float32)
    waves = rng.uniform(360.0, 830.0, size=(n, 4)).astype(np.float32)
    u = rng.uniform(size=n).astype(np.float32)
    return wi, uv, waves, u


def scalar_lanes(variant, desc, mode, wi, uv, waves, u, null):
    """Lane by lane in the scalar variant."""
    mi.set_variant(variant)
    bsdf = mi.load_dict(desc)
    ctx = context(mode)
    rows = []
    for i in range(len(wi)):
        si = mi.SurfaceInteraction3f()
        si.n = mi.Normal3f(0, 0, 1)
        si.sh_frame = mi.Frame3f(si.n)
        si.wi = mi.Vector3f(*[float(x) for x in wi[i]])
        si.uv = mi.Point2f(float(uv[i, 0]), float(uv[i, 1]))
        if mi.is_spectral:
            si.wavelengths = mi.UnpolarizedSpectrum(*[float(x) for x in waves[i]])
        if null:
            rows.append(np.array(bsdf.eval_null_transmission(si), dtype=np.float64))
            continue
        bs, w = bsdf.sample(ctx, si, float(u[i]), mi.Point2f(0.5, 0.5))
        rows.append((np.array(bs.wo, dtype=np.float64), float(bs.pdf), float(bs.eta),
                     int(bs.sampled_component), np.array(w, dtype=np.float64)))
    return rows


def jit_lanes(variant, desc, mode, wi, uv, waves, u, null):
    """Every lane at once in the JIT variant, in Mitsuba's default mode."""
    mi.set_variant(variant)
    bsdf = mi.load_dict(desc)
    si = batch_si(wi, waves, uv)
    n = len(wi)
    lanes_of = lambda x: np.broadcast_to(np.array(x, dtype=np.float64),  # noqa: E731
                                         np.array(x).shape[:-1] + (n,))
    if null:
        return lanes_of(bsdf.eval_null_transmission(si))
    bs, w = bsdf.sample(context(mode), si, floats(u), mi.Point2f(0.5, 0.5))
    dr.eval(bs, w)  # one kernel for every output (read one by one: a kernel each)
    return (lanes_of(bs.wo).T, lanes_of(bs.pdf), lanes_of(bs.eta),
            lanes_of(bs.sampled_component), lanes_of(w))


def weight_error(a: np.ndarray, b: np.ndarray) -> float:
    """The largest difference of two weights relative to the largest entry of either."""
    scale = max(np.abs(a).max(), np.abs(b).max(), 1e-30)
    return float(np.abs(a - b).max() / scale) if scale > 1e-30 else 0.0


def compare(variant: str, cases, per_case: int):
    """Every case's lanes in both modes against the scalar variant; returns (lanes compared,
    lanes that chose another lobe, worst weight error)."""
    scalar = variant.replace("llvm_ad", "scalar")
    compared, flipped, worst = 0, 0, 0.0
    for k in range(len(cases())):
        wi, uv, waves, u = lanes(10 + k, per_case)
        for mode in ("radiance", "importance"):
            mi.set_variant(variant)
            name = cases()[k][0]
            got = jit_lanes(variant, cases()[k][1], mode, wi, uv, waves, u, False)
            mi.set_variant(scalar)
            want = scalar_lanes(scalar, cases()[k][1], mode, wi, uv, waves, u, False)
            for i, (wo, pdf, eta, comp, w) in enumerate(want):
                if got[3][i] != comp:
                    flipped += 1
                    continue
                if pdf == 0.0:
                    assert got[1][i] == 0.0 and np.all(got[4][..., i] == 0.0), (name, mode, i)
                    compared += 1
                    continue
                assert np.abs(got[0][i] - wo).max() <= DIR_TOL, (name, mode, i, got[0][i], wo)
                assert abs(got[1][i] - pdf) <= DIR_TOL * max(1.0, pdf), (name, mode, i)
                assert abs(got[2][i] - eta) <= DIR_TOL * max(1.0, eta), (name, mode, i)
                e = weight_error(got[4][..., i], w.reshape(got[4][..., i].shape))
                worst = max(worst, e)
                assert e <= TOL, (name, mode, i, wi[i], waves[i], e)
                compared += 1
    return compared, flipped, worst


@pytest.mark.parametrize("variant", ["llvm_ad_spectral_polarized", "llvm_ad_spectral"])
def test_recorded_plate_equals_the_scalar_core(variant):
    """6000 lanes (polarized; 1800 unpolarized) over six plates, both modes and sides."""
    mi.set_variant(variant)
    per_plate = 500 if "polarized" in variant else 150
    compared, flipped, worst = compare(variant, plates, per_plate)
    lanes_total = 2 * per_plate * len(plates())
    print(f"{variant}: {compared} of {lanes_total} lanes compared, {flipped} chose another "
          f"lobe at a boundary, worst weight error {worst:.2e} of the largest entry")
    assert flipped <= 0.002 * lanes_total
    assert compared >= 0.99 * lanes_total


def test_recorded_stack_equals_the_scalar_core():
    """1800 lanes over three stacks (textured layers, a zero-order quarter-wave plate of two
    crossed quartz plates, an absorbing film on a dichroic layer), both modes and sides."""
    variant = "llvm_ad_spectral_polarized"
    mi.set_variant(variant)
    compared, flipped, worst = compare(variant, stacks, 300)
    lanes_total = 2 * 300 * len(stacks())
    print(f"stacks: {compared} of {lanes_total} lanes compared, {flipped} chose another lobe, "
          f"worst weight error {worst:.2e}")
    assert flipped <= 0.002 * lanes_total
    assert compared >= 0.99 * lanes_total


@pytest.mark.parametrize("variant", ["llvm_ad_spectral_polarized", "llvm_ad_rgb"])
def test_recorded_crystal_equals_the_scalar_core(variant):
    """The bulk crystal's surface from both sides (inside: o and e arrivals), birefringent in
    the polarized variant, isotropic and absorbing in RGB (at the variant's wavelength)."""
    mi.set_variant(variant)
    cases = crystals if "polarized" in variant else isotropic_crystals
    compared, flipped, worst = compare(variant, cases, 300)
    lanes_total = 2 * 300 * len(cases())
    print(f"{variant} crystals: {compared} of {lanes_total} lanes compared, {flipped} chose "
          f"another lobe, worst weight error {worst:.2e}")
    assert flipped <= 0.002 * lanes_total
    assert compared >= 0.99 * lanes_total


@pytest.mark.parametrize("variant", ["llvm_ad_spectral_polarized"])
def test_recorded_null_transmission_equals_the_scalar_core(variant):
    mi.set_variant(variant)
    desc = {"type": "thinbirefringent", "material": "quartz", "thickness": checker(1.0, 80.0),
            "optic_axis": [1, 1, 0]}
    wi, uv, waves, u = lanes(3, 400)
    got = jit_lanes(variant, desc, "radiance", wi, uv, waves, u, True)
    want = scalar_lanes("scalar_spectral_polarized", desc, "radiance", wi, uv, waves, u, True)
    for i, w in enumerate(want):
        e = weight_error(got[..., i], w.reshape(got[..., i].shape))
        assert e <= TOL, (i, e)


def test_plates_render_in_mitsubas_default_mode():
    """A scene of plates renders with Dr.Jit's default (symbolic) flags, and while it exists a
    symbolic render of a scene without the plugins succeeds too."""
    mi.set_variant("llvm_ad_spectral_polarized")
    assert dr.flag(dr.JitFlag.SymbolicLoops) and dr.flag(dr.JitFlag.SymbolicCalls)
    def scene(bsdf):
        return mi.load_dict({
            "type": "scene", "integrator": {"type": "path", "max_depth": 6},
            "sensor": {"type": "orthographic",
                       "to_world": mi.ScalarTransform4f().look_at(origin=[0, 0, 5],
                                                                  target=[0, 0, 0], up=[0, 1, 0]),
                       "film": {"type": "hdrfilm", "width": 8, "height": 8},
                       "sampler": {"type": "independent", "sample_count": 4}},
            "light": {"type": "constant"},
            "plate": {"type": "rectangle", "bsdf": bsdf}})
    ours = scene({"type": "thinbirefringent", "material": "quartz", "thickness": 30.0})
    img = mi.render(ours)
    assert np.isfinite(np.array(img)).all() and np.array(img).max() > 0
    theirs = scene({"type": "thindielectric"})
    img = mi.render(theirs)
    assert np.isfinite(np.array(img)).all()
