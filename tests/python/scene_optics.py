"""Independent optics for the scene tests (tests/python/test_scene_*.py): the calculator binary,
Mitsuba's own colour matching, and the transfer matrix of uniaxial layers at normal incidence.

Nothing here calls the plugins or the core's physics: the transfer matrix is written out from the
textbook (Born & Wolf, Principles of Optics, sect. 1.6.2, the characteristic matrix of a
homogeneous film, applied to each principal polarisation of a uniaxial layer whose optic axis
lies in its faces), and the colour weights are Mitsuba's.
"""

from __future__ import annotations

import json
import math
import pathlib
import subprocess

import mitsuba as mi
import numpy as np

#: The calculator binary (`make setup` builds it).
CALCULATOR = pathlib.Path(__file__).resolve().parents[2] / "target" / "release" / "birefringence"
#: Mitsuba's "air", the plugins' default ext_ior.
AIR = 1.000277


def calculator(command: str, query: dict) -> dict:
    """One query of `birefringence <command>` (JSON in, JSON out)."""
    out = subprocess.run([str(CALCULATOR), command], input=json.dumps(query), text=True,
                         capture_output=True, check=True).stdout
    return json.loads(out)


def crystal_indices(material: str, wavelength_nm: float) -> tuple[float, float]:
    """(n_o, n_e) of a named crystal of the core's catalogue at one wavelength, from the
    calculator (the effective indices of the o and e waves at normal incidence, axis in the
    surface)."""
    q = {"wavelength_nm": wavelength_nm, "material": material, "optic_axis": [1, 0, 0],
         "theta_deg": 0, "side": "outside"}
    waves = calculator("interface", q)["waves"]["transmitted"]
    return waves["o"]["effective_index"][0], waves["e"]["effective_index"][0]


def colour_weights(lam: np.ndarray, step: float) -> np.ndarray:
    """Per wavelength of the grid `lam` (nm, a multiple of 4 points, spacing `step`): linear sRGB
    of Mitsuba's film for light of the `d65` emitter's radiance (scale 1), times `step`, so that
    `weights.T @ T(lam)` is the pixel colour of a spectral transmission T. Mitsuba's own colour
    matching (`mi.spectrum_to_srgb`, averaging over the 4 wavelengths it is given); needs a
    spectral variant."""
    d65 = mi.load_dict({"type": "d65"})
    si = mi.SurfaceInteraction3f()
    out = np.zeros((len(lam), 3))
    for k in range(0, len(lam), 4):
        ls = [float(v) for v in lam[k:k + 4]]
        si.wavelengths = mi.UnpolarizedSpectrum(*ls)
        radiance = np.array(d65.eval(si))
        for j in range(4):
            unit = [0.0] * 4
            unit[j] = 1.0
            rgb = np.array(mi.spectrum_to_srgb(mi.UnpolarizedSpectrum(*unit), mi.UnpolarizedSpectrum(*ls)))
            out[k + j] = 4 * rgb * radiance[j] * step
    return out


def rotation(angle_deg: float) -> np.ndarray:
    a = math.radians(angle_deg)
    return np.array([[math.cos(a), -math.sin(a)], [math.sin(a), math.cos(a)]])


def layer_matrix(n_o: float, n_e: float, d_nm: float, angle_deg: float, lam: np.ndarray) -> np.ndarray:
    """(len(lam), 4, 4) characteristic matrices of a uniaxial layer with its optic axis in the
    faces at `angle_deg` from x, acting on (E_x, E_y, H'_x, H'_y) with H' = (H_y, -H_x) in units
    where a wave travelling forward in a medium of index n has H' = n E. In the principal frame
    each polarisation is an isotropic film (Born & Wolf eq. 1.6.(30) with exp(-i w t)):
    [[cos delta, -i sin delta / n], [-i n sin delta, cos delta]], delta = 2 pi n d / lambda,
    index n_e along the axis and n_o across it; H' turns with E under rotations about z."""
    r = rotation(angle_deg)
    m = np.zeros((len(lam), 4, 4), dtype=complex)
    for k, n in enumerate((n_e, n_o)):  # principal axis k: 0 along the optic axis
        delta = 2 * np.pi * n * d_nm / lam
        u = r[:, k]
        proj = np.outer(u, u)
        m[:, :2, :2] += np.cos(delta)[:, None, None] * proj
        m[:, :2, 2:] += (-1j * np.sin(delta) / n)[:, None, None] * proj
        m[:, 2:, :2] += (-1j * n * np.sin(delta))[:, None, None] * proj
        m[:, 2:, 2:] += np.cos(delta)[:, None, None] * proj
    return m


def stack_jones(layers: list[tuple[float, float, float, float]], lam: np.ndarray,
                n0: float = AIR) -> np.ndarray:
    """(len(lam), 2, 2) Jones transmission matrices (x, y components) of uniaxial layers
    (n_o, n_e, d_nm, angle_deg), listed in the order the light meets them, between media of
    index n0, every internal reflection included. With M = [[A, B], [C, D]] the product of the
    layers' characteristic matrices: E_inc + E_ref = (A + n0 B) E_t and n0 (E_inc - E_ref) =
    (C + n0 D) E_t, so E_t = 2 n0 (n0 A + n0^2 B + C + n0 D)^-1 E_inc."""
    m = np.broadcast_to(np.eye(4, dtype=complex), (len(lam), 4, 4)).copy()
    for n_o, n_e, d_nm, angle in layers:
        m = m @ layer_matrix(n_o, n_e, d_nm, angle, lam)
    a, b, c, d = m[:, :2, :2], m[:, :2, 2:], m[:, 2:, :2], m[:, 2:, 2:]
    return 2 * n0 * np.linalg.inv(n0 * a + n0**2 * b + c + n0 * d)


def between_polarisers(jones: np.ndarray, polariser_deg: float, analyser_deg: float) -> np.ndarray:
    """Transmitted fraction of unpolarised light through an ideal polariser, the element of Jones
    matrix `jones` and an ideal analyser (their axes from x): (1/2) |a^T J p|^2."""
    p = rotation(polariser_deg)[:, 0]
    a = rotation(analyser_deg)[:, 0]
    return 0.5 * np.abs(np.einsum("i,lij,j->l", a, jones, p)) ** 2
