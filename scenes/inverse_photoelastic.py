"""Inverse photoelasticity: the stress birefringence and principal directions of a loaded disk
recovered from polarised images by gradient descent through the renderer.

What it shows: target images of the photoelastic disk (scenes/photoelastic_disk.py: a disk
under diametral compression, the closed-form field of Hertz and Michell) are rendered from the
known field at several wavelengths, behind a circular polariser; then the plate's two textures,
`birefringence` (sigma_1 - sigma_2, MPa) and `axis_angle` (the direction of sigma_1, degrees),
start uniform and are fitted to the targets with Mitsuba's Adam optimiser, the gradients flowing
through `mi.render` (llvm_ad_spectral_polarized, the `path` integrator, the plugins' derivatives:
docs/gradients.md). The recovered maps are compared with the known field.

Identifiability (the design of the targets): between crossed circular polarisers the image is
(1/2) sin^2(delta / 2), blind to the principal direction theta. The targets are therefore the
images of several analyser states behind the circular polariser: crossed circular (the classic
isochromatics, (S0 - S3) / 2), and linear at 0 and 45 degrees ((S0 + S1) / 2, (S0 + S2) / 2,
which carry sin(delta) cos(2 theta) and sin(delta) sin(2 theta)), read from Mitsuba's `stokes`
integrator (the Stokes vector those analysers measure). They fix theta modulo 180 degrees where
sin(delta) > 0: the load is chosen so that the retardance stays below pi at every wavelength
(the stress is clipped next to the loads, where it diverges), and sigma_1 - sigma_2 >= 0 is kept
by the fit (it is non-negative by definition). theta is compared modulo 180 degrees, and only
where the retardance is above a tenth of its largest (at an isotropic point the direction is
undefined). The disk is immersed in an index-matching liquid (ext_ior = exit_ior = its index,
as in an immersion polariscope): no reflections, so every path takes the same lobe and the fit
sees no sampling noise beyond the pixel positions, which the targets share (the same seed).

Reported: the retardance error (RMS over the texture, relative to the known field's range) and
the principal-direction error (RMS, degrees, where the retardance is not near 0), the loss
curve and the time; the figure shows a target, the start, the result and the loss.

    .venv/bin/python scenes/inverse_photoelastic.py [--texture 24] [--size 72]
        [--iterations 150] [--out out]

writes <out>/inverse_photoelastic.json and .png. tests/python/test_inverse_photoelastic.py runs
it at a small size against the issue's targets (retardance RMS <= 2 % of its range, direction
RMS <= 2 degrees).
"""

from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _common import backlight, data_texture, layer, ortho_sensor  # noqa: E402
from photoelastic_disk import VIEW_HALF, principal_maps  # noqa: E402

VARIANT = "llvm_ad_spectral_polarized"

#: The disk of scenes/photoelastic_disk.py (50 mm, 6 mm thick, index 1.585, C = 8e-11 / Pa)
#: under a load small enough that the retardance stays below pi.
DIAMETER_MM, THICKNESS_MM, INDEX, STRESS_OPTIC_PER_PA = 50.0, 6.0, 1.585, 8e-11
LOAD_N = 40.0
#: sigma_1 - sigma_2 is clipped here (MPa): a fringe order of 0.45 at 450 nm.
MAX_MPA = 0.45 * 450e-9 / (STRESS_OPTIC_PER_PA * THICKNESS_MM * 1e-3) / 1e6
#: Retardance below this fraction of its largest: the direction is not compared there.
NEAR_ZERO = 0.1
#: Adam's step sizes decay geometrically to this fraction of their start over the iterations.
DECAY = 0.05


def known_field(texture: int) -> tuple[np.ndarray, np.ndarray]:
    """(sigma_1 - sigma_2 in MPa, direction of sigma_1 in degrees) on a texture x texture grid."""
    return principal_maps(texture, LOAD_N, DIAMETER_MM, THICKNESS_MM, MAX_MPA)


