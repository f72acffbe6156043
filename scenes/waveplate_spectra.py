"""Waveplates and a Lyot filter against wavelength, measured from rendered Stokes images beside
their design formulas.

    .venv/bin/python scenes/waveplate_spectra.py [--out out/plots] [--step 5]

What it shows: the retardance of three quarter-wave plates from 400 to 700 nm, and the
transmission of a three-stage Lyot filter, each point read from a render (scalar_spectral_polarized,
a monochromatic camera at that wavelength, the `stokes` integrator) of an optical bench: a light
box, a polariser and the element, seen by an orthographic camera. The plates:

- a true zero-order quartz plate (`thinbirefringent`, 15.0 um): delta = 2 pi dn_q(lambda) d / lambda;
- a compound zero-order quartz plate: two plates 515.0 and 500 um thick with crossed axes (a
  `birefringentstack` of two layers): the retardations subtract, leaving that of the 15.0 um
  difference, delta = 2 pi dn_q(lambda) (d1 - d2) / lambda (the same curve as the true
  zero-order plate, from plates thick enough to make);
- an achromatic plate: quartz (273.2 um) and MgF2 (223.3 um) with crossed axes (a stack),
  delta = 2 pi (dn_m(lambda) d_m - dn_q(lambda) d_q) / lambda, the thicknesses solving
  delta = pi / 2 at 460 and 640 nm: the two crystals' different dispersion of birefringence
  flattens the curve between.

dn = n_e - n_o of each crystal from the core's catalogue (quartz: Ghosh 1999; MgF2: Dodge 1984),
asked of the calculator at each wavelength: the design formulas are those of an ideal retarder
with the crystals' own indices. The Lyot filter: three quartz plates of thickness d, 2d and 4d,
each with its axis at 45 degrees between parallel polarisers, transmit
T(lambda) = prod_k cos^2(pi dn_q(lambda) 2^k d / lambda) of polarised light: passbands where
dn_q d / lambda is a whole number m, here d = 300.2 um (dn_q d = 5 x 550 nm: passbands near 687,
550, 458 and 393 nm), each of full width about lambda / (8 m) at half maximum.

The plates are immersed (`ext_ior` = `exit_ior` = 1.544, an index-matching oil or cement, as
real compound plates and Lyot filters are): their faces then reflect almost nothing (quartz's
n_o within 0.003 of the oil at every wavelength, R < 1e-5; the quartz/MgF2 contact and the MgF2
faces reflect 0.3 % and 0.09 %), so a plate is close to the ideal retarder and a single
wavelength is evaluated exactly, without the fringes of multiple reflections in thick plates.
How the retardance is read: light polarised at 45 degrees to the plate's axes (Stokes
S = (1, 0, 1, 0)) leaves the plate as (1, 0, cos delta, +-sin delta), so
delta = atan2(|S3|, S2) in [0, pi], unambiguous for every plate here (zero order).

The check (tests/python/test_scene_waveplate_spectra.py): the measured retardance and
transmission against the design formulas at a few wavelengths, within bounds derived from the
immersed faces' reflections.

Not a gallery scene of its own (no `scene` function): `gallery(out)` draws the plot for the
contact sheet (scenes/gallery.py, EXAMPLES).
"""

from __future__ import annotations

import argparse
import functools
import math
import pathlib
import sys
import time
import typing

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
if str(HERE) not in sys.path:
    sys.path.insert(0, str(HERE))

from _common import backlight, layer, ortho_sensor  # noqa: E402
from waveplates import indices  # noqa: E402

VARIANT = "scalar_spectral_polarized"
#: Index of the immersion medium around every plate (module docstring).
IMMERSION = 1.544
DESIGN_NM = 550.0
#: Design wavelengths of the achromatic plate (a quarter wave at both).
ACHROMAT_NM = (460.0, 640.0)
#: Thickness of the thinner plate of the compound zero-order plate (um).
COMPOUND_BASE_UM = 500.0
#: Order of the Lyot filter's passband at DESIGN_NM: dn_q d = LYOT_ORDER x DESIGN_NM.
LYOT_ORDER = 5


def birefringence(material: str, wavelength_nm: float) -> float:
    """n_e - n_o of a catalogue crystal (the calculator's indices, module docstring)."""
    n_o, n_e = indices(material, float(wavelength_nm))
    return n_e - n_o


class Layer(typing.NamedTuple):
    """A plate: crystal, thickness (um) and the angle of its optic axis (degrees from x)."""

    material: str
    thickness_um: float
    axis_deg: float


