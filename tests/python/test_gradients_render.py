"""Gradients of whole renders (`mi.render`, the `path` integrator, llvm_ad_spectral_polarized, in
Mitsuba's default mode) with respect to every differentiable parameter, forward and reverse mode,
against central finite differences of the same renders (same seed; Richardson-extrapolated,
float32 images), within 1e-3 relative where the derivative is not tiny, beyond the finite
differences' own error: the images' float32 rounding over the step, which differs from machine
to machine (RENDER_ULPS), and their truncation error (grad_helpers.fd_error). The plugins'
lobes' derivatives (Dr.Jit's AD through the replayed programs) are tested lane by lane by
test_gradients_bsdf.py; here the render's wiring.

Why single-lobe scenes: attached sampling differentiates each sample's weight with its lobe
choice held fixed, which is unbiased for the derivative of the expected image; a finite
difference of a render with the same seed also moves the choice probabilities of the lanes
that keep their lobe (d(M/P) instead of dM/P), so the two agree sample by sample only where
the choice is certain. The scenes therefore give each path one lobe at our surfaces, and no
moving visibility edge (the surfaces fill the view):

- a plate with `absorbing_exit` (reflection alone) seen through a linear polariser (Mitsuba's
  `polarizer`, so that the whole Mueller matrix matters) under a constant sky: every plate
  parameter;
- an absorbing isotropic bulk (reflection alone): its indices and extinction;
- a birefringent crystal's o and e refraction: a light path through the scene written out here
  (camera rays, `scene.ray_intersect`, `sample` restricted to one component, the radiance of a
  smooth sky along the sampled direction, an analyser on the way back), so that the refracted
  direction's derivative counts;
- `prb` (Mitsuba's path-replay integrator, unpolarized variants only) with a plate in front of a
  diffuse floor: the floor's reflectance gradient equals the finite differences, and the
  plate's own parameters get none (prb samples delta lobes detached, as it does Mitsuba's
  `dielectric`: docs/gradients.md).
"""

from __future__ import annotations

import contextlib
import math

import drjit as dr
import mitsuba as mi
import numpy as np
import pytest

from grad_helpers import Derivatives, check, finite_differences, moved, step
from jit_helpers import evaluated_mode, floats

POLARIZED = "llvm_ad_spectral_polarized"
H = {k: 2.0 ** -k for k in range(20)}


def look_at(origin, target=(0, 0, 0), up=(0, 0, 1)):
    return mi.ScalarTransform4f().look_at(origin=list(origin), target=list(target), up=list(up))


def reflection_scene(bsdf: dict) -> dict:
    """A camera 40 degrees off the normal of a 6 x 6 surface (filling the view), a linear
    polariser across the view, a constant sky."""
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 5},
        "sensor": {"type": "perspective", "fov": 12, "to_world": look_at((0, -2.57, 3.06)),
                   "film": {"type": "hdrfilm", "width": 6, "height": 6, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 2}},
        "surface": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale(3), "bsdf": bsdf},
        "analyser": {"type": "rectangle",
                     "to_world": look_at((0, -2.25, 2.68), (0, -2.57 * 2, 3.06 * 2), (0, 0, 1)),
                     "bsdf": {"type": "polarizer", "theta": 30.0}},
        "sky": {"type": "constant", "radiance": 1.0},
    }


#: Rounding error of a rendered pixel, in units of U32 times the image's largest value: a
#: path's Mueller matrices multiplied in float32 (a few 4-term dot products), the spectrum
#: turned into RGB, the film's weighted sum over the samples. Measured: the images of these
#: scenes rendered at LLVM vector widths 4 and 8 and on one thread differ by at most 4.8
#: U32 of their largest value (Dr.Jit's approximate rsqrt and its summation order differ);
#: 16 leaves room for the rest of each render's own rounding.
RENDER_ULPS = 16.0