def scene_dict(size: int, dsigma: np.ndarray, angle: np.ndarray,
               wavelengths: tuple[float, ...]) -> dict:
    """The disk behind a circular polariser, one monochromatic Stokes camera per wavelength."""
    disk = {"type": "thinbirefringent", "eta_o": INDEX, "eta_e": INDEX, "ext_ior": INDEX,
            "exit_ior": INDEX, "thickness": THICKNESS_MM * 1e3,
            "birefringence": data_texture(dsigma),
            "birefringence_scale": STRESS_OPTIC_PER_PA * 1e6,
            "axis_angle": data_texture(angle)}
    d = {
        "type": "scene",
        # Russian roulette off: its survival probability follows the throughput, which would
        # make the loss jump with the fitted parameters.
        "integrator": {"type": "stokes",
                       "integrator": {"type": "path", "max_depth": 8, "rr_depth": 100}},
        "light": backlight(-3.0, 4.0),
        "polarizer": layer(-2.0, 2, 2, {"type": "polarizer", "theta": 0.0}),
        "qwp_in": layer(-1.5, 2, 2, {"type": "retarder", "theta": 45.0, "delta": 90.0}),
        "disk": layer(0.0, 1.0, 1.0, disk),
    }
    for k, w in enumerate(wavelengths):
        d[f"sensor_{k}"] = ortho_sensor(size, size, 1, VIEW_HALF, VIEW_HALF, wavelength_nm=w,
                                        single_channel=False)
    return d


def analyser_images(image):
    """(crossed circular, linear 0 deg, linear 45 deg) analyser images of a `stokes` render
    (15 channels: RGB, then S0..S3 as RGB; the sum of the three channels of each)."""
    import drjit as dr

    s = [dr.sum(image[:, :, 3 + 3 * k: 6 + 3 * k], axis=2) for k in range(4)]
    return (s[0] - s[3]) * 0.5, (s[0] + s[1]) * 0.5, (s[0] + s[2]) * 0.5


def direction_error(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """|a - b| in degrees, modulo 180 (a principal direction has no sign)."""
    d = np.mod(a - b, 180.0)
    return np.minimum(d, 180.0 - d)


def reconstruct(texture: int = 24, size: int = 72, wavelengths=(460.0, 560.0, 660.0),
                iterations: int = 150, lr_stress: float = 0.03, lr_angle: float = 5.0,
                seed: int = 7, progress: bool = False) -> dict:
    """Renders the targets, fits the two textures from a uniform start; returns the errors,
    the loss curve, the time and the maps."""
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)
    from mitsuba_birefringent import evaluated_mode

    true_ds, true_angle = known_field(texture)
    scene = mi.load_dict(scene_dict(size, true_ds, true_angle, tuple(wavelengths)))
    params = mi.traverse(scene)
    keys = {"stress": "disk.bsdf.birefringence.data", "angle": "disk.bsdf.axis_angle.data"}
    sensors = range(len(wavelengths))
    integrator = scene.integrator()
    start = time.perf_counter()
    with evaluated_mode():
        targets = [[np.array(x) for x in
                    analyser_images(integrator.render(scene, sensor=k, seed=seed, spp=1))]
                   for k in sensors]
        # The start: a uniform stress at half the range, every direction 0.
        start_ds = np.full_like(true_ds, 0.5 * MAX_MPA)
        start_angle = np.zeros_like(true_angle)
        params[keys["stress"]] = mi.TensorXf(start_ds[..., None].astype(np.float32))
        params[keys["angle"]] = mi.TensorXf(start_angle[..., None].astype(np.float32))
        params.update()
        opt = mi.ad.Adam(lr=lr_stress)
        opt[keys["stress"]] = params[keys["stress"]]
        opt[keys["angle"]] = params[keys["angle"]]
        opt.set_learning_rate({keys["stress"]: lr_stress, keys["angle"]: lr_angle})
        params.update(opt)
        losses = []
        for it in range(iterations):
            # The step sizes decay geometrically to DECAY of their start over the iterations.
            f = DECAY ** (it / max(1, iterations - 1))
            opt.set_learning_rate({keys["stress"]: lr_stress * f, keys["angle"]: lr_angle * f})
            loss = mi.Float(0.0)
            for k in sensors:
                # The integrator's own render, recorded by Dr.Jit's AD: the residual and its
                # gradient then come from the same samples as the targets (mi.render would
                # render twice, the gradient with decorrelated samples).
                img = integrator.render(scene, sensor=k, seed=seed, spp=1)
                for x, t in zip(analyser_images(img), targets[k]):
                    loss += dr.mean(dr.square(x - mi.TensorXf(t)).array)
            dr.backward(loss)
            opt.step()
            # sigma_1 - sigma_2 >= 0 by definition.
            opt[keys["stress"]] = dr.maximum(opt[keys["stress"]], 0.0)
            params.update(opt)
            losses.append(float(loss[0]))
            if progress and (it % 10 == 0 or it == iterations - 1):
                print(f"  iteration {it:4d}: loss {losses[-1]:.3e}", flush=True)
        seconds = time.perf_counter() - start
        got_ds = np.array(params[keys["stress"]])[..., 0]
        got_angle = np.array(params[keys["angle"]])[..., 0]
    span = true_ds.max() - true_ds.min()
    retardance_rms = float(np.sqrt(np.mean((got_ds - true_ds) ** 2)) / span)
    where = true_ds > NEAR_ZERO * true_ds.max()
    direction_rms = float(np.sqrt(np.mean(direction_error(got_angle, true_angle)[where] ** 2)))
    return {"texture": texture, "size": size, "wavelengths_nm": list(wavelengths),
            "iterations": iterations, "seconds": seconds, "losses": losses,
            "retardance_rms_of_range": retardance_rms, "direction_rms_deg": direction_rms,
            "direction_texels": int(where.sum()), "max_mpa": MAX_MPA,
            "maps": {"true_stress": true_ds, "true_angle": true_angle, "start_stress": start_ds,
                     "start_angle": start_angle, "stress": got_ds, "angle": got_angle},
            "target_crossed": targets[0][0]}


