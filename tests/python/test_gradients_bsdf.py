"""Gradients of the plugins' sampled lobes (`weight * pdf` of `sample`, and
`eval_null_transmission`) in the llvm_ad variants, with respect to every differentiable
parameter and to `si.wi`, in forward and reverse mode, against central finite differences of
the same lanes (grad_helpers.py: Richardson-extrapolated, float32 as Mitsuba returns it; lanes
whose lobe choice flips within the steps are left out). Tolerance 1e-3 relative where the
derivative is not tiny (the issue's bar), beyond the finite differences' own error bound. The
derivatives are Dr.Jit's AD through the replayed programs (docs/gradients.md). Birefringent
parameters, not only the isotropic limit: a birefringent, dichroic plate with stress
birefringence and a tilted axis; a stack's second layer; calcite-like constant indices with a
tilted axis; an absorbing isotropic bulk for kappa.
"""

from __future__ import annotations

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from grad_helpers import check, derivatives, moved
from jit_helpers import batch_si, floats, random_directions

LANES = 48
POLARIZED = "llvm_ad_spectral_polarized"

PLATE = {"type": "thinbirefringent", "eta_o": 1.54, "eta_e": 1.55, "kappa_o": 0.002,
         "kappa_e": 0.001, "thickness": 2.0, "birefringence": 0.002, "axis_angle": 20.0,
         "optic_axis": [1.0, 0.3, 0.2], "ext_ior": 1.0, "exit_ior": 1.3}
CRYSTAL = {"type": "birefringent", "eta_o": 1.55, "eta_e": 1.65, "optic_axis": [0.3, 0.5, 0.8],
           "ext_ior": 1.0}
ABSORBING = {"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "kappa_o": 0.5, "kappa_e": 0.5,
             "ext_ior": 1.0}