def render_derivatives(scene_dict: dict, keys: str, direction, h: float,
                       forward_mode=True, evaluated=False) -> Derivatives:
    """The derivatives of `mi.render` with respect to `s`, the parameters `keys` being moved by
    `direction * s`: forward mode (`forward_mode` False: the finite differences stand in for
    it), reverse mode of a random projection, and the finite differences of the same renders
    with their error bound. Rendered in Mitsuba's default (symbolic) mode, or in evaluated mode
    (`evaluated`: Python integrators that record `if` statements on arrays, section 4 of
    docs/gradients.md). Every `s` is opaque and carries gradients, so that each render runs
    the same kernels (a literal would be compiled into kernels of its own)."""
    scene = mi.load_dict(scene_dict)
    params = mi.traverse(scene)
    base = {k: type(params[k])(params[k]) for k in keys.split("+")}

    # mi.render's gradient pass uses another seed than its primal pass (decorrelated): the
    # finite differences render with that seed, so that both see the same samples.
    seed_grad = int(mi.sample_tea_32(3, 1)[0])

    def render(s, seed=3):
        for k, v in base.items():
            params[k] = v + direction * s
        params.update()
        return mi.render(scene, params, seed=seed, spp=2)

    with evaluated_mode() if evaluated else contextlib.nullcontext():
        fd, fd_err = finite_differences(
            lambda s: np.array(render(step(s), seed_grad), dtype=np.float64), h, RENDER_ULPS)
        forward = fd
        if forward_mode:
            s = step(0.0)
            out = render(s)
            dr.forward(s)
            forward = np.array(dr.grad(out), dtype=np.float64)
        r = np.random.default_rng(11).normal(size=fd.shape)
        s = step(0.0)
        out = render(s)
        dr.backward(dr.sum(out * mi.TensorXf(r.astype(np.float32)), axis=None))
        reverse = float(dr.grad(s)[0])
    return image_derivatives(forward, fd, fd_err, reverse, r)


def image_derivatives(forward, fd, fd_err, reverse: float, r: np.ndarray) -> Derivatives:
    """Derivatives of an image (every pixel compared), `r` the projection's weights."""
    fd_err = np.broadcast_to(fd_err, fd.shape)
    return Derivatives(forward, fd, reverse, float((fd * r).sum()), np.ones(1, dtype=bool),
                       fd_err, float((np.abs(r) * fd_err).sum()))


def check_render(d: Derivatives):
    check(d, min_lanes=1)


PLATE = {"type": "thinbirefringent", "eta_o": 1.54, "eta_e": 1.55, "kappa_o": 0.005,
         "kappa_e": 0.004, "thickness": 2.0, "birefringence": 0.002, "axis_angle": 20.0,
         "optic_axis": [1.0, 0.3, 0.2], "exit_ior": 1.3, "absorbing_exit": True}
