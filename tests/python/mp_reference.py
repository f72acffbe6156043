"""High-precision reference (mpmath, 50 significant digits) for one planar interface between
an isotropic exterior and a uniaxial, possibly absorbing, crystal; independent of the Rust core.

Derived from Maxwell's equations, not from the core's code:

* Plane waves ``E exp(i k0 (beta x + q z))`` in a non-magnetic medium of permittivity tensor
  ``eps`` satisfy ``k x (k x E) + eps E = 0`` with ``k = (beta, 0, q)`` (units of k0, time
  factor ``exp(-i w t)``), i.e. ``M(q) E = 0`` with ``M = k k^T - (k.k) I + eps``.
  ``det M(q)`` is a polynomial of degree 4 in ``q``; its coefficients are computed exactly by
  polynomial arithmetic on the entries of ``M`` and its four roots by ``mpmath.polyroots`` (the
  factorisation into ordinary and extraordinary waves is *not* used: it is a consequence that
  the comparison checks).
* Each root's polarisation is the null vector of ``M(q)`` (the largest cross product of two rows
  of the complex-symmetric ``M``); ``H = k x E`` (Faraday's law in these units).
* A wave goes down (into the crystal, ``z < 0``) if it decays downwards (``Im q < 0``) or, when
  ``q`` is real, if its time-averaged Poynting flux ``1/2 Re(E x H*)_z`` points down.
* o/e labels: the ordinary wave is the one whose field is perpendicular to the optic axis
  (``E . A = 0``); when the wave vector is (nearly) along the axis, the one with
  ``q^2 + beta^2`` closest to ``eps_o``.
* The boundary conditions (continuity of tangential ``E`` and ``H`` at ``z = 0``) give a 4x4
  linear system for the two reflected and two transmitted amplitudes, solved by LU at 50 digits.
* Power fractions are ``|amplitude|^2 |S_z(out)| / |S_z(in)|``, each wave's own normal Poynting
  flux (the definition documented for the calculator's outputs).

Exterior waves use the basis ``E_s = y``, ``E_p = k_hat x y`` of the working frame (z = normal
towards the exterior, x = tangential direction of the wave vector, y = z x x), the convention
stated in docs/calculator.md. The local frame of the calculator is mapped to this working frame with the
calculator's documented azimuth convention: the direction towards the light is
``(sin t cos phi, sin t sin phi, +-cos t)``, so ``x = -(cos phi, sin phi, 0)``.
"""

from __future__ import annotations

import mpmath as mp

mp.mp.dps = 50

ZERO = mp.mpc(0)
ONE = mp.mpc(1)


# ---- polynomials in q (lists of coefficients, lowest degree first) -------------------------

def padd(a, b):
    n = max(len(a), len(b))
    return [(a[i] if i < len(a) else ZERO) + (b[i] if i < len(b) else ZERO) for i in range(n)]


def pmul(a, b):
    out = [ZERO] * (len(a) + len(b) - 1)
    for i, x in enumerate(a):
        for j, y in enumerate(b):
            out[i + j] += x * y
    return out


def pneg(a):
    return [-x for x in a]


def peval(a, q):
    return sum(c * q**i for i, c in enumerate(a))


# ---- media -----------------------------------------------------------------------------------

def mpc_of(z):
    """An mpc from a float, a complex or an (re, im) pair: the exact binary value."""
    if isinstance(z, (list, tuple)):
        return mp.mpc(mp.mpf(z[0]), mp.mpf(z[1]))
    if isinstance(z, complex):
        return mp.mpc(mp.mpf(z.real), mp.mpf(z.imag))
    return mp.mpc(mp.mpf(z))


