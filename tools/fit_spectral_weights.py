#!/usr/bin/env python3
"""Fit camera-channel spectral weights with sums of Gaussians in wavenumber.

Run from the repository root, inside a virtual environment that has
``tools/requirements-tools.txt`` installed::

    python -m venv /tmp/venv && /tmp/venv/bin/pip install -r tools/requirements-tools.txt
    /tmp/venv/bin/python tools/fit_spectral_weights.py

It writes ``src/colour/data.rs`` (overwriting it) and prints a fit
report to standard output.  The script is deterministic: all randomness comes
from a seeded ``numpy.random.Generator`` (one stream per channel), BLAS is
forced single-threaded, and the optimiser is deterministic (the last digits
could differ on a CPU whose BLAS kernels round differently).  It takes about
12 minutes on 2 cores.  The output is formatted with ``rustfmt --edition
2021`` when rustfmt is on the PATH (a warning is printed otherwise).

Physics
-------
An interference intensity is a sum of terms ``a cos(k D + phi)`` in the
wavenumber ``k = 2 pi / lambda`` (``D`` an optical path difference).  A camera
channel ``c`` records ``integral w_c(k) I(k) dk`` where ``w_c`` is the channel's
spectral weight per unit wavenumber.  If ``w_c(k) = sum_j a_j N(k; mu_j,
sigma_j)`` (``N`` the unit-mass normal pdf) then every term integrates in closed
form::

    integral N(k; mu, sigma) exp(i k D) dk = exp(i mu D - sigma^2 D^2 / 2).

Data (all from the ``colour-science`` PyPI package, pinned in
``tools/requirements-tools.txt``)
--------------------------------------------------------------------------
* CIE 1931 2-degree standard observer colour-matching functions x̄, ȳ, z̄,
  360..830 nm at 1 nm (CIE 015:2018 "Colorimetry, 4th edition" and its data
  tables; ISO/CIE 11664-1:2019).  ``colour.MSDS_CMFS["CIE 1931 2 Degree Standard
  Observer"]`` holds this 1-nm table.
* CIE standard illuminant D65 relative spectral power distribution
  (CIE 015:2018; ISO/CIE 11664-2:2022).  ``colour.SDS_ILLUMINANTS["D65"]``
  holds the CIE 5-nm table but only for 300..780 nm; the values for 785..830
  nm are computed with the CIE daylight procedure (S0, S1, S2 basis functions
  of CIE 015:2018 with M1, M2 rounded to three decimals, nominal CCT 6500 K x
  1.4388/1.4380), ``colour.sd_CIE_illuminant_D_series``.  That procedure is
  checked here to agree with the tabulated values to better than 1e-3
  (relative 1e-5) where both exist.  The 1-nm values are obtained by linear
  interpolation of the 5-nm table, as CIE 015:2018 prescribes for the D
  illuminants (and as the 1-nm table of ISO/CIE 11664-2 is made).
* CIE standard illuminant E: constant.
* IEC 61966-2-1:1999 XYZ -> linear sRGB matrix (4-decimal, D65 white),
  ``colour.models.RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB``.

Weight sets (per unit wavelength, on the 1-nm table, linearly interpolated)
--------------------------------------------------------------------------
* ``xyz-e``:    w_c = cmf_c(lambda)
* ``xyz-d65``:  w_c = cmf_c(lambda) D65(lambda)
* ``srgb-d65``: w_c = sum_m M_sRGB[c][m] cmf_m(lambda) D65(lambda)  (signed)

then each channel is divided by its integral over lambda (trapezoid rule on
the 1-nm table, which is the exact integral of the piecewise-linear weight),
so a spectrally flat response of 1 gives exactly 1 in every channel.
Converting to wavenumber: ``w(k) dk = w(lambda) dlambda``, so
``w_k(k) = w_lambda(2 pi / k) lambda^2 / (2 pi)`` (lambda in nm, k in rad/nm).

Fit
---
For every channel, a sum of N Gaussians in k, signed amplitudes allowed,
minimising the L2 error in k-space (by Parseval this is also the L2 error of
the Fourier transform over all optical path differences D), with the equality
constraint ``sum_j a_j = 1`` (so the fit's integral, i.e. its response to a
flat spectrum, is exact).  Amplitudes are solved linearly for given (mu,
sigma) (variable projection); (mu, log sigma) are optimised by
``scipy.optimize.least_squares``.  Candidates come from a greedy start (add a
component where the residual is largest) plus seeded random restarts.
"""