GLASS = {"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0}
STACK = {"type": "birefringentstack", "ext_ior": 1.0, "exit_ior": 1.3,
         "plate_0": {"type": "thinbirefringent", "eta_o": 1.54, "eta_e": 1.55, "thickness": 1.5,
                     "optic_axis": [1.0, 0.0, 0.0]},
         "plate_1": {"type": "thinbirefringent", "eta_o": 1.54, "eta_e": 1.56, "kappa_e": 0.001,
                     "thickness": 2.0, "axis_angle": 30.0, "optic_axis": [1.0, 0.3, 0.2]}}


def lanes(seed: int, upper: bool = False):
    """(wi, wavelengths, u, tangent of wi) of LANES random lanes."""
    rng = np.random.default_rng(seed)
    wi = random_directions(LANES, rng, min_abs_cos=0.2).astype(np.float64)
    if upper:
        wi[:, 2] = np.abs(wi[:, 2])
    waves = rng.uniform(400.0, 700.0, size=(LANES, 4))
    u = rng.uniform(size=LANES)
    t = np.cross(wi, rng.normal(size=(LANES, 3)))
    t /= np.linalg.norm(t, axis=1)[:, None]
    return wi, waves, u, t


def maker(variant: str, desc: dict, key: str, direction, seed: int = 1, upper: bool = False,
          mode: str = "radiance"):
    """`make(s)`: the BSDF with `key` moved by `direction * s` ("wi": si.wi turned towards a
    random tangent by `s` radians; "a+b": both parameters moved), its surface interaction, lobe
    numbers and context."""
    wi, waves, u, t = lanes(seed, upper)

    def make(s):
        mi.set_variant(variant)
        bsdf = mi.load_dict(desc)
        if key != "wi":
            moved(mi.traverse(bsdf), key, direction, s)
        si = batch_si(wi.astype(np.float32), waves.astype(np.float32))
        if key == "wi":
            w = mi.Vector3f(*[floats(wi[:, k]) for k in range(3)])
            tv = mi.Vector3f(*[floats(t[:, k]) for k in range(3)])
            si.wi = dr.normalize(w + tv * s)
        ctx = mi.BSDFContext(mi.TransportMode.Radiance if mode == "radiance"
                             else mi.TransportMode.Importance)
        return bsdf, si, floats(u), ctx

    return make


# Steps of s: powers of two, so that x0 + k h is exact in float32 (a rounded step of 1 ulp
# would be an error of 2e-4 at h = 5e-4 around 1.5). Each case's step is the one whose error
# bound (grad_helpers.fd_error: rounding / h against truncation ~ h^4) is least among 2^-4 ..
# 2^-14, measured: 0.14-2.7e-4 of the largest derivative (the plate's fringes limit its steps
# to 2^-10 .. 2^-12, a crystal's to 2^-9 .. 2^-10; a direction's own rounding, the rest).
H = {k: 2.0 ** -k for k in range(20)}

# (id, variant, description, key, direction, step of s, lanes on the upper side only)
CASES = [
    # The plate: each differentiable parameter (textures through their values).
    ("plate-thickness", POLARIZED, PLATE, "thickness.value", 1.0, H[10], False),
    ("plate-birefringence", POLARIZED, PLATE, "birefringence.value", 1.0, H[12], False),
    ("plate-axis_angle", POLARIZED, PLATE, "axis_angle.value", 1.0, 0.5, False),
    ("plate-eta_o", POLARIZED, PLATE, "eta_o", 1.0, H[12], False),
    ("plate-eta_e", POLARIZED, PLATE, "eta_e", 1.0, H[12], False),
    ("plate-kappa_o", POLARIZED, PLATE, "kappa_o", 1.0, H[12], False),
    ("plate-kappa_e", POLARIZED, PLATE, "kappa_e", 1.0, H[12], False),
    ("plate-optic_axis", POLARIZED, PLATE, "optic_axis", "y", H[6], False),
    ("plate-wi", POLARIZED, PLATE, "wi", None, H[9], False),
    ("plate-thickness-spectral", "llvm_ad_spectral", PLATE, "thickness.value", 1.0, H[10], False),
    # A stack's layers (each a plate's parameters), the second layer of two.
    ("stack-layer-thickness", POLARIZED, STACK, "layer_1.thickness.value", 1.0, H[10], False),
    ("stack-layer-optic_axis", POLARIZED, STACK, "layer_1.optic_axis", "y", H[6], False),
    ("stack-layer-eta_e", POLARIZED, STACK, "layer_1.eta_e", 1.0, H[12], False),
    # The crystal: calcite-like constant indices, a tilted axis (double refraction).
    ("crystal-eta_o", POLARIZED, CRYSTAL, "eta_o", 1.0, H[9], False),
    ("crystal-eta_e", POLARIZED, CRYSTAL, "eta_e", 1.0, H[9], False),
    ("crystal-optic_axis", POLARIZED, CRYSTAL, "optic_axis", "x", H[10], False),
    ("crystal-wi", POLARIZED, CRYSTAL, "wi", None, H[9], False),
    ("crystal-optic_axis-mono", "llvm_ad_mono_polarized", CRYSTAL, "optic_axis", "x", H[10], False),
    # An isotropic crystal stays isotropic (the only absorbing one is isotropic): its pair of
    # indices moves together, each carrying half the derivative (test_isotropic_pair_splits).
    ("crystal-kappa", POLARIZED, ABSORBING, "kappa_o+kappa_e", 1.0, H[6], True),
    ("crystal-eta-rgb", "llvm_ad_rgb", GLASS, "eta_o+eta_e", 1.0, H[10], False),
]


def direction_of(d):
    if isinstance(d, str):
        return mi.Vector3f(*[1.0 if c == d else 0.0 for c in "xyz"])
    return d


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_sampled_lobe_gradient(case):
    name, variant, desc, key, direction, h, upper = case
    mi.set_variant(variant)
    make = maker(variant, desc, key, direction_of(direction), upper=upper)
    check(derivatives(make, h, direction=key == "wi"))


@pytest.mark.parametrize("key,h", [("thickness.value", H[11]), ("birefringence.value", H[12]),
                                   ("wi", H[9])])
def test_null_transmission_gradient(key, h):
    """eval_null_transmission (the plate between equal media: what volpath's shadow rays see)."""
    mi.set_variant(POLARIZED)
    desc = {**PLATE, "exit_ior": 1.0}
    make = maker(POLARIZED, desc, key, 1.0, upper=True)
    check(derivatives(make, h, null=True, direction=key == "wi"))


@pytest.mark.parametrize("variant,desc,pair", [(POLARIZED, ABSORBING, ("kappa_o", "kappa_e")),
                                               ("llvm_ad_rgb", GLASS, ("eta_o", "eta_e"))])
def test_isotropic_pair_splits(variant, desc, pair):
    """An isotropic crystal's derivative with respect to eta_o (kappa_o) alone is half of that
    along the pair (moving one would split the refraction into o and e rays), as is eta_e's."""
    mi.set_variant(variant)
    grads = {}
    for keys in (pair[0], pair[1], "+".join(pair)):
        s = mi.Float(0.0)
        dr.enable_grad(s)
        from grad_helpers import evaluate
        w, _, _ = evaluate(maker(variant, desc, keys, 1.0, upper=True), s)
        dr.forward(s)
        grads[keys] = np.array(dr.grad(w), dtype=np.float64)
    both = grads["+".join(pair)]
    assert np.abs(both).max() > 1e-3
    for k in pair:
        np.testing.assert_allclose(grads[k], 0.5 * both, rtol=1e-5, atol=1e-7 * np.abs(both).max())
