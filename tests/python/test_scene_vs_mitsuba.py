"""Whole renders against Mitsuba's own plugins in the limits where they must agree.

Statistical test: each scene is rendered R = 16 times with independent seeds per BSDF; per 4x4
block of pixels the two sets of block means are compared by Welch's statistic
z = (mean_a - mean_b) / sqrt(se_a^2 + se_b^2). With 16 renders per side the statistic is close to
normal (about 30 degrees of freedom); the threshold 5.0 on max |z| over all blocks gives a
family-wise false-alarm rate below 64 blocks x 2 x P(|t_30| > 5) ~ 3e-3 even with heavier t
tails (below 1e-4 for a normal statistic), while any systematic difference larger than a few
standard errors of a block fails.
"""

import numpy as np
import mitsuba as mi

import mitsuba_birefringent  # noqa: F401

RENDERS, SIZE, BLOCK, THRESHOLD = 16, 32, 4, 5.0


def renders(scene_dict):
    scene = mi.load_dict(scene_dict)
    out = []
    for seed in range(RENDERS):
        img = np.array(mi.render(scene, seed=seed))[..., :3].mean(axis=-1)
        out.append(img.reshape(SIZE // BLOCK, BLOCK, SIZE // BLOCK, BLOCK).mean(axis=(1, 3)))
    return np.array(out)


def max_z(a, b):
    mean = lambda x: x.mean(axis=0)
    se2 = lambda x: x.var(axis=0, ddof=1) / len(x)
    z = (mean(a) - mean(b)) / np.sqrt(se2(a) + se2(b) + 1e-30)
    return float(np.abs(z).max()), float(np.abs(mean(a) - mean(b)).max()), float(mean(a).mean())


def glass_scene(bsdf):
    T = mi.ScalarTransform4f
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 8},
        "sensor": {"type": "perspective", "fov": 40,
                   "to_world": T().look_at(origin=[0, -3, 2], target=[0, 0, 0.3], up=[0, 0, 1]),
                   "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 8}},
        "light": {"type": "rectangle", "to_world": T().translate([0, 1.5, 2.5]).rotate([1, 0, 0], 120),
                  "emitter": {"type": "area", "radiance": {"type": "d65", "scale": 3.0}}},
        "floor": {"type": "rectangle", "to_world": T().scale(4),
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "checkerboard",
                           "to_uv": mi.ScalarTransform4f().scale([8, 8, 1])}}},
        "glass": {"type": "sphere", "center": [0, 0, 0.7], "radius": 0.6, "bsdf": bsdf},
    }


def test_isotropic_crystal_renders_like_dielectric():
    mi.set_variant("scalar_spectral_polarized")
    ours = renders(glass_scene({"type": "birefringent", "eta_o": 1.5, "eta_e": 1.5, "ext_ior": 1.0}))
    theirs = renders(glass_scene({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}))
    z, diff, level = max_z(ours, theirs)
    print(f"glass sphere: max |z| = {z:.2f} over {ours.shape[1] * ours.shape[2]} blocks, "
          f"max |difference| = {diff:.4f} (mean level {level:.4f})")
    assert z < THRESHOLD


def plate_scene(bsdf):
    T = mi.ScalarTransform4f
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": {"type": "orthographic",
                   "to_world": T().look_at(origin=[0, 0, 3], target=[0, 0, 0], up=[0, 1, 0]),
                   "film": {"type": "hdrfilm", "width": SIZE, "height": SIZE,
                            "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": 8}},
        "light": {"type": "rectangle", "to_world": T().translate([0, 0, -2]).scale(3),
                  "emitter": {"type": "area", "radiance": {"type": "checkerboard",
                              "color0": 0.2, "color1": 1.0,
                              "to_uv": mi.ScalarTransform4f().scale([4, 4, 1])}}},
        "plate": {"type": "rectangle", "to_world": T().scale(2), "bsdf": bsdf},
    }


def test_thick_isotropic_plate_renders_like_thindielectric_at_normal_incidence():
    """Orthographic view through a plate onto a light: normal incidence everywhere, where the
    incoherent plate and Mitsuba's thindielectric must agree (scalar_rgb: our closed-form RGB
    integration of a 1 mm plate)."""
    mi.set_variant("scalar_rgb")
    ours = renders(plate_scene({"type": "thinbirefringent", "eta_o": 1.5, "eta_e": 1.5,
                                "ext_ior": 1.0, "thickness": 1000.0}))
    theirs = renders(plate_scene({"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0}))
    z, diff, level = max_z(ours, theirs)
    print(f"plate: max |z| = {z:.2f}, max |difference| = {diff:.5f} (mean level {level:.4f})")
    assert z < THRESHOLD


def test_the_comparison_detects_a_wrong_index():
    """Power check of the statistic: the same glass scene with int_ior 1.5 against 1.6 must fail
    the test above (otherwise its agreement would mean nothing)."""
    mi.set_variant("scalar_spectral_polarized")
    a = renders(glass_scene({"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}))
    b = renders(glass_scene({"type": "dielectric", "int_ior": 1.6, "ext_ior": 1.0}))
    z, _, _ = max_z(a, b)
    print(f"1.5 vs 1.6: max |z| = {z:.2f}")
    assert z > THRESHOLD