from __future__ import annotations

import math
import os
import subprocess
import sys
import warnings

# Single-threaded BLAS: multi-threaded reductions are not bit-reproducible, and
# for these small problems threads only add contention.  Must precede numpy.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import numpy as np  # noqa: E402

SEED = 20240601
LAMBDA_MIN_NM = 360
LAMBDA_MAX_NM = 830
N_TABLE = LAMBDA_MAX_NM - LAMBDA_MIN_NM + 1  # 471
SET_NAMES = ["xyz-e", "xyz-d65", "srgb-d65"]
CHANNELS = {
    "xyz-e": ["X", "Y", "Z"],
    "xyz-d65": ["X", "Y", "Z"],
    "srgb-d65": ["R", "G", "B"],
}
# Gaussian count per channel: the fit is run for N = 1..NMAX; the smallest N
# >= NMIN whose relative L2 error (k-space) is <= REL_L2_TARGET is kept, else
# NMAX.
NMIN = 4
NMAX = 8
REL_L2_TARGET = 2.0e-3
RESTARTS = 12
MAX_NFEV = 400

TWO_PI = 2.0 * math.pi
K_TABLE_MIN = TWO_PI / LAMBDA_MAX_NM  # rad/nm
K_TABLE_MAX = TWO_PI / LAMBDA_MIN_NM
# Fitting grid in k: wider than the table so that mass put outside it costs.
K_GRID = np.linspace(TWO_PI / 2000.0, TWO_PI / 250.0, 6001)
DK = K_GRID[1] - K_GRID[0]
SIGMA_MIN = 2.0e-5
SIGMA_MAX = 6.0e-3
RIDGE = 1.0e-6  # tiny amplitude penalty: keeps cancelling pairs bounded

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUTPUT = os.path.join(REPO_ROOT, "src", "colour", "data.rs")


# --------------------------------------------------------------------------
# Data
# --------------------------------------------------------------------------
def load_data() -> dict:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
        from colour.temperature import CCT_to_xy_CIE_D

    lam = np.arange(LAMBDA_MIN_NM, LAMBDA_MAX_NM + 1, dtype=float)

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    assert np.array_equal(cmfs.wavelengths, lam), "CMF table is not 360..830 @ 1 nm"
    cmf = np.array(cmfs.values, dtype=float).T.copy()  # (3, 471)

    d65_tab = colour.SDS_ILLUMINANTS["D65"]
    tab_wl = np.array(d65_tab.wavelengths, dtype=float)
    tab_val = np.array(d65_tab.values, dtype=float)
    assert tab_wl[0] <= 300 and np.all(np.diff(tab_wl) == 5.0)
    xy = CCT_to_xy_CIE_D(6500.0 * 1.4388 / 1.4380)
    d_series = colour.sd_CIE_illuminant_D_series(xy)
    ds_wl = np.array(d_series.wavelengths, dtype=float)
    ds_val = np.array(d_series.values, dtype=float)
    assert ds_wl[-1] >= LAMBDA_MAX_NM and np.all(np.diff(ds_wl) == 5.0)
    # check the CIE daylight procedure against the tabulated values
    common = np.isin(ds_wl, tab_wl)
    dev = np.max(np.abs(ds_val[common] - tab_val[np.isin(tab_wl, ds_wl)]))
    assert dev < 1e-3, dev
    wl5 = np.arange(LAMBDA_MIN_NM, LAMBDA_MAX_NM + 1, 5, dtype=float)
    d65_5 = np.empty_like(wl5)
    for i, w in enumerate(wl5):
        if w <= tab_wl[-1]:
            d65_5[i] = tab_val[tab_wl == w][0]
        else:
            d65_5[i] = ds_val[ds_wl == w][0]
    d65 = np.interp(lam, wl5, d65_5)
    assert abs(d65[560 - LAMBDA_MIN_NM] - 100.0) < 1e-12

    m_xyz_to_srgb = np.array(colour.models.RGB_COLOURSPACE_sRGB.matrix_XYZ_to_RGB, dtype=float)
    return {
        "lam": lam,
        "cmf": cmf,
        "d65": d65,
        "d65_dev": dev,
        "m_xyz_to_srgb": m_xyz_to_srgb,
        "colour_version": colour.__version__,
    }


