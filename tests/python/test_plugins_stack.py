"""The `birefringentstack` plugin (thinbirefringent plates nested as layers) driven through
Mitsuba: one layer is the plate, two layers against the calculator's exact stack, the order of
the layers, XML and dicts, traversal and updates (a rejected one changes nothing), errors, flags
and Null transmission, and every supported variant.
"""

from __future__ import annotations

import json
import pathlib
import subprocess

import numpy as np
import drjit as dr
import pytest

import mitsuba as mi
import mitsuba_birefringent

from bfr_helpers import (
    POLARIZED,
    context,
    direction,
    random_directions,
    sample,
    surface_interaction,
    variant,
)

CALCULATOR = pathlib.Path(__file__).resolve().parents[2] / "target" / "release" / "birefringence"
TAPE = {"type": "thinbirefringent", "eta_o": 1.47, "eta_e": 1.478, "thickness": 40.0}


def layer(**kw):
    return {**TAPE, **kw}


def stack(*layers, **kw):
    d = {"type": "birefringentstack", **kw}
    for k, l in enumerate(layers):
        d[f"plate_{k}"] = l
    return mi.load_dict(d)


def lobe(bsdf, si, mode, component):
    """weight * pdf of one component (numpy)."""
    bs, w = sample(bsdf, context(mode, component), si)
    return w * float(bs.pdf)


def test_one_layer_is_the_plate():
    """A stack of one plate answers as the plate itself, both lobes, both sides, both transport
    modes (the core's one-layer recursion is the slab's, to 1e-12; the float32 outputs measured
    equal; bound 2e-7, a few ulps of the values)."""
    kw = dict(material="quartz", thickness=7.5, optic_axis=[0.3, 0.5, 0.81], axis_angle=20.0)
    worst = 0.0
    for name in (POLARIZED, "scalar_spectral"):
        variant(name)
        s = stack({"type": "thinbirefringent", **kw}, exit_ior=1.33)
        p = mi.load_dict({"type": "thinbirefringent", **kw, "exit_ior": 1.33})
        for wi in random_directions(24, seed=3):
            si = surface_interaction(wi)
            for mode in ("radiance", "importance"):
                for c in (0, 1):
                    a, b = lobe(s, si, mode, c), lobe(p, si, mode, c)
                    worst = max(worst, float(np.abs(a - b).max()))
    print(f"one-layer stack vs plate: worst {worst:.2e}")
    assert worst < 2e-7


def test_one_layer_is_the_plate_with_its_scales():
    """A layer's thickness_scale and birefringence_scale act in the stack as on the plate: a
    stack of one plate with both scales set (a stressed glass: 3 um x 2.5 thick, a
    birefringence of 2 x 1e-2) answers as the plate itself, both lobes, from both sides, both
    transport modes (the same bound as above: a few ulps of the float32 outputs). Without
    either scale the answers differ by far more (checked here: the plate with scales 1)."""
    kw = dict(eta_o=1.5, eta_e=1.5, thickness=3.0, thickness_scale=2.5, birefringence=2.0,
              birefringence_scale=1e-2, optic_axis=[0.3, 0.5, 0.81], axis_angle=20.0)
    for name in (POLARIZED, "scalar_spectral"):
        variant(name)
        s = stack({"type": "thinbirefringent", **kw}, exit_ior=1.33)
        p = mi.load_dict({"type": "thinbirefringent", **kw, "exit_ior": 1.33})
        unscaled = [mi.load_dict({"type": "thinbirefringent", **kw, scale: 1.0, "exit_ior": 1.33})
                    for scale in ("thickness_scale", "birefringence_scale")]
        worst, apart = 0.0, [0.0, 0.0]
        for wi in random_directions(12, seed=5):
            si = surface_interaction(wi)
            for mode in ("radiance", "importance"):
                for c in (0, 1):
                    a = lobe(s, si, mode, c)
                    worst = max(worst, float(np.abs(a - lobe(p, si, mode, c)).max()))
                    for k, u in enumerate(unscaled):
                        apart[k] = max(apart[k], float(np.abs(a - lobe(u, si, mode, c)).max()))
        print(f"{name}: one-layer stack with scales vs plate: worst {worst:.2e}; "
              f"vs the plate without thickness_scale {apart[0]:.2e}, birefringence_scale {apart[1]:.2e}")
        assert worst < 2e-7
        assert min(apart) > 1e-3