class Plate(typing.NamedTuple):
    """A waveplate design: its layers (from the camera's side down) and its name."""

    name: str
    layers: tuple[Layer, ...]

    def retardance(self, wavelength_nm: float) -> float:
        """Design retardance (radians) of an ideal retarder: 2 pi / lambda times the sum over
        the layers of +-dn d, + for a slow axis (a positive crystal's optic axis) along x."""
        path = 0.0
        for m in self.layers:
            along_x = round(math.cos(math.radians(m.axis_deg)) ** 2)  # axis along x (1) or y (0)
            path += (1 if along_x else -1) * birefringence(m.material, wavelength_nm) * m.thickness_um
        return 2 * math.pi * path * 1e3 / wavelength_nm

    def bsdf(self) -> dict:
        """The plate as a plugin: one `thinbirefringent`, or a `birefringentstack` of its layers."""
        plates = [{"type": "thinbirefringent", "material": m.material, "thickness": m.thickness_um,
                   "axis_angle": m.axis_deg} for m in self.layers]
        surroundings = {"ext_ior": IMMERSION, "exit_ior": IMMERSION}
        if len(plates) == 1:
            return {**plates[0], **surroundings}
        return {"type": "birefringentstack", **surroundings,
                **{f"layer_{k}": p for k, p in enumerate(plates)}}


@functools.lru_cache(maxsize=None)
def plates() -> tuple[Plate, ...]:
    """The three quarter-wave designs (module docstring), thicknesses from the catalogue."""
    quarter = DESIGN_NM * 1e-3 / (4 * birefringence("quartz", DESIGN_NM))
    # Achromat: dn_m(l) d_m - dn_q(l) d_q = l / 4 at both design wavelengths.
    a = [[birefringence("mgf2", w), -birefringence("quartz", w)] for w in ACHROMAT_NM]
    d_m, d_q = np.linalg.solve(a, [w * 1e-3 / 4 for w in ACHROMAT_NM])
    return (
        Plate("zero-order quartz", (Layer("quartz", quarter, 0.0),)),
        Plate("compound zero-order quartz", (Layer("quartz", COMPOUND_BASE_UM + quarter, 0.0),
                                             Layer("quartz", COMPOUND_BASE_UM, 90.0))),
        Plate("achromatic quartz + MgF2", (Layer("mgf2", float(d_m), 0.0),
                                           Layer("quartz", float(d_q), 90.0))),
    )


def lyot_thickness_um() -> float:
    """The Lyot filter's thinnest plate: dn_q d = LYOT_ORDER x DESIGN_NM."""
    return LYOT_ORDER * DESIGN_NM * 1e-3 / birefringence("quartz", DESIGN_NM)


def lyot_transmission(wavelength_nm: float) -> float:
    """The closed form: prod_k cos^2(pi dn_q 2^k d / lambda) (module docstring)."""
    phase = math.pi * birefringence("quartz", wavelength_nm) * lyot_thickness_um() * 1e3 / wavelength_nm
    return math.prod(math.cos(phase * 2**k) ** 2 for k in range(3))