def trapz(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.sum(0.5 * (y[..., 1:] + y[..., :-1]) * np.diff(x), axis=-1)


def weight_sets(data: dict) -> dict:
    """Per set: (mixing matrix (3x3) applied to cmf x illuminant, illuminant, norms, weights)."""
    lam, cmf, d65 = data["lam"], data["cmf"], data["d65"]
    out = {}
    for name in SET_NAMES:
        if name == "xyz-e":
            mix, illum = np.eye(3), np.ones_like(lam)
        elif name == "xyz-d65":
            mix, illum = np.eye(3), d65
        else:
            mix, illum = data["m_xyz_to_srgb"], d65
        raw = mix @ (cmf * illum)  # (3, 471)
        norm = trapz(raw, lam)
        out[name] = {"mix": mix, "illum": illum, "norm": norm, "w": raw / norm[:, None]}
    return out


def w_per_nm(w_tab: np.ndarray, lam_nm: np.ndarray) -> np.ndarray:
    """Piecewise-linear interpolation of the 1-nm table, 0 outside."""
    lo, hi = LAMBDA_MIN_NM, LAMBDA_MAX_NM
    val = np.interp(lam_nm, np.arange(lo, hi + 1, dtype=float), w_tab)
    return np.where((lam_nm >= lo) & (lam_nm <= hi), val, 0.0)


def w_per_k(w_tab: np.ndarray, k: np.ndarray) -> np.ndarray:
    lam = TWO_PI / k
    return w_per_nm(w_tab, lam) * lam * lam / TWO_PI


# --------------------------------------------------------------------------
# Gaussian model
# --------------------------------------------------------------------------
def gauss(k: np.ndarray, mu: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    z = (k[:, None] - mu[None, :]) / sigma[None, :]
    return np.exp(-0.5 * z * z) / (sigma[None, :] * math.sqrt(TWO_PI))


def solve_amplitudes(mu, sigma, target):
    """min ||sqrt(dk)(G a - w)||^2 + RIDGE ||a||^2  s.t.  sum a = 1."""
    n = len(mu)
    a_mat = gauss(K_GRID, mu, sigma) * math.sqrt(DK)
    b = target * math.sqrt(DK)
    a0 = np.full(n, 1.0 / n)
    if n == 1:
        return a0
    # orthonormal basis of {a : sum a = 0}
    q, _ = np.linalg.qr(np.concatenate([np.ones((n, 1)), np.eye(n)[:, : n - 1]], axis=1))
    z = q[:, 1:n]
    lhs = np.vstack([a_mat @ z, math.sqrt(RIDGE) * z])
    rhs = np.concatenate([b - a_mat @ a0, -math.sqrt(RIDGE) * a0])
    y, *_ = np.linalg.lstsq(lhs, rhs, rcond=None)
    return a0 + z @ y


def unpack(x):
    """x = [mu (n), log sigma (n), a_1..a_{n-1}]; a_n = 1 - sum(a_1..a_{n-1})."""
    n = (len(x) + 1) // 3
    a = np.append(x[2 * n :], 1.0 - np.sum(x[2 * n :]))
    return x[:n], np.exp(x[n : 2 * n]), a


def residual(x, target):
    mu, sigma, a = unpack(x)
    r = (gauss(K_GRID, mu, sigma) @ a - target) * math.sqrt(DK)
    return np.concatenate([r, math.sqrt(RIDGE) * a])


def jacobian(x, target):
    mu, sigma, a = unpack(x)
    n = len(mu)
    g = gauss(K_GRID, mu, sigma)
    z = (K_GRID[:, None] - mu[None, :]) / sigma[None, :]
    m = len(K_GRID)
    jac = np.zeros((m + n, 3 * n - 1))
    jac[:m, :n] = g * a * z / sigma
    jac[:m, n : 2 * n] = g * a * (z * z - 1.0)
    jac[:m, 2 * n :] = g[:, : n - 1] - g[:, n - 1 : n]
    jac[:m] *= math.sqrt(DK)
    ridge = math.sqrt(RIDGE)
    jac[m + np.arange(n - 1), 2 * n + np.arange(n - 1)] = ridge
    jac[m + n - 1, 2 * n :] = -ridge
    return jac


def optimise(mu0, sigma0, target):
    """Local least-squares fit from (mu0, sigma0); amplitudes start at their linear optimum."""
    from scipy.optimize import least_squares

    n = len(mu0)
    lo_mu, hi_mu = K_TABLE_MIN - 0.002, K_TABLE_MAX + 0.002
    mu0 = np.clip(mu0, lo_mu + 1e-9, hi_mu - 1e-9)
    sigma0 = np.clip(sigma0, SIGMA_MIN * 1.001, SIGMA_MAX * 0.999)
    a0 = solve_amplitudes(mu0, sigma0, target)
    lo = np.concatenate([np.full(n, lo_mu), np.full(n, math.log(SIGMA_MIN)), np.full(n - 1, -np.inf)])
    hi = np.concatenate([np.full(n, hi_mu), np.full(n, math.log(SIGMA_MAX)), np.full(n - 1, np.inf)])
    x0 = np.concatenate([mu0, np.log(sigma0), a0[: n - 1]])
    scale = np.concatenate([np.full(n, 1e-3), np.ones(n), np.ones(n - 1)])
    sol = least_squares(
        residual,
        x0,
        jac=jacobian,
        bounds=(lo, hi),
        x_scale=scale,
        args=(target,),
        method="trf",
        xtol=1e-10,
        ftol=1e-10,
        gtol=1e-10,
        max_nfev=MAX_NFEV,
    )
    mu, sigma, a = unpack(sol.x)
    order = np.argsort(mu)
    return mu[order], sigma[order], a[order], float(np.sum(sol.fun**2))


def fit_channel(w_tab, nmax=NMAX, verbose=False, rng=None):
    """Return list indexed by N (1..nmax) of (mu, sigma, a, cost)."""
    if rng is None:
        rng = np.random.default_rng(SEED)
    target = w_per_k(w_tab, K_GRID)
    absw = np.abs(target)
    pdf = absw / absw.sum()
    m = float(np.sum(K_GRID * pdf))
    s = float(math.sqrt(np.sum((K_GRID - m) ** 2 * pdf)))
    results = {}
    best = optimise(np.array([m]), np.array([s]), target)
    results[1] = best
    for n in range(2, nmax + 1):
        mu_p, sig_p, a_p, _ = results[n - 1]
        fit_prev = gauss(K_GRID, mu_p, sig_p) @ a_p
        i = int(np.argmax(np.abs(target - fit_prev)))
        cands = [optimise(np.append(mu_p, K_GRID[i]), np.append(sig_p, 3e-4), target)]
        for _ in range(RESTARTS):
            mu0 = np.sort(rng.choice(K_GRID, size=n, p=pdf))
            sig0 = np.exp(rng.uniform(math.log(2e-4), math.log(2e-3), size=n))
            cands.append(optimise(mu0, sig0, target))
        best = min(cands, key=lambda c: c[3])
        results[n] = best
        if verbose:
            print(f"  N={n}: rel L2 {rel_l2(best, target):.3e}  costs", " ".join(f"{c[3]:.3e}" for c in cands), flush=True)
    return results


def rel_l2(fit, target):
    mu, sigma, a, _ = fit
    err = gauss(K_GRID, mu, sigma) @ a - target
    return float(math.sqrt(np.sum(err**2) / np.sum(target**2)))


def choose(results):
    for n in range(NMIN, NMAX + 1):
        if results[n][4] <= REL_L2_TARGET:
            return n
    return NMAX


# --------------------------------------------------------------------------
# Evaluation
# --------------------------------------------------------------------------
D_REPORT = np.arange(0.0, 50000.0 + 1e-9, 10.0)  # nm
# Reference quadrature in lambda: composite Simpson, step 0.05 nm, nodes on
# every integer nm (the weight is linear between them).  Error bound ~
# (h phi')^4/180 with phi' = 2 pi D / lambda^2 <= 2.5 rad/nm at D = 50 um:
# below 1e-6 of the channel's integral (= 1).
H_REF = 0.05


def fourier_reference(w_tab, d_values):
    n_sub = int(round((LAMBDA_MAX_NM - LAMBDA_MIN_NM) / H_REF))
    lam = np.linspace(LAMBDA_MIN_NM, LAMBDA_MAX_NM, n_sub + 1)
    simpson = np.ones(n_sub + 1)
    simpson[1:-1:2] = 4.0
    simpson[2:-1:2] = 2.0
    simpson *= H_REF / 3.0
    wq = w_per_nm(w_tab, lam) * simpson
    out = np.empty(len(d_values), dtype=complex)
    k = TWO_PI / lam
    for i in range(0, len(d_values), 200):
        d = d_values[i : i + 200]
        out[i : i + 200] = np.exp(1j * np.outer(d, k)) @ wq
    return out


def fourier_fit(mu, sigma, a, d_values):
    d = d_values[:, None]
    return (a * np.exp(-0.5 * (sigma * d) ** 2) * np.exp(1j * mu * d)).sum(axis=1)


def evaluate(w_tab, mu, sigma, a):
    target = w_per_k(w_tab, K_GRID)
    # a finer grid for the norms of the residual
    k_fine = np.linspace(K_GRID[0], K_GRID[-1], 60001)
    dk = k_fine[1] - k_fine[0]
    wt = w_per_k(w_tab, k_fine)
    res = gauss(k_fine, mu, sigma) @ a - wt
    ref = fourier_reference(w_tab, D_REPORT)
    fit = fourier_fit(mu, sigma, a, D_REPORT)
    err = np.abs(fit - ref)
    # envelope of the true transform: max |F| within +-250 nm of D
    absref = np.abs(ref)
    env = np.array([absref[max(0, i - 25) : i + 26].max() for i in range(len(absref))])
    rel = err / env
    bad = np.nonzero(rel > 0.1)[0]
    d_rel10 = D_REPORT[bad[0] - 1] if len(bad) else D_REPORT[-1]
    return {
        "n": len(mu),
        "sum_a": float(np.sum(a)),
        "rel_l2": float(math.sqrt(np.sum(res**2) / np.sum(wt**2))),
        "max_abs": float(np.max(np.abs(res))),
        "max_rel": float(np.max(np.abs(res)) / np.max(np.abs(wt))),
        "l1": float(np.sum(np.abs(res)) * dk),
        "err": err,
        "fit": fit,
        "ref": ref,
        "absref": absref,
        "d_rel10": float(d_rel10),
        "target_peak": float(np.max(np.abs(target))),
    }


BINS = [(0, 1000), (1000, 2000), (2000, 5000), (5000, 10000), (10000, 20000), (20000, 50000)]


def bin_max(values, lo, hi):
    sel = (D_REPORT >= lo) & (D_REPORT <= hi)
    return float(np.max(values[sel]))


def fringe_delta_e(fits, sets, data):
    """Max CIEDE2000 over D in [0, 20 um] between the closed-form and the quadrature colour of
    the two-beam fringe I(k) = (1 + cos k D) / 2, per weight set (CIELAB relative to the set's
    white, the flat spectrum, at Y = 1)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    sel = D_REPORT <= 20000.0
    m_inv = np.linalg.inv(data["m_xyz_to_srgb"])
    out = {}
    for set_name in SET_NAMES:
        norm = sets[set_name]["norm"]
        if set_name == "srgb-d65":
            to_xyz = m_inv * norm[None, :]
        else:
            to_xyz = np.diag(norm)
        y_white = (to_xyz @ np.ones(3))[1]
        to_xyz = to_xyz / y_white
        white = to_xyz @ np.ones(3)
        labs = []
        for key in ("fit", "ref"):
            v = np.array([0.5 * (1.0 + fits[set_name][c]["eval"][key][sel].real) for c in range(3)])
            xyz = (to_xyz @ v).T
            labs.append(colour.XYZ_to_Lab(xyz, colour.XYZ_to_xy(white)))
        de = colour.delta_E(labs[0], labs[1], method="CIE 2000")
        out[set_name] = float(np.max(de))
    return out


def report_lines(fits, delta_e=None):
    lines = []
    lines.append("set       ch  N  sum(a)-1   relL2(k)  max|err|/peak  L1=int|err|dk  D(rel err<10%)")
    for set_name in SET_NAMES:
        for c, ch in enumerate(CHANNELS[set_name]):
            ev = fits[set_name][c]["eval"]
            lines.append(
                f"{set_name:9s} {ch}  {ev['n']}  {ev['sum_a'] - 1:+.1e}  {ev['rel_l2']:.2e}  "
                f"{ev['max_rel']:.2e}       {ev['l1']:.2e}       {ev['d_rel10'] / 1000:.2f} um"
            )
    lines.append("")
    lines.append("max |fourier() - quadrature| (complex modulus; the white response is 1) per D range in um,")
    lines.append("and in brackets max |quadrature| (the true fringe amplitude) over the same range:")
    head = "set       ch " + "".join(f"{f'{lo // 1000}-{hi // 1000}':>20s}" for lo, hi in BINS)
    lines.append(head)
    for set_name in SET_NAMES:
        for c, ch in enumerate(CHANNELS[set_name]):
            ev = fits[set_name][c]["eval"]
            cells = "".join(
                f"{bin_max(ev['err'], lo, hi):9.1e} [{bin_max(ev['absref'], lo, hi):7.1e}]" for lo, hi in BINS
            )
            lines.append(f"{set_name:9s} {ch}  {cells}")
    if delta_e is not None:
        lines.append("")
        lines.append("max CIEDE2000, closed form vs quadrature, colour of the fringe (1 + cos kD)/2, D in [0, 20 um]:")
        lines.append("  " + ", ".join(f"{k} {v:.3f}" for k, v in delta_e.items()))
    return lines


# --------------------------------------------------------------------------
# Code generation
# --------------------------------------------------------------------------
def rs_float(x: float) -> str:
    s = repr(float(x))
    if "e" not in s and "." not in s and "inf" not in s and "nan" not in s:
        s += ".0"
    return s


def rs_array(name, values, doc):
    body = ", ".join(rs_float(v) for v in values)
    return f"/// {doc}\npub const {name}: [f64; {len(values)}] = [{body}];\n"


def rs_matrix(name, m, doc):
    rows = ", ".join("[" + ", ".join(rs_float(v) for v in row) + "]" for row in m)
    return f"/// {doc}\npub const {name}: [[f64; 3]; 3] = [{rows}];\n"


def const_name(set_name):
    return set_name.upper().replace("-", "_")


def generate(data, sets, fits) -> str:
    out = []
    out.append("// @generated by `python tools/fit_spectral_weights.py` (run from the repository root in a")
    out.append("// virtual environment with `tools/requirements-tools.txt` installed). DO NOT EDIT BY HAND.")
    out.append("//")
    out.append(f"// Data source: the `colour-science` PyPI package, version {data['colour_version']}.")
    out.append("// * CIE 1931 2-degree standard observer colour-matching functions, 360..=830 nm, 1 nm:")
    out.append("//   CIE 015:2018 Colorimetry, 4th edition (doi:10.25039/TR.015.2018); ISO/CIE 11664-1:2019")
    out.append("//   (CIE standard colorimetric observers).")
    out.append("// * CIE standard illuminant D65 relative spectral power distribution: CIE 015:2018;")
    out.append("//   ISO/CIE 11664-2:2022 (CIE standard illuminants).  5-nm table (the values for 785..830 nm")
    out.append("//   from the CIE daylight procedure, S0 + M1 S1 + M2 S2 of CIE 015:2018, which matches the")
    out.append(f"//   tabulated values to {data['d65_dev']:.0e} where both exist), linearly interpolated to 1 nm")
    out.append("//   as CIE 015:2018 prescribes for the D illuminants.  Normalised to 100 at 560 nm.")
    out.append("// * CIE standard illuminant E: constant.")
    out.append("// * XYZ -> linear sRGB matrix: IEC 61966-2-1:1999 (sRGB), D65 white; its inverse is computed")
    out.append("//   in double precision.")
    out.append("//")
    out.append("// Weight sets (per unit wavelength, piecewise-linear on the 1-nm table, 0 outside 360..=830):")
    out.append("//   xyz-e: cmf_c;  xyz-d65: cmf_c * D65;  srgb-d65: sum_m XYZ_TO_SRGB[c][m] cmf_m * D65;")
    out.append("//   each channel divided by its integral over wavelength (`NORM_*`), so a flat response of 1")
    out.append("//   gives 1.  In wavenumber k = 2 pi / lambda (rad/nm): w_k(k) = w_lambda(lambda) lambda^2 / (2 pi).")
    out.append("// Gaussian fits: w_k(k) ~= sum_j amplitude_j N(k; mu_j, sigma_j), N the unit-mass normal pdf,")
    out.append("//   least squares in k with sum_j amplitude_j = 1 enforced.")
    out.append("//")
    out.append("// Fit report (k-space errors against the tabulated weight; `L1` bounds the error of the")
    out.append("// closed-form Fourier transform at every optical path difference D):")
    for line in report_lines(fits, fringe_delta_e(fits, sets, data)):
        out.append(("// " + line).rstrip())
    out.append("")
    out.append("use crate::band::Gaussian;")
    out.append("")
    out.append(rs_float_const("LAMBDA_MIN_NM", LAMBDA_MIN_NM, "First wavelength of the tables (nm)."))
    out.append(rs_float_const("LAMBDA_MAX_NM", LAMBDA_MAX_NM, "Last wavelength of the tables (nm)."))
    out.append(f"/// Number of 1-nm samples in each table.\npub const N_TABLE: usize = {N_TABLE};\n")
    names = ["CMF_X", "CMF_Y", "CMF_Z"]
    for i in range(3):
        out.append(rs_array(names[i], data["cmf"][i], f"CIE 1931 2-degree colour-matching function {names[i][-1].lower()}-bar, 360..=830 nm."))
    out.append(rs_array("D65", np.round(data["d65"], 6), "CIE standard illuminant D65 relative SPD, 360..=830 nm, 100 at 560 nm."))
    out.append(rs_matrix("XYZ_TO_SRGB", data["m_xyz_to_srgb"], "IEC 61966-2-1 XYZ -> linear sRGB matrix (D65 white)."))
    out.append(rs_matrix("SRGB_TO_XYZ", np.linalg.inv(data["m_xyz_to_srgb"]), "Inverse of `XYZ_TO_SRGB`."))
    for set_name in SET_NAMES:
        cn = const_name(set_name)
        norm = sets[set_name]["norm"]
        out.append(
            f"/// Integral over wavelength (nm, trapezoid on the 1-nm table) of the un-normalised `{set_name}` weights.\n"
            f"pub const NORM_{cn}: [f64; 3] = [{', '.join(rs_float(v) for v in norm)}];\n"
        )
    for set_name in SET_NAMES:
        cn = const_name(set_name)
        chans = []
        for c in range(3):
            mu, sigma, a = fits[set_name][c]["mu"], fits[set_name][c]["sigma"], fits[set_name][c]["a"]
            gs = ", ".join(
                f"Gaussian {{ amplitude: {rs_float(a[j])}, mu: {rs_float(mu[j])}, sigma: {rs_float(sigma[j])} }}"
                for j in range(len(mu))
            )
            chans.append(f"&[{gs}]")
        out.append(
            f"/// Gaussian fits of the `{set_name}` weights per unit wavenumber, channels {', '.join(CHANNELS[set_name])}.\n"
            f"pub static FIT_{cn}: [&[Gaussian]; 3] = [{', '.join(chans)}];\n"
        )
    l1 = [[fits[s][c]["eval"]["l1"] for c in range(3)] for s in SET_NAMES]
    out.append(
        "/// Per set (xyz-e, xyz-d65, srgb-d65) and channel: integral over k of |fit - tabulated weight|, an\n"
        "/// upper bound on |closed-form Fourier transform - exact one| at every optical path difference.\n"
        f"pub const FIT_L1_ERROR: [[f64; 3]; 3] = [{', '.join('[' + ', '.join(rs_float(v) for v in row) + ']' for row in l1)}];\n"
    )
    e20 = [[bin_max(fits[s][c]["eval"]["err"], 0, 20000) for c in range(3)] for s in SET_NAMES]
    out.append(
        "/// Per set and channel: max over D in [0, 20 um] (10-nm steps) of the modulus of the difference\n"
        "/// between the closed-form Fourier transform and Simpson quadrature of the tabulated weight,\n"
        "/// as measured by the generator (used by the tests).\n"
        "#[cfg(test)]\n"
        f"pub const FOURIER_MAX_ERROR_20UM: [[f64; 3]; 3] = [{', '.join('[' + ', '.join(rs_float(v) for v in row) + ']' for row in e20)}];\n"
    )
    de = fringe_delta_e(fits, sets, data)
    out.append(
        "/// Per set: max over D in [0, 20 um] (10-nm steps) of the CIEDE2000 difference between the\n"
        "/// closed-form and the quadrature colour of the fringe (1 + cos kD) / 2, as measured by the\n"
        "/// generator (used by the tests).\n"
        "#[cfg(test)]\n"
        f"pub const FRINGE_MAX_DELTA_E00_20UM: [f64; 3] = [{', '.join(rs_float(de[s]) for s in SET_NAMES)}];\n"
    )
    return "\n".join(out)


def rs_float_const(name, value, doc):
    return f"/// {doc}\npub const {name}: f64 = {rs_float(value)};\n"


def main():
    data = load_data()
    sets = weight_sets(data)
    fits = {}
    for s_idx, set_name in enumerate(SET_NAMES):
        fits[set_name] = []
        for c, ch in enumerate(CHANNELS[set_name]):
            w_tab = sets[set_name]["w"][c]
            # an independent, seeded stream per channel
            results = fit_channel(w_tab, rng=np.random.default_rng([SEED, s_idx, c]))
            target = w_per_k(w_tab, K_GRID)
            for n in results:
                results[n] = results[n][:4] + (rel_l2(results[n], target),)
            n = choose(results)
            mu, sigma, a = results[n][:3]
            ev = evaluate(w_tab, mu, sigma, a)
            fits[set_name].append({"mu": mu, "sigma": sigma, "a": a, "eval": ev})
            print(
                f"{set_name} {ch}: rel L2 by N = "
                + ", ".join(f"{m}:{results[m][4]:.2e}" for m in range(1, NMAX + 1))
                + f" -> N = {n}",
                flush=True,
            )
    print()
    print("\n".join(report_lines(fits, fringe_delta_e(fits, sets, data))))
    os.makedirs(os.path.dirname(OUTPUT), exist_ok=True)
    with open(OUTPUT, "w", encoding="utf-8") as fh:
        fh.write(generate(data, sets, fits))
    try:
        subprocess.run(["rustfmt", "--edition", "2021", OUTPUT], check=True)
    except (OSError, subprocess.CalledProcessError) as exc:
        print(f"warning: rustfmt failed ({exc}); run `rustfmt --edition 2021` on the output", file=sys.stderr)
    print(f"\nwrote {os.path.relpath(OUTPUT, REPO_ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