def test_one_layer_is_the_plate_over_rgb_channels():
    """scalar_rgb: the stack's channel integration (its own method) against the plate's: within
    the fits' and methods' error (measured 1e-5; bound 1e-3, the plate tests' tolerance against
    quadrature), away from grazing incidence (docs/physics.md §8: beyond ~85 degrees a thin
    stack's coherent orders are more than the stack's rule resolves)."""
    variant("scalar_rgb")
    kw = dict(material="quartz", thickness=3.0, optic_axis=[0.3, 0.5, 0.81])
    s, p = stack({"type": "thinbirefringent", **kw}), mi.load_dict({"type": "thinbirefringent", **kw})
    worst = 0.0
    for wi in random_directions(8, seed=4, min_abs_cos=0.1):
        si = surface_interaction(wi)
        for c in (0, 1):
            worst = max(worst, float(np.abs(lobe(s, si, "importance", c) - lobe(p, si, "importance", c)).max()))
    print(f"rgb: one-layer stack vs plate: worst {worst:.2e}")
    assert worst < 1e-3


def calculator(query: dict) -> dict:
    out = subprocess.run([str(CALCULATOR), "stack"], input=json.dumps(query), text=True,
                         capture_output=True, check=True).stdout
    return json.loads(out)


def test_two_layers_against_the_calculator():
    """Two crossed tapes and a quartz plate at 45 degrees (axis_angle rotating each axis), light
    from wi in Importance mode: M00 and the Frobenius norm of the transmission and reflection
    Mueller matrices (both independent of the Stokes frames) against the calculator's exact
    stack, at each of the 4 wavelengths (float32: 1e-6)."""
    variant(POLARIZED)
    layers = [layer(thickness=40.0), layer(thickness=55.0, axis_angle=90.0),
              {"type": "thinbirefringent", "material": "quartz", "thickness": 20.0,
               "axis_angle": 45.0}]
    s = stack(*layers, exit_ior=1.5)
    theta, phi = 35.0, 20.0
    si = surface_interaction(direction(theta, phi))
    waves = [450.0, 500.0, 550.0, 600.0]
    for c, key in ((1, "T"), (0, "R")):
        m = lobe(s, si, "importance", c)
        for j, lam in enumerate(waves):
            axes = [[1, 0, 0], [0, 1, 0], [0.5 ** 0.5, 0.5 ** 0.5, 0]]
            q = {"wavelength_nm": lam, "theta_deg": theta, "phi_deg": phi, "ext_ior": 1.000277,
                 "exit_ior": 1.5, "layers": [
                     {"eta_o": 1.47, "eta_e": 1.478, "thickness_um": 40.0, "optic_axis": axes[0]},
                     {"eta_o": 1.47, "eta_e": 1.478, "thickness_um": 55.0, "optic_axis": axes[1]},
                     {"material": "quartz", "thickness_um": 20.0, "optic_axis": axes[2]}]}
            want = np.array(calculator(q)["mueller"][key])
            got = m[:, :, j]
            assert got[0, 0] == pytest.approx(want[0, 0], abs=1e-6)
            assert np.linalg.norm(got) == pytest.approx(np.linalg.norm(want), abs=1e-6)


def test_the_order_of_the_layers_counts():
    """Layers are nested in order from the exterior down, in dicts (insertion order, whatever
    the keys) and in XML (document order): a polariser-like dichroic layer then a retarder is
    not the retarder then the polariser, seen from the front."""
    variant(POLARIZED)
    pol = {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5, "kappa_e": 0.01,
           "thickness": 300.0}
    ret = {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.52, "thickness": 7.0,
           "axis_angle": 30.0}
    a = mi.load_dict({"type": "birefringentstack", "z": pol, "a": ret})
    b = mi.load_dict({"type": "birefringentstack", "a": ret, "z": pol})
    xml = mi.load_string("""
        <bsdf version="3.0.0" type="birefringentstack">
            <bsdf type="thinbirefringent">
                <float name="eta_o" value="1.5"/> <float name="eta_e" value="1.5"/>
                <float name="kappa_e" value="0.01"/> <float name="thickness" value="300"/>
            </bsdf>
            <bsdf type="thinbirefringent">
                <float name="eta_o" value="1.5"/> <float name="eta_e" value="1.52"/>
                <float name="thickness" value="7"/> <float name="axis_angle" value="30"/>
            </bsdf>
        </bsdf>""")
    si = surface_interaction(direction(10, 5))
    ta, tb, tx = (lobe(x, si, "importance", 1) for x in (a, b, xml))
    np.testing.assert_array_equal(ta, tx)
    # Light polarised by the first layer (S1 output of unpolarised input) vs not.
    assert np.abs(ta - tb).max() > 0.05


def test_traverse_and_update():
    variant(POLARIZED)
    s = stack(layer(), layer(axis_angle=45.0), exit_ior=1.2)
    params = mi.traverse(s)
    for key in ("ext_ior", "exit_ior", "filter_bandwidth", "layer_0.thickness.value",
                "layer_1.axis_angle.value", "layer_1.eta_e", "layer_0.optic_axis"):
        assert key in params, key
    # A nested plate's surroundings are the stack's: not exposed per layer.
    assert "layer_0.ext_ior" not in params and "layer_1.filter_bandwidth" not in params
    si = surface_interaction(direction(20))
    before = lobe(s, si, "radiance", 1)
    params["layer_1.thickness.value"] = 41.0
    params.update()
    after = lobe(s, si, "radiance", 1)
    assert np.abs(before - after).max() > 1e-4
    fresh = stack(layer(), layer(axis_angle=45.0, thickness=41.0), exit_ior=1.2)
    np.testing.assert_array_equal(after, lobe(fresh, si, "radiance", 1))
    # A rejected update (a negative thickness) raises and changes nothing.
    params["layer_0.thickness.value"] = -3.0
    with pytest.raises(RuntimeError, match="thickness"):
        params.update()
    np.testing.assert_array_equal(after, lobe(s, si, "radiance", 1))
    assert mi.traverse(s)["layer_0.thickness.value"] == pytest.approx(40.0)