OPAQUE = {"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "kappa_o": 0.5, "kappa_e": 0.5}

# Steps: powers of two (x + k h exact in float32), each the one whose error bound
# (grad_helpers.fd_error: the image's rounding / h against the truncation ~ h^4) is least,
# measured over 2^3 .. 2^-12: 0.9-2.5e-4 of the largest derivative (the kappas at 2^-10, the
# largest step that keeps 4h below them).
RENDER_CASES = [
    ("plate-thickness", PLATE, "surface.bsdf.thickness.value", 1.0, H[9]),
    ("plate-birefringence", PLATE, "surface.bsdf.birefringence.value", 1.0, H[9]),
    ("plate-axis_angle", PLATE, "surface.bsdf.axis_angle.value", 1.0, 2.0),
    ("plate-eta_o", PLATE, "surface.bsdf.eta_o", 1.0, H[10]),
    ("plate-eta_e", PLATE, "surface.bsdf.eta_e", 1.0, H[9]),
    ("plate-kappa_o", PLATE, "surface.bsdf.kappa_o", 1.0, H[10]),
    ("plate-kappa_e", PLATE, "surface.bsdf.kappa_e", 1.0, H[10]),
    ("plate-optic_axis", PLATE, "surface.bsdf.optic_axis", "y", H[5]),
    ("crystal-eta", OPAQUE, "surface.bsdf.eta_o+surface.bsdf.eta_e", 1.0, H[5]),
    ("crystal-kappa", OPAQUE, "surface.bsdf.kappa_o+surface.bsdf.kappa_e", 1.0, H[5]),
]


@pytest.mark.parametrize("case", RENDER_CASES, ids=[c[0] for c in RENDER_CASES])
def test_render_gradient(case):
    _, bsdf, keys, direction, h = case
    mi.set_variant(POLARIZED)
    if isinstance(direction, str):
        direction = mi.Vector3f(*[1.0 if c == direction else 0.0 for c in "xyz"])
    check_render(render_derivatives(reflection_scene(bsdf), keys, direction, h))


def polariscope_scene(stress: float) -> dict:
    """The photoelastic disk's set-up at normal incidence (an orthographic camera straight down
    the optical axis, where every Stokes frame of the path coincides): a circular polariser, an
    immersed stressed plate (ext_ior = exit_ior = its index: no reflection, one lobe), a crossed
    circular analyser."""
    from _common import backlight, layer, ortho_sensor

    plate = {"type": "thinbirefringent", "eta_o": 1.585, "eta_e": 1.585, "ext_ior": 1.585,
             "exit_ior": 1.585, "thickness": 6000.0, "birefringence": stress,
             "birefringence_scale": 8e-5, "axis_angle": 30.0}
    # Russian roulette off (rr_depth beyond the path): its survival probability follows the
    # throughput, which makes the estimate flat in it (a finite difference then sees ~0).
    return {"type": "scene", "integrator": {"type": "volpath", "max_depth": 8, "rr_depth": 100},
            "sensor": ortho_sensor(6, 6, 2, 1.0, 1.0),
            "light": backlight(-3.0, 4.0),
            "polarizer": layer(-2.0, 2, 2, {"type": "polarizer", "theta": 0.0}),
            "qwp_in": layer(-1.5, 2, 2, {"type": "retarder", "theta": 45.0, "delta": 90.0}),
            "plate": layer(0.0, 2, 2, plate),
            "qwp_out": layer(1.5, 2, 2, {"type": "retarder", "theta": -45.0, "delta": 90.0}),
            "analyser": layer(2.0, 2, 2, {"type": "polarizer", "theta": 90.0})}


@pytest.mark.parametrize("key,h", [("plate.bsdf.birefringence.value", H[8]),
                                   ("plate.bsdf.axis_angle.value", 0.5)])
def test_polariscope_at_normal_incidence(key, h):
    """The disk's own geometry: gradients finite (no NaN from the frame rotations at exactly
    normal incidence, where a sampled direction attached to the graph would differentiate
    sqrt at 0: columns that are zero in every lane are not attached) and equal to the finite
    differences. Under crossed circular polarisers the image is (1/2) sin^2(delta / 2), blind
    to the axis: its derivative must vanish."""
    import sys
    import pathlib

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
    mi.set_variant(POLARIZED)
    d = render_derivatives(polariscope_scene(0.4), key, 1.0, h)
    assert np.all(np.isfinite(d.forward)) and np.isfinite(d.reverse)
    if "axis_angle" in key:
        assert np.abs(d.forward).max() < 1e-6 and abs(d.reverse) < 1e-5 and np.abs(d.fd).max() < 1e-4
        return
    check_render(d)


CRYSTAL = {"type": "birefringent", "eta_o": 1.55, "eta_e": 1.65, "optic_axis": [0.3, 0.5, 0.8]}


def sky(d):
    """A smooth sky radiance along world direction `d`."""
    return 1.0 + 0.6 * d.x + 0.3 * d.y * d.y


def refraction_image(key: str, direction, s, component: int):
    """The light path of the module docstring through a crystal face at z = 0: camera rays from
    a 5 x 5 grid, 35 degrees off the normal, the crystal's lobe `component` (1: o, 2: e) sampled
    alone (probability 1), the sky along the refracted direction, seen through an analyser at
    0 degrees in the frame of the light leaving towards the camera: (1/2)(S0 + S1) per sampled
    wavelength."""
    scene = mi.load_dict({"type": "scene",
                          "face": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale(10),
                                   "bsdf": CRYSTAL}})
    params = mi.traverse(scene)
    moved(params, "face.bsdf." + key, direction, s)
    g = np.linspace(-0.5, 0.5, 5)
    x, y = [a.ravel().astype(np.float32) for a in np.meshgrid(g, g)]
    t = math.radians(35.0)
    d = mi.Vector3f(math.sin(t), 0.2, -math.cos(t))
    ray = mi.Ray3f(o=mi.Point3f(floats(x), floats(y), floats(np.full_like(x, 2.0))),
                   d=dr.normalize(d), wavelengths=mi.UnpolarizedSpectrum(450.0, 520.0, 590.0, 660.0))
    with evaluated_mode():
        si = scene.ray_intersect(ray)
        ctx = mi.BSDFContext()
        ctx.component = component
        bs, w = si.bsdf().sample(ctx, si, mi.Float(0.5), mi.Point2f(0.5, 0.5))
        L = sky(si.to_world(bs.wo))
        return 0.5 * (w[0, 0] + w[1, 0]) * L