def figure(result: dict, path: pathlib.Path) -> pathlib.Path:
    """Target, start, result and loss curve."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    m = result["maps"]
    fig, ax = plt.subplots(2, 4, figsize=(13, 6.2))
    extent = (-1, 1, -1, 1)
    panels = [
        (ax[0, 0], result["target_crossed"], "target: crossed circular, "
         f"{result['wavelengths_nm'][0]:.0f} nm", "gray", None),
        (ax[0, 1], m["true_stress"], "known sigma1 - sigma2 (MPa)", "magma", (0, result["max_mpa"])),
        (ax[0, 2], m["start_stress"], "start", "magma", (0, result["max_mpa"])),
        (ax[0, 3], m["stress"], f"recovered (RMS {100 * result['retardance_rms_of_range']:.2f} % of range)",
         "magma", (0, result["max_mpa"])),
        (ax[1, 1], m["true_angle"], "known direction of sigma1 (deg)", "twilight", (-90, 90)),
        (ax[1, 2], m["start_angle"], "start", "twilight", (-90, 90)),
        (ax[1, 3], (m["angle"] + 90) % 180 - 90,
         f"recovered (RMS {result['direction_rms_deg']:.2f} deg)", "twilight", (-90, 90)),
    ]
    for a, img, title, cmap, lim in panels:
        # Texture row 0 is the bottom of the disk (y = -1); image row 0 is the top.
        origin = "upper" if img is result["target_crossed"] else "lower"
        im = a.imshow(img, origin=origin, extent=extent, cmap=cmap,
                      vmin=None if lim is None else lim[0], vmax=None if lim is None else lim[1])
        a.set_title(title, fontsize=9)
        a.set_xticks([])
        a.set_yticks([])
        fig.colorbar(im, ax=a, fraction=0.046)
    a = ax[1, 0]
    a.semilogy(result["losses"])
    a.set_xlabel("iteration")
    a.set_title(f"loss ({result['seconds']:.0f} s)", fontsize=9)
    fig.suptitle(f"Inverse photoelasticity: {result['texture']}^2 texels from "
                 f"{len(result['wavelengths_nm'])} wavelengths x 3 analysers, "
                 f"{result['size']}^2 px", fontsize=11)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80, facecolor="white")
    plt.close(fig)
    return path


def gallery(out: pathlib.Path) -> pathlib.Path:
    """The gallery's entry (scenes/gallery.py): the default reconstruction and its figure,
    with its numbers beside it in JSON."""
    result = reconstruct()
    summary = {k: v for k, v in result.items() if k not in ("maps", "target_crossed")}
    out.mkdir(parents=True, exist_ok=True)
    (out / "inverse_photoelastic.json").write_text(json.dumps(summary, indent=1))
    return figure(result, out / "inverse_photoelastic.png")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--texture", type=int, default=24)
    p.add_argument("--size", type=int, default=72)
    p.add_argument("--iterations", type=int, default=150)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out"))
    a = p.parse_args()
    result = reconstruct(a.texture, a.size, iterations=a.iterations, progress=True)
    a.out.mkdir(parents=True, exist_ok=True)
    png = figure(result, a.out / "inverse_photoelastic.png")
    summary = {k: v for k, v in result.items() if k not in ("maps", "target_crossed")}
    (a.out / "inverse_photoelastic.json").write_text(json.dumps(summary, indent=1))
    print(f"retardance RMS {100 * result['retardance_rms_of_range']:.2f} % of its range, "
          f"direction RMS {result['direction_rms_deg']:.2f} deg over "
          f"{result['direction_texels']} texels, {result['seconds']:.0f} s; {png}")


if __name__ == "__main__":
    main()