def light_and_camera(width: int, spp: int, wavelength_nm: float, stokes: bool) -> dict:
    """The bench's light box (black: reflects nothing back), camera and integrator; the view is
    [-1, 1] x [-0.5, 0.5], `width` pixels wide and half as tall."""
    nested = {"type": "volpath", "max_depth": 16}
    return {
        "type": "scene",
        "integrator": {"type": "stokes", "nested": nested} if stokes else nested,
        "sensor": ortho_sensor(width, max(1, width // 2), spp, 1.0, 0.5, wavelength_nm=wavelength_nm,
                               single_channel=not stokes),
        "light": backlight(-3.0, 4.0, black=True),
    }


def retardance_bench(plate: Plate, wavelength_nm: float, width: int = 2, spp: int = 4) -> dict:
    """Light polarised at +45 degrees through `plate` (its axes along x and y), read with the
    `stokes` integrator, monochromatic (scalar_spectral_polarized)."""
    d = light_and_camera(width, spp, wavelength_nm, stokes=True)
    # Mitsuba's polarizer transmits along -theta (see scenes/_common.py).
    d["polarizer"] = layer(-2.0, 2.0, 2.0, {"type": "polarizer", "theta": -45.0})
    d["plate"] = layer(0.0, 2.0, 2.0, plate.bsdf())
    return d


def lyot_bench(wavelength_nm: float, width: int = 2, spp: int = 4) -> dict:
    """Left half of the view: four parallel polarisers (along x) alone; right half: the Lyot
    filter, a quartz plate of d, 2d and 4d (axis at 45 degrees, immersed) after each of the first
    three. Monochromatic camera, one channel (scalar_spectral_polarized)."""
    d = light_and_camera(width, spp, wavelength_nm, stokes=False)
    d0 = lyot_thickness_um()
    for k in range(4):
        d[f"polarizer_{k}"] = layer(-2.0 + 0.5 * k, 2.0, 2.0, {"type": "polarizer", "theta": 0.0})
        if k < 3:
            d[f"plate_{k}"] = layer(-1.75 + 0.5 * k, 1.0, 2.0, {
                "type": "thinbirefringent", "material": "quartz", "thickness": d0 * 2**k,
                "axis_angle": 45.0, "ext_ior": IMMERSION}, centre_x=1.0)
    return d


def use_variant():
    """Sets VARIANT (before a bench is built: its transforms belong to the variant)."""
    import mitsuba as mi

    mi.set_variant(VARIANT)
    import mitsuba_birefringent  # noqa: F401  (registers the plugins)

    return mi


def render(scene: dict, seed: int = 0) -> np.ndarray:
    mi = use_variant()
    return np.array(mi.render(mi.load_dict(scene), seed=seed), dtype=np.float64)


def measured_retardance(plate: Plate, wavelength_nm: float, **bench) -> float:
    """delta = atan2(|S3|, S2) of the rendered Stokes vector (module docstring), radians."""
    use_variant()
    image = render(retardance_bench(plate, wavelength_nm, **bench))
    # Channels: RGB, then S0..S3 as RGB triplets; at one wavelength every triplet is one value
    # times the same factors, so their sums are the Stokes vector up to a common scale.
    s = [image[..., 3 + 3 * i: 6 + 3 * i].sum() for i in range(4)]
    return math.atan2(abs(s[3]), s[2])


def measured_transmission(wavelength_nm: float, **bench) -> float:
    """The right half over the left half of a rendered Lyot bench: the filter's transmission of
    polarised light."""
    use_variant()
    image = render(lyot_bench(wavelength_nm, **bench))[..., 0]
    half = image.shape[1] // 2
    return float(image[:, half:].sum() / image[:, :half].sum())


def curves(step_nm: float = 5.0, lyot_step_nm: float = 2.0) -> dict:
    """Measured and design curves over 400-700 nm: the plates rendered `step_nm` apart, the
    Lyot filter (passbands a few nm wide) `lyot_step_nm` apart, the design curves at 0.5 nm."""
    measured = np.arange(400.0, 700.0 + 1e-9, step_nm)
    lyot = np.arange(400.0, 700.0 + 1e-9, lyot_step_nm)
    dense = np.arange(400.0, 700.25, 0.5)
    out = {"measured_nm": measured, "lyot_nm": lyot, "dense_nm": dense, "plates": {}}
    for p in plates():
        out["plates"][p.name] = {
            "measured": np.array([measured_retardance(p, w) for w in measured]),
            "design": np.array([p.retardance(w) for w in dense])}
    out["lyot"] = {"measured": np.array([measured_transmission(w) for w in lyot]),
                   "design": np.array([lyot_transmission(w) for w in dense])}
    return out


def figure(data: dict, path: pathlib.Path) -> pathlib.Path:
    """Retardance (left) and the Lyot filter's transmission (right): rendered points on the
    design curves."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9.6, 3.8), dpi=100)
    for (name, c), colour in zip(data["plates"].items(), ("C0", "C1", "C2")):
        same = " (the same curve)" if name.startswith("compound") else ""
        ax.plot(data["dense_nm"], np.degrees(c["design"]), color=colour, lw=1.2,
                label=f"{name}: design{same}")
        ax.plot(data["measured_nm"], np.degrees(c["measured"]), "o", color=colour, ms=3.5,
                mfc="none", label="rendered")
    ax.axhline(90.0, color="0.6", lw=0.6, ls=":")
    ax.set_xlabel("wavelength (nm)")
    ax.set_ylabel("retardance (degrees)")
    ax.set_title("quarter-wave plates")
    ax.legend(fontsize=6.5, loc="upper right")
    bx.plot(data["dense_nm"], data["lyot"]["design"], color="C3", lw=1.2,
            label="closed form, prod cos$^2$(pi dn 2$^k$ d / lambda)")
    bx.plot(data["lyot_nm"], data["lyot"]["measured"], "o", color="C3", ms=2.5, mfc="none",
            label="rendered")
    bx.set_xlabel("wavelength (nm)")
    bx.set_ylabel("transmission of polarised light")
    bx.set_title(f"Lyot filter: quartz {lyot_thickness_um():.1f}, x2, x4 um")
    bx.legend(fontsize=6.5, loc="upper right")
    bx.set_ylim(-0.02, 1.25)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(str(path))
    plt.close(fig)
    return path


def gallery(out: pathlib.Path) -> pathlib.Path:
    """The contact sheet's panel (scenes/gallery.py): the figure at 10 nm steps."""
    return figure(curves(10.0), out / "waveplate_spectra.png")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/plots"))
    p.add_argument("--step", type=float, default=5.0, help="nm between rendered points")
    a = p.parse_args()
    start = time.perf_counter()
    data = curves(a.step)
    path = figure(data, a.out / "waveplate_spectra.png")
    for name, c in data["plates"].items():
        design = np.array([next(p for p in plates() if p.name == name).retardance(w)
                           for w in data["measured_nm"]])
        print(f"{name}: max |rendered - design| = "
              f"{np.degrees(np.abs(c['measured'] - design).max()):.4f} degrees")
    lyot = np.array([lyot_transmission(w) for w in data["lyot_nm"]])
    print(f"Lyot filter: max |rendered - closed form| = {np.abs(data['lyot']['measured'] - lyot).max():.2e}")
    print(f"{path} in {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()
