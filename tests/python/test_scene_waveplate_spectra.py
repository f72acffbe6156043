"""scenes/waveplate_spectra.py: retardance of three quarter-wave plates and the transmission of a
Lyot filter, read from rendered Stokes images at single wavelengths, against the design formulas
(ideal retarders with the crystals' own birefringence) and against the calculator's exact stack.

Bounds, from the immersed plates' faces (module docstring of the scene: ext_ior = exit_ior =
1.544). An interface between indices n1, n2 reflects r = (n1 - n2) / (n1 + n2) of the amplitude;
the multiple reflections between interfaces i and j change a mode's transmitted amplitude by the
factor 1 / (1 - sum r_i r_j e^{i phi_ij} - ...), whose phase is at most
asin(s / (1 - s)) with s = sum over pairs of |r_i r_j| (first order), so the retardance (the
difference of two modes' phases) differs from the ideal retarder's by at most twice that, s taken
over the larger of each interface's o and e reflections. The achromat's quartz/MgF2 contact and
its MgF2 face reflect r = 0.057 each: bound 0.38 degrees (measured: 0.34 at 5 nm steps); the
quartz plates in oil: r < 0.008, bound 0.007 degrees. The Lyot filter's transmission differs from
the closed form by each plate's loss, 1 - (1 - r^2)^2 per mode, and the same multiple-reflection
factor on |t|^2, 4 r^2 / (1 - r^2) per plate at most: summed over the three plates at the worst
wavelength, 1.3e-3 (measured 1.2e-4 at 2 nm steps).

Against the calculator (the same stack asked through the calculator's `stack` and `slab`, its
Jones matrix giving the retardance as the phase difference of its principal components): the
render's float32 and the 0.01 nm sensor band, bound 0.01 degrees.
"""

import math
import pathlib
import sys

import numpy as np
import pytest

import scene_optics as so

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "scenes"))
import waveplate_spectra as ws  # noqa: E402

WAVELENGTHS = (400.0, 460.0, 550.0, 640.0, 700.0)


def reflection(n1, n2):
    return abs((n1 - n2) / (n1 + n2))


def retardance_bound(plate: ws.Plate, wavelength_nm: float) -> float:
    """Radians: twice asin(s / (1 - s)), s over the pairs of the plate's interfaces (docstring)."""
    media = [(ws.IMMERSION, ws.IMMERSION)] + [so.crystal_indices(m.material, wavelength_nm)
                                              for m in plate.layers] + [(ws.IMMERSION, ws.IMMERSION)]
    r = [max(reflection(a[0], b[0]), reflection(a[1], b[1]), reflection(a[0], b[1]), reflection(a[1], b[0]))
         for a, b in zip(media, media[1:])]
    s = sum(r[i] * r[j] for i in range(len(r)) for j in range(i + 1, len(r)))
    return 2 * math.asin(s / (1 - s))


def calculator_retardance(plate: ws.Plate, wavelength_nm: float) -> float:
    """The retardance of the calculator's stack: the phase difference of its Jones transmission's
    x and y components (the plate's axes) for light polarised at 45 degrees, |arg(t_xx / t_yy)|.
    Normal incidence: the calculator's p = x, s = y."""
    layers = [{"material": m.material, "thickness_um": m.thickness_um,
               "optic_axis": [math.cos(math.radians(m.axis_deg)), math.sin(math.radians(m.axis_deg)), 0]}
              for m in plate.layers]
    q = {"wavelength_nm": wavelength_nm, "theta_deg": 0.0, "ext_ior": ws.IMMERSION, "layers": layers}
    jt = so.calculator("stack", q)["jones"]["T"]
    t_ss, t_pp = complex(*jt[0][0]), complex(*jt[1][1])
    return abs(np.angle(t_pp / t_ss))


@pytest.mark.parametrize("index", range(3))
def test_quarter_wave_plate_retardance(index):
    plate = ws.plates()[index]
    worst_design, worst_calc = 0.0, 0.0
    for w in WAVELENGTHS:
        measured = ws.measured_retardance(plate, w)
        design = abs(plate.retardance(w))
        exact = calculator_retardance(plate, w)
        bound = retardance_bound(plate, w)
        assert abs(measured - design) <= bound + 1e-6, (plate.name, w, measured, design, bound)
        assert abs(measured - exact) <= math.radians(0.01), (plate.name, w, measured, exact)
        worst_design = max(worst_design, abs(measured - design) / bound)
        worst_calc = max(worst_calc, abs(measured - exact))
    print(f"{plate.name}: |rendered - design| up to {worst_design:.2f} of its bound; "
          f"|rendered - calculator| up to {math.degrees(worst_calc):.1e} degrees")
    # A quarter wave at the design wavelength(s).
    for w in (ws.ACHROMAT_NM if "achromatic" in plate.name else (ws.DESIGN_NM,)):
        assert abs(plate.retardance(w) - math.pi / 2) < 1e-9


def test_design_formula_sensitivity():
    """The bounds are tight enough to matter: an achromat whose plates were both quartz (no
    dispersion compensation) or whose MgF2 were 1 % thinner would fail them."""
    achromat = ws.plates()[2]
    m, q = achromat.layers
    for wrong in (ws.Plate("mgf2 1 % thin", (m._replace(thickness_um=0.99 * m.thickness_um), q)),):
        misses = [abs(wrong.retardance(w) - achromat.retardance(w)) - retardance_bound(achromat, w)
                  for w in WAVELENGTHS]
        assert max(misses) > 0, misses


def test_lyot_filter_transmission():
    d = ws.lyot_thickness_um()
    assert abs(ws.birefringence("quartz", ws.DESIGN_NM) * d * 1e3 / ws.DESIGN_NM - ws.LYOT_ORDER) < 1e-12
    # A passband (T = 1) at the design wavelength, the skirts and a stop band.
    for w in (ws.DESIGN_NM, 545.0, 552.0, 500.0, 470.0, 675.0):
        measured = ws.measured_transmission(w)
        closed = ws.lyot_transmission(w)
        print(f"Lyot at {w} nm: rendered {measured:.5f}, closed form {closed:.5f}")
        assert abs(measured - closed) < 1.3e-3, (w, measured, closed)
    assert ws.lyot_transmission(ws.DESIGN_NM) > 0.999999