ERRORS = [
    ({}, "at least one layer"),
    ({"x": {"type": "diffuse"}}, "not a thinbirefringent plate"),
    ({"x": layer(ext_ior=1.5)}, "sets \"ext_ior\""),
    ({"x": layer(filter_bandwidth=2.0)}, "sets \"filter_bandwidth\""),
    ({"x": layer(), "exit_ior": -1.0}, "exit_ior"),
    ({"x": layer(), "filter_bandwidth": -1.0}, "filter_bandwidth"),
    ({"x": layer(), "ext_ior": "unobtainium"}, "ext_ior"),
    ({f"x{k}": layer() for k in range(17)}, "at most 16 layers"),
]


@pytest.mark.parametrize("params,message", ERRORS)
def test_errors_are_clear(params, message):
    variant(POLARIZED)
    with pytest.raises(RuntimeError) as e:
        mi.load_dict({"type": "birefringentstack", **params})
    assert message in str(e.value), str(e.value)


def test_flags_and_null_transmission():
    variant(POLARIZED)
    F = mi.BSDFFlags
    s = stack(layer(), layer(axis_angle=30.0))
    sides = F.FrontSide | F.BackSide | F.Anisotropic
    assert s.flags(0) == F.DeltaReflection | sides and s.flags(1) == F.Null | sides
    glass = stack({"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5, "thickness": 10.0},
                  exit_ior=1.5)
    assert glass.flags(1) == F.DeltaTransmission | F.FrontSide | F.BackSide | F.NonSymmetric
    si = surface_interaction(direction(25, 40))
    null = np.array(s.eval_null_transmission(si))
    bs, w = sample(s, context("radiance", 1), si)
    np.testing.assert_allclose(null, w * float(bs.pdf), atol=1e-7)


def test_textures_per_layer_drive_the_stack():
    """A checkerboard of thicknesses on the second layer: each cell is the stack with that
    thickness (float32: equal)."""
    variant(POLARIZED)
    checker = {"type": "checkerboard", "color0": 30.0, "color1": 50.0}
    s = stack(layer(), layer(thickness=checker, axis_angle=45.0))
    for uv, d in (((0.25, 0.25), 50.0), ((0.75, 0.25), 30.0)):
        si = surface_interaction(direction(15), uv=uv)
        want = lobe(stack(layer(), layer(thickness=d, axis_angle=45.0)), si, "radiance", 1)
        np.testing.assert_array_equal(lobe(s, si, "radiance", 1), want)


def test_layers_are_differentiable_as_their_plates():
    """A nested plate's parameters, differentiable on a plate of its own in the llvm_ad
    variants, are differentiable as a stack's layer too (their derivatives come from the
    replayed program: test_gradients_bsdf.py's stack cases)."""
    variant("llvm_ad_spectral_polarized")
    plate = mi.traverse(mi.load_dict(layer()))
    layers = mi.traverse(stack(layer(), layer(axis_angle=45.0)))
    nondiff = int(mi.ParamFlags.NonDifferentiable)
    for key in ("eta_o", "kappa_e", "optic_axis", "thickness.value", "axis_angle.value"):
        if key in plate:
            assert not plate.flags(key) & nondiff, key
            assert not layers.flags(f"layer_1.{key}") & nondiff, key


@pytest.mark.parametrize("name", mitsuba_birefringent.VARIANTS)
def test_every_variant_loads_and_samples(name):
    """Every variant the package lists; a CUDA variant where a CUDA device exists (there a
    stack over colour channels is refused at load: its channel integral needs the host)."""
    if name.startswith("cuda_"):
        if not dr.has_backend(dr.JitBackend.CUDA):
            pytest.skip("no CUDA device on this machine")
        if "spectral" not in name:
            variant(name)
            with pytest.raises(RuntimeError, match="llvm"):
                stack(layer(), layer(axis_angle=45.0))
            return
    variant(name)
    s = stack(layer(), layer(axis_angle=45.0))
    si = surface_interaction(direction(20))
    with mitsuba_birefringent.evaluated_mode():
        bs, w = s.sample(context(), si, 0.5, mi.Point2f(0.5, 0.5))
    assert float(np.array(bs.pdf).ravel()[0]) > 0.0
