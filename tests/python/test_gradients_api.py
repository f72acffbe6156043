"""What the gradient machinery promises besides the derivatives' values (docs/gradients.md):
which parameters `mi.traverse` flags differentiable (as the docs mark them), that attaching
gradients changes no value, that a query which cannot give derivatives says why instead of
returning zeros, and that a rejected update keeps a differentiable handle as it was.
"""

from __future__ import annotations

import importlib.util
import pathlib
import sys

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from jit_helpers import batch_si, evaluated_mode, floats, random_directions

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLATE = {"type": "thinbirefringent", "eta_o": 1.54, "eta_e": 1.55, "thickness": 2.0,
         "birefringence": 0.002, "axis_angle": 20.0, "optic_axis": [1.0, 0.3, 0.2],
         "exit_ior": 1.3}
CRYSTAL = {"type": "birefringent", "eta_o": 1.55, "eta_e": 1.65, "optic_axis": [0.3, 0.5, 0.8]}


def documented_differentiable(plugin: str) -> set[str]:
    spec = importlib.util.spec_from_file_location("plugin_docs", ROOT / "tools" / "plugin_docs.py")
    docs = importlib.util.module_from_spec(spec)
    sys.modules["plugin_docs"] = docs  # dataclasses look their module up there
    spec.loader.exec_module(docs)
    _, params = docs.parameters((ROOT / "cpp" / "src" / f"{plugin}.cpp").read_text())
    return {n for p in params if "differentiable" in p.flags for n in p.names()}


@pytest.mark.parametrize("desc", [PLATE, CRYSTAL], ids=["thinbirefringent", "birefringent"])
def test_traverse_flags_the_documented_parameters_differentiable(desc):
    """In an llvm_ad variant exactly the parameters the docs mark differentiable are (a texture
    through its own values), in a scalar variant none."""
    mi.set_variant("llvm_ad_spectral_polarized")
    params = mi.traverse(mi.load_dict(desc))
    differentiable = {k.split(".")[0] for k in params.keys()
                      if not params.flags(k) & mi.ParamFlags.NonDifferentiable}
    assert differentiable == documented_differentiable(desc["type"])
    mi.set_variant("scalar_spectral_polarized")
    params = mi.traverse(mi.load_dict(desc))
    assert all(params.flags(k) & mi.ParamFlags.NonDifferentiable for k in params.keys())


def sample_weights(bsdf, wi, grad_key=None):
    si = batch_si(wi)
    with evaluated_mode():
        if grad_key:
            params = mi.traverse(bsdf)
            dr.enable_grad(params[grad_key])
            params.update()
        bs, w = bsdf.sample(mi.BSDFContext(), si, floats(np.linspace(0.01, 0.99, len(wi))),
                            mi.Point2f(0.5, 0.5))
        return dr.grad_enabled(w), np.array(dr.detach(w)), np.array(dr.detach(bs.wo))


@pytest.mark.parametrize("desc,key", [(PLATE, "thickness.value"), (PLATE, "optic_axis"),
                                      (CRYSTAL, "eta_e"), (CRYSTAL, "optic_axis")])
def test_attaching_gradients_changes_no_value(desc, key):
    """The same lanes with and without a parameter carrying gradients: weights and directions
    equal to float32 rounding. With gradients the parameter is an input of the recorded program
    instead of a constant folded into it, so the kernel computes the same float64 expressions in
    another order (LLVM may contract a product and a sum into one fma): the float64 results move
    by a few 1e-16 and their float32 rounding by at most one unit in the last place, or by
    1e-6 of the largest entry where an entry is the difference of larger ones."""
    mi.set_variant("llvm_ad_spectral_polarized")
    wi = random_directions(40, np.random.default_rng(3))
    plain = sample_weights(mi.load_dict(desc), wi)
    attached = sample_weights(mi.load_dict(desc), wi, key)
    assert not plain[0] and attached[0]
    for a, p in zip(attached[1:], plain[1:]):
        ulp = np.spacing(np.maximum(np.abs(a), np.abs(p)).astype(np.float32))
        bound = ulp + 1e-6 * np.abs(p).max()
        assert np.all(np.abs(a - p) <= bound), np.abs(a - p).max()


@pytest.mark.parametrize("variant,desc,key,words", [
    ("llvm_ad_rgb", PLATE, "thickness.value", ["llvm_ad_rgb", "llvm_ad_spectral"]),
    ("llvm_ad_mono_polarized", PLATE, "eta_e", ["llvm_ad_mono", "llvm_ad_spectral_polarized"]),
    ("llvm_ad_spectral", {**PLATE, "filter_bandwidth": 4.0}, "thickness.value", ["filter_bandwidth"]),
    ("llvm_ad_spectral_polarized", CRYSTAL, "kappa_o", ["kappa_o", "cannot absorb"]),
])
def test_no_derivatives_is_an_error_with_the_reason(variant, desc, key, words):
    """Where the core has no derivatives (a plate integrated over colour channels or a band; the
    extinction of a birefringent crystal) the query raises, naming what to use instead, rather
    than returning a gradient of zero."""
    mi.set_variant(variant)
    bsdf = mi.load_dict(desc)
    with pytest.raises(RuntimeError) as e:
        sample_weights(bsdf, random_directions(4, np.random.default_rng(1)), key)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_rejected_update_keeps_the_differentiable_handle():
    """An invalid eta_o set through the handle is refused; the handle, its value and the lobes
    stay as before (the core keeps the double given at load, not its float)."""
    mi.set_variant("llvm_ad_spectral_polarized")
    bsdf = mi.load_dict(CRYSTAL)
    wi = random_directions(16, np.random.default_rng(5))
    before = sample_weights(bsdf, wi)[1]
    params = mi.traverse(bsdf)
    params["eta_o"] = -1.0
    with pytest.raises(RuntimeError, match="eta_o"):
        params.update()
    params = mi.traverse(bsdf)
    assert float(params["eta_o"][0]) == pytest.approx(1.55)
    assert not params.flags("eta_o") & mi.ParamFlags.NonDifferentiable
    np.testing.assert_array_equal(sample_weights(bsdf, wi)[1], before)
    params["eta_o"] = 1.6
    params.update()
    assert np.abs(sample_weights(bsdf, wi)[1] - before).max() > 1e-4