# Steps (powers of two), per ray: the least error bound among 2^-2 .. 2^-9, measured; the
# o-ray's weak dependence on eta_e (0.006 against values of 0.5) at 2^-4, 7.6e-4 of it.
@pytest.mark.parametrize("key,direction,steps", [("eta_o", 1.0, (H[5], H[5])),
                                                 ("eta_e", 1.0, (H[4], H[6])),
                                                 ("optic_axis", "x", (H[6], H[6]))])
@pytest.mark.parametrize("component", [1, 2], ids=["o", "e"])
def test_refraction_path_gradient(key, direction, steps, component):
    mi.set_variant(POLARIZED)
    h = steps[component - 1]
    if isinstance(direction, str):
        direction = mi.Vector3f(*[1.0 if c == direction else 0.0 for c in "xyz"])
    fd, fd_err = finite_differences(
        lambda s: np.array(refraction_image(key, direction, mi.Float(s), component),
                           dtype=np.float64), h, RENDER_ULPS)
    s = mi.Float(0.0)
    dr.enable_grad(s)
    out = refraction_image(key, direction, s, component)
    dr.forward(s)
    forward = np.array(dr.grad(out), dtype=np.float64)
    r = np.random.default_rng(2).normal(size=fd.shape)
    s = mi.Float(0.0)
    dr.enable_grad(s)
    out = refraction_image(key, direction, s, component)
    with evaluated_mode():
        dr.backward(dr.sum(dr.ravel(out) * mi.Float(r.ravel(order="F").astype(np.float32))))
    reverse = float(dr.grad(s)[0])
    # (The o-ray's direction does not depend on eta_e, its amplitudes do: the boundary
    # conditions couple the o and e waves.)
    check_render(image_derivatives(forward, fd, fd_err, reverse, r))


def prb_scene(integrator: str) -> dict:
    return {"type": "scene", "integrator": {"type": integrator, "max_depth": 6},
            "sensor": {"type": "perspective", "fov": 30, "to_world": look_at((0, 0, 4), up=(0, 1, 0)),
                       "film": {"type": "hdrfilm", "width": 6, "height": 6, "rfilter": {"type": "box"}},
                       "sampler": {"type": "independent", "sample_count": 2}},
            "plate": {"type": "rectangle", "to_world": mi.ScalarTransform4f().translate([0, 0, 1]).scale(3),
                      "bsdf": {"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.55,
                               "thickness": 2.0, "optic_axis": [1.0, 0.3, 0.0]}},
            "floor": {"type": "rectangle", "to_world": mi.ScalarTransform4f().scale(3),
                      "bsdf": {"type": "diffuse", "reflectance": 0.5}},
            "light": {"type": "constant"}}


@pytest.mark.parametrize("variant,integrator", [("llvm_ad_rgb", "prb"), ("llvm_ad_mono", "prb"),
                                                ("llvm_ad_spectral", "prb"),
                                                ("llvm_ad_spectral", "prb_basic")])
def test_prb_in_the_unpolarized_variants(variant, integrator):
    """prb and prb_basic run with the plugins in evaluated mode (which switches Dr.Jit's
    symbolic conditionals off too: prb records its `if`s); the floor's reflectance gradient
    equals the finite differences (the render is affine in it), in reverse mode and, except in
    llvm_ad_spectral (where Mitsuba 3.9.1's prb fails in forward mode by itself: its loop state
    changes type), in forward mode. In llvm_ad_spectral the plate's thickness gets no gradient
    from prb, while `path` gives one (prb samples delta lobes detached)."""
    mi.set_variant(variant)
    spectral = variant == "llvm_ad_spectral"
    check_render(render_derivatives(prb_scene(integrator), "floor.bsdf.reflectance.value",
                                    1.0, H[6], forward_mode=not spectral, evaluated=True))
    if not spectral:
        return
    for name, expect_zero in ((integrator, True), ("path", False)):
        scene = mi.load_dict(prb_scene(name))
        params = mi.traverse(scene)
        with evaluated_mode():
            dr.enable_grad(params["plate.bsdf.thickness.value"])
            params.update()
            img = mi.render(scene, params, seed=1, spp=2)
            dr.backward(dr.sum(img, axis=None))
            g = float(dr.grad(params["plate.bsdf.thickness.value"])[0])
        assert (g == 0.0) == expect_zero, (name, g)