def permittivity(eta_o, eta_e, axis):
    """``eps = eps_o I + (eps_e - eps_o) A A^T`` of a uniaxial medium (axis: unit, mp)."""
    eo, ee = eta_o**2, eta_e**2
    return [[eo * (1 if i == j else 0) + (ee - eo) * axis[i] * axis[j] for j in range(3)]
            for i in range(3)]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def dot(a, b):
    """Bilinear (not Hermitian) product."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def hnorm(a):
    return mp.sqrt(sum(abs(x) ** 2 for x in a))


class Wave:
    """A plane wave of unit amplitude at z = 0: wave vector (beta, 0, q), fields E, H."""

    def __init__(self, beta, q, e, kind):
        self.beta, self.q, self.e, self.kind = beta, q, e, kind
        self.k = [beta, ZERO, q]
        self.h = cross(self.k, e)
        s = cross(e, [mp.conj(x) for x in self.h])
        self.poynting = [mp.re(x) / 2 for x in s]
        self.flux = self.poynting[2]

    def tangential(self):
        return [self.e[0], self.e[1], self.h[0], self.h[1]]


def isotropic_waves(eta, beta):
    """(down, up) pairs [s, p] of an isotropic medium of index eta: q = +-sqrt(eta^2 - beta^2)
    on the branch that decays (or carries power) in its direction."""
    q = mp.sqrt(eta**2 - beta**2)
    if mp.im(q) < 0 or (mp.im(q) == 0 and mp.re(q) < 0):
        q = -q
    out = []
    for qq in (-q, q):  # down, up
        s = Wave(beta, qq, [ZERO, ONE, ZERO], "s")
        p = Wave(beta, qq, [-qq / eta, ZERO, beta / eta], "p")  # k_hat x y
        out.append([s, p])
    return out[0], out[1]


def quartic(eps, beta):
    """Coefficients (lowest first) of det(k k^T - (k.k) I + eps) in q, exactly."""
    b = beta
    # Entries as polynomials in q: k k^T - (beta^2 + q^2) I + eps.
    kk = [[[b * b], [ZERO], [ZERO, b]],
          [[ZERO], [ZERO], [ZERO]],
          [[ZERO, b], [ZERO], [ZERO, ZERO, ONE]]]
    m = [[padd(kk[i][j], [eps[i][j]]) for j in range(3)] for i in range(3)]
    for i in range(3):
        m[i][i] = padd(m[i][i], [-b * b, ZERO, -ONE])
    det = [ZERO]
    for (i, j, k, sign) in [(0, 1, 2, 1), (1, 2, 0, 1), (2, 0, 1, 1),
                            (0, 2, 1, -1), (1, 0, 2, -1), (2, 1, 0, -1)]:
        term = pmul(pmul(m[0][i], m[1][j]), m[2][k])
        det = padd(det, term if sign > 0 else pneg(term))
    while len(det) > 1 and det[-1] == 0:
        det.pop()
    return det, m


def null_vectors(m, q):
    """Null space of M(q) (3x3 complex symmetric): one vector if rank 2, two if rank 1."""
    mq = [[peval(m[i][j], q) for j in range(3)] for i in range(3)]
    scale = max(abs(x) for row in mq for x in row)
    cands = [cross(mq[0], mq[1]), cross(mq[1], mq[2]), cross(mq[2], mq[0])]
    best = max(cands, key=hnorm)
    if hnorm(best) > mp.mpf(10) ** (-30) * scale**2:
        return [best]
    r = max(mq, key=hnorm)
    units = [[ONE, ZERO, ZERO], [ZERO, ONE, ZERO], [ZERO, ZERO, ONE]]
    v1 = max((cross(r, u) for u in units), key=hnorm)
    return [v1, cross(r, v1)]


def crystal_waves(eta_o, eta_e, axis, beta):
    """(down, up) pairs [o, e] of the crystal (axis in the working frame, unit), or its s/p
    waves when eta_o == eta_e exactly (then the calculator labels them o = s, e = p).

    Near a degeneracy (two roots q closer than ~1e-10 relative: wave vector nearly along the
    axis, or eta_e nearly eta_o) a root is only known to ~u/sep and its null vector to
    ~u/sep^2 (u = 10^-dps), so the working precision is raised to 50 + 2 log10(1/sep) + 10
    digits there: the reference keeps ~50 significant digits in every case."""
    if eta_o == eta_e:
        return isotropic_waves(eta_o, beta)
    down, up = _crystal_waves(eta_o, eta_e, axis, beta)
    qs = [w.q for w in down + up]
    sep = min(abs(qs[i] - qs[j]) / max(abs(qs[i]), mp.mpf(1))
              for i in range(4) for j in range(i + 1, 4))
    if sep < mp.mpf(10) ** -10:
        extra = 2 * int(-mp.log10(max(sep, mp.mpf(10) ** -200))) + 10
        with mp.extradps(extra):
            down, up = _crystal_waves(+eta_o, +eta_e, [+a for a in axis], +beta)
    return down, up


def _crystal_waves(eta_o, eta_e, axis, beta):
    eps = permittivity(eta_o, eta_e, axis)
    det, m = quartic(eps, beta)
    roots = mp.polyroots(det, maxsteps=400, extraprec=400, asc=True)
    waves = []
    used = set()
    for idx, q in enumerate(roots):
        vs = null_vectors(m, q)
        if len(vs) == 2:  # exactly degenerate pair: give each root one of the two fields
            key = min(j for j in range(len(roots)) if abs(roots[j] - q) < mp.mpf(10) ** -30)
            e = vs[0] if key not in used else vs[1]
            used.add(key)
        else:
            e = vs[0]
        e = [x / hnorm(e) for x in e]
        waves.append(Wave(beta, q, e, None))
    tiny = mp.mpf(10) ** -30
    down = [w for w in waves if mp.im(w.q) < -tiny or (abs(mp.im(w.q)) <= tiny and w.flux < 0)]
    up = [w for w in waves if w not in down]
    assert len(down) == 2 and len(up) == 2, [w.q for w in waves]
    eo = eta_o**2

    def label(pair):
        score = [abs(dot(w.e, axis)) for w in pair]
        if max(score) > tiny and min(score) < mp.mpf("0.5") * max(score):
            o = 0 if score[0] < score[1] else 1
        else:
            d = [abs(w.q**2 + beta**2 - eo) for w in pair]
            o = 0 if d[0] <= d[1] else 1
        pair[o].kind, pair[1 - o].kind = "o", "e"
        return [pair[o], pair[1 - o]]

    return label(down), label(up)


def solve(a_cols, rhs):
    a = mp.matrix(4, 4)
    for j, col in enumerate(a_cols):
        for i in range(4):
            a[i, j] = col[i]
    return mp.lu_solve(a, mp.matrix(rhs))


def working_frame(phi_deg):
    phi = mp.radians(mp.mpf(phi_deg))
    u = [-mp.cos(phi), -mp.sin(phi), mp.mpf(0)]
    s = [-u[1], u[0], mp.mpf(0)]  # z x u
    return u, s


def to_local(frame, v):
    u, s = frame
    return [u[i] * v[0] + s[i] * v[1] + (v[2] if i == 2 else 0) for i in range(3)]


def working_axis(case):
    """The case's optic axis (any length, local frame) as a unit vector in the working frame of
    its plane of incidence (`phi_deg`)."""
    u, s = working_frame(case.get("phi_deg", 0.0))
    a_local = [mp.mpf(x) for x in case["optic_axis"]]
    na = mp.sqrt(sum(x * x for x in a_local))
    a_local = [x / na for x in a_local]
    return [mp.mpc(sum(a_local[i] * u[i] for i in range(3))),
            mp.mpc(sum(a_local[i] * s[i] for i in range(3))), mp.mpc(a_local[2])]


def interface(case):
    """Reference outputs for one calculator input (a dict with wavelength_nm, ext_ior, eta_o,
    eta_e, optic_axis, beta, phi_deg, side, inside_mode; constant indices only)."""
    n1 = mpc_of(case.get("ext_ior", 1.0))
    eta_o, eta_e = mpc_of(case["eta_o"]), mpc_of(case["eta_e"])
    axis = working_axis(case)
    beta = mpc_of(case["beta"])
    ext_down, ext_up = isotropic_waves(n1, beta)
    cr_down, cr_up = crystal_waves(eta_o, eta_e, axis, beta)
    cols = [w.tangential() for w in ext_up] + [[-x for x in w.tangential()] for w in cr_down]
    out = {"waves_ext_up": ext_up, "waves_cr_down": cr_down, "waves_cr_up": cr_up,
           "waves_ext_down": ext_down, "frame": working_frame(case.get("phi_deg", 0.0))}
    if case.get("side", "outside") == "outside":
        R, T, r, t = {}, {}, {}, {}
        for a, inc in zip("sp", ext_down):
            x = solve(cols, [-v for v in inc.tangential()])
            pin = abs(inc.flux)
            for b, k in zip("sp", range(2)):
                r[a + b] = x[k]
                R[a + b] = abs(x[k]) ** 2 * abs(ext_up[k].flux) / pin
            for b, k in zip("oe", range(2)):
                t[(a, b)] = x[2 + k]
                T[(a, b)] = abs(x[2 + k]) ** 2 * abs(cr_down[k].flux) / pin
        out.update(R=R, T=T, r=r, t=t)
    else:
        m = 0 if case["inside_mode"] == "o" else 1
        inc = cr_up[m]
        x = solve(cols, inc.tangential())
        pin = abs(inc.flux)
        out.update(
            T={b: abs(x[k]) ** 2 * abs(ext_up[k].flux) / pin for b, k in zip("sp", range(2))},
            R={b: abs(x[2 + k]) ** 2 * abs(cr_down[k].flux) / pin for b, k in zip("oe", range(2))},
            t={b: x[k] for b, k in zip("sp", range(2))},
            r={b: x[2 + k] for b, k in zip("oe", range(2))},
        )
    return out


def ray_direction(frame, wave):
    """Unit Poynting direction in the local frame (None if the wave carries no power)."""
    p = wave.poynting
    n = mp.sqrt(sum(x * x for x in p))
    if n == 0:
        return None
    return to_local(frame, [x / n for x in p])


def k_max_e(eta_o, eta_e, axis):
    """The incidence parameter beyond which the crystal's extraordinary waves are evanescent
    (lossless): the beta at which its two e roots merge, i.e. where the discriminant in q of the
    e-wave dispersion relation k^T eps k = eps_o eps_e vanishes (found by bisection on beta)."""
    eps = permittivity(eta_o, eta_e, axis)

    def disc(b):
        # k^T eps k - eps_o eps_e = a q^2 + 2 c q + d with k = (b, 0, q)
        a = eps[2][2]
        c = eps[0][2] * b
        d = eps[0][0] * b * b - eta_o**2 * eta_e**2
        return mp.re(c * c - a * d)

    lo, hi = mp.mpf(0), mp.mpf(10)
    for _ in range(200):
        mid = (lo + hi) / 2
        if disc(mid) > 0:
            lo = mid
        else:
            hi = mid
    return lo


def slab(case):
    """Reference plate (calculator `slab` input: thickness_um, exit_ior; outside incidence) at
    one wavelength: the eight unknown amplitudes (reflected s, p at z = 0; the crystal's two
    down-going waves referenced at z = 0 and two up-going waves referenced at z = -d; the exit
    medium's s, p referenced at z = -d) from the continuity of tangential E and H at both
    faces, one 8x8 system per input polarisation, solved at 50 digits. Referencing every wave
    where it enters the layer keeps every propagation factor exp(i k0 q dz) of modulus <= 1.
    Returns R[in+out], T[in+out] power fractions and the flux-normalised Jones matrices
    J_R, J_T (rows: output s, p; columns: input s, p)."""
    n1 = mpc_of(case.get("ext_ior", 1.0))
    n3 = mpc_of(case.get("exit_ior", case.get("ext_ior", 1.0)))
    eta_o, eta_e = mpc_of(case["eta_o"]), mpc_of(case["eta_e"])
    axis = working_axis(case)
    beta = mpc_of(case["beta"])
    k0d = 2 * mp.pi * mp.mpf(case["thickness_um"]) * 1000 / mp.mpf(case["wavelength_nm"])
    top_down, top_up = isotropic_waves(n1, beta)
    cr_down, cr_up = crystal_waves(eta_o, eta_e, axis, beta)
    ex_down, _ = isotropic_waves(n3, beta)
    i = mp.mpc(0, 1)
    pd = [mp.exp(-i * w.q * k0d) for w in cr_down]  # down wave from z = 0 to z = -d
    pu = [mp.exp(i * w.q * k0d) for w in cr_up]     # up wave from z = -d to z = 0
    # Unknowns x = [r_s, r_p, a_1, a_2, b_1, b_2, t_s, t_p].
    a = mp.matrix(8, 8)
    for row in range(4):
        # z = 0: incident + r_s, r_p (top) = a (crystal down) + b exp(i q_up d) (crystal up)
        a[row, 0] = top_up[0].tangential()[row]
        a[row, 1] = top_up[1].tangential()[row]
        for k in range(2):
            a[row, 2 + k] = -cr_down[k].tangential()[row]
            a[row, 4 + k] = -cr_up[k].tangential()[row] * pu[k]
        # z = -d: a exp(-i q_down d) + b = t (exit down)
        for k in range(2):
            a[4 + row, 2 + k] = cr_down[k].tangential()[row] * pd[k]
            a[4 + row, 4 + k] = cr_up[k].tangential()[row]
            a[4 + row, 6 + k] = -ex_down[k].tangential()[row]
    R, T = {}, {}
    jr = [[None, None], [None, None]]
    jt = [[None, None], [None, None]]
    ex_flux = [abs(w.flux) if abs(mp.im(w.q)) < mp.mpf(10) ** -30 or mp.im(n3) != 0 else 0
               for w in ex_down]
    for c, inc in enumerate(top_down):
        rhs = mp.matrix([-v for v in inc.tangential()] + [0, 0, 0, 0])
        x = mp.lu_solve(a, rhs)
        pin = abs(inc.flux)
        for o in range(2):
            R["sp"[c] + "sp"[o]] = abs(x[o]) ** 2 * abs(top_up[o].flux) / pin
            T["sp"[c] + "sp"[o]] = abs(x[6 + o]) ** 2 * ex_flux[o] / pin
            jr[o][c] = x[o]
            jt[o][c] = x[6 + o] * mp.sqrt(ex_flux[o] / pin)
    return {"R": R, "T": T, "jones_R": jr, "jones_T": jt}
