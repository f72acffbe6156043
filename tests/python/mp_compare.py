"""Adversarial interface and plate cases, the core's answers (calculator `interface --batch`,
`slab --batch`) and the 50-digit reference of mp_reference.py, compared quantity by quantity.

Run ``python tests/python/mp_compare.py [N_PER_CATEGORY]`` for a report; the pytest file
test_mp_reference.py runs the same comparison with tolerances.

Error model (what the tolerances scale with). The core works in f64 (unit roundoff
u = 1.1e-16). Two places are ill-conditioned by nature, not by the method:

* near the edge of total internal reflection at K (beta = K (1 +- d)), the normal component
  q ~ sqrt(K^2 - beta^2) of the wave going evanescent comes from a difference of O(1) numbers:
  its relative error, and that of the powers ~ q, is ~ u K / |K - beta| = u / d;
* near the optic-axis degeneracy (wave vector at angle a from the axis), the o/e fields are
  fixed by k x A, of length ~ sin a: the per-mode fields, hence per-mode powers, amplitudes and
  ray directions, have relative error ~ u / sin a. Basis-free totals are not affected.

So the condition number of a case is cond = max(1, K/|K - beta| over the edges K present,
1/sin a over the crystal waves), and each quantity is compared as
error <= TOL * cond with TOL = 1e-12 (a factor ~1e4 above u for the few dozen operations
and the 4x4 solve, whose own condition number stays below ~1e2 away from the edges).
"""

from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys

import mpmath as mp

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import mp_reference as ref  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BIN = os.path.join(ROOT, "target", "release", "birefringence")
TOL = 1e-12


def unit(rng):
    z = rng.uniform(-1, 1)
    p = rng.uniform(0, 2 * math.pi)
    r = math.sqrt(1 - z * z)
    return [r * math.cos(p), r * math.sin(p), z]


def rnd_index(rng, lossless):
    n = rng.choice([1.0001, 4.0, math.exp(rng.uniform(math.log(1.0001), math.log(4.0)))])
    if lossless or rng.random() < 0.4:
        return n
    k = rng.choice([20.0, 10 ** rng.uniform(-6, math.log10(20))])
    return [n, k]


def re_of(x):
    return x[0] if isinstance(x, list) else x


def to_local(phi_deg, v):
    """Working-frame vector -> local frame (the calculator's azimuth convention)."""
    p = math.radians(phi_deg)
    u = (-math.cos(p), -math.sin(p))
    s = (-u[1], u[0])
    return [u[0] * v[0] + s[0] * v[1], u[1] * v[0] + s[1] * v[1], v[2]]


def tilt(v, eps, rng):
    n = math.sqrt(sum(x * x for x in v))
    v = [x / n for x in v]
    r = unit(rng)
    w = [v[1] * r[2] - v[2] * r[1], v[2] * r[0] - v[0] * r[2], v[0] * r[1] - v[1] * r[0]]
    nw = math.sqrt(sum(x * x for x in w))
    return [math.cos(eps) * a + math.sin(eps) * b / nw for a, b in zip(v, w)]


def e_index(no, ne, axis_w, d):
    """Extraordinary index along the unit wave normal d (working frame), real indices."""
    c = sum(a * b for a, b in zip(axis_w, d))
    return math.sqrt(no * no * ne * ne / (no * no * (1 - c * c) + ne * ne * c * c))


def working(phi_deg, a):
    p = math.radians(phi_deg)
    u = (-math.cos(p), -math.sin(p), 0.0)
    s = (-u[1], u[0], 0.0)
    n = math.sqrt(sum(x * x for x in a))
    return [sum(a[i] * u[i] for i in range(3)) / n, sum(a[i] * s[i] for i in range(3)) / n, a[2] / n]


def inside_beta(case, theta):
    """beta of an o- or e-wave inside whose wave normal makes the angle theta with the normal."""
    no, ne = re_of(case["eta_o"]), re_of(case["eta_e"])
    d = [math.sin(theta), 0.0, math.cos(theta)]
    if case["inside_mode"] == "o":
        return no * math.sin(theta)
    return e_index(no, ne, working(case["phi_deg"], case["optic_axis"]), d) * math.sin(theta)


def generate(n, seed=6):
    """About 6 n cases in six adversarial categories; each is (category, input, edges, axis angle)."""
    rng = random.Random(seed)
    cases = []

    def base(lossless=True):
        return {"wavelength_nm": rng.uniform(300, 1000), "ext_ior": rng.uniform(1.0, 2.0),
                "eta_o": rnd_index(rng, lossless), "eta_e": rnd_index(rng, lossless),
                "optic_axis": unit(rng), "phi_deg": rng.uniform(0, 360)}

    def with_side(c, k):
        side = ["outside", "inside", "inside"][k % 3]
        c["side"] = side
        if side == "inside":
            c["inside_mode"] = "o" if k % 3 == 1 else "e"
        return c

    # 1. generic: n in [1.0001, 4], kappa in [0, 20], any axis and angle
    for k in range(n):
        c = with_side(base(lossless=k % 2 == 0), k)
        theta = rng.uniform(0, 1.55)
        c["beta"] = c["ext_ior"] * math.sin(theta) if c["side"] == "outside" else inside_beta(c, theta)
        cases.append(("generic", c))
    # 2. grazing: 89.9 .. 89.999 degrees, both sides
    for k in range(n):
        c = with_side(base(lossless=k % 2 == 0), k)
        theta = math.radians([89.9, 89.99, 89.999][k % 3])
        c["beta"] = c["ext_ior"] * math.sin(theta) if c["side"] == "outside" else inside_beta(c, theta)
        cases.append(("grazing", c))
    # 3. TIR edges, beta = K (1 +- 1e-9), lossless
    for k in range(n):
        c = base()
        sign = 1 if k % 2 else -1
        kind = (k // 2) % 3
        no, ne = rng.uniform(1.3, 2.5), rng.uniform(1.3, 2.5)
        c["eta_o"], c["eta_e"] = no, ne
        aw = [mp.mpc(x) for x in working(c["phi_deg"], c["optic_axis"])]
        ke = float(ref.k_max_e(mp.mpf(no), mp.mpf(ne), aw))
        if kind == 0:  # from a dense exterior: the crystal's o or e wave goes evanescent
            c["ext_ior"] = rng.uniform(2.6, 4.0)
            c["side"] = "outside"
            edge = no if k % 4 < 2 else ke
        elif kind == 1:  # from inside: the transmitted exterior wave goes evanescent
            c["ext_ior"] = rng.uniform(1.0, 1.29)
            c["side"], c["inside_mode"] = "inside", "o" if k % 4 < 2 else "e"
            edge = c["ext_ior"]
        else:  # from inside: the other reflected mode goes evanescent
            c["ext_ior"] = 1.0
            c["side"] = "inside"
            c["inside_mode"], edge = ("e", no) if ke > no else ("o", ke)
        c["beta"] = edge * (1 + sign * 1e-9)
        cases.append(("tir_edge", c))
    # 4. optic axis within 1e-8 rad of the wave vector (lossless)
    for k in range(n):
        c = with_side(base(), k)
        no = re_of(c["eta_o"])
        theta = rng.uniform(0, 1.4)
        if c["side"] == "outside":
            c["beta"] = c["ext_ior"] * math.sin(theta)
            st = c["beta"] / no
            if st >= 1:
                c["ext_ior"], st = 1.0, math.sin(theta) / no
                c["beta"] = math.sin(theta)
            kw = [st, 0.0, -math.sqrt(1 - st * st)]  # refracted, o and e coincide along A
        else:
            c["inside_mode"] = "o" if k % 2 else "e"
            c["beta"] = no * math.sin(theta)  # along the axis both indices are n_o
            kw = [math.sin(theta), 0.0, math.cos(theta)]
        c["optic_axis"] = tilt(to_local(c["phi_deg"], kw), [1e-8, 1e-10, 1e-6][k % 3], rng)
        cases.append(("axis_along_k", c))
    # 5. optic axis within 1e-8 rad of the normal (incl. normal incidence)
    for k in range(n):
        c = with_side(base(lossless=k % 4 != 3), k)
        c["optic_axis"] = tilt([0.0, 0.0, 1.0], 1e-8, rng)
        theta = 0.0 if k % 4 == 0 else rng.uniform(0, 1.5)
        c["beta"] = c["ext_ior"] * math.sin(theta) if c["side"] == "outside" else inside_beta(c, theta)
        cases.append(("axis_along_normal", c))
    # 6. eta_e = eta_o exactly, and to 1e-12
    for k in range(n):
        c = with_side(base(lossless=k % 2 == 0), k)
        if k % 3 == 2:
            c["side"] = "outside"
            c.pop("inside_mode", None)
        eo = c["eta_o"]
        if k % 3 == 0:
            c["eta_e"] = eo
        else:
            c["eta_e"] = [re_of(eo) * (1 + 1e-12), eo[1]] if isinstance(eo, list) else eo * (1 + 1e-12)
        theta = rng.uniform(0, 1.5)
        c["beta"] = c["ext_ior"] * math.sin(theta) if c["side"] == "outside" else inside_beta(c, theta)
        cases.append(("eta_e_eq_eta_o", c))
    return cases


def run_core(cases, sub="interface"):
    """The calculator's answers to `cases` ((category, case) pairs), one batch run of `sub`."""
    text = "\n".join(json.dumps(c) for _, c in cases) + "\n"
    p = subprocess.run([BIN, sub, "--batch"], input=text, capture_output=True, text=True)
    return [json.loads(line) for line in p.stdout.splitlines()]


def cx(v):
    return complex(v[0], v[1])


def angle_to_axis(wave, axis_w):
    """sin of the angle between a wave's (real) wave vector and the optic axis."""
    k = [mp.re(x) for x in wave.k]
    a = [mp.mpf(x) for x in axis_w]
    c = ref.cross(k, a)
    return float(mp.sqrt(sum(x * x for x in c)) / mp.sqrt(sum(x * x for x in k))
                 / mp.sqrt(sum(x * x for x in a)))


def compare(category, case, core, errors, details):
    """Adds this case's errors (error / (TOL * cond) is what the test bounds) to `errors`:
    a dict quantity -> list of (error, cond, case)."""
    out = ref.interface(case)
    beta = float(mp.re(ref.mpc_of(case["beta"])))
    no, ne = re_of(case["eta_o"]), re_of(case["eta_e"])
    lossless = not isinstance(case["eta_o"], list) and not isinstance(case["eta_e"], list)
    aw = working(case["phi_deg"], case["optic_axis"])
    edges = [case["ext_ior"], no]
    if lossless and no != ne:
        edges.append(float(ref.k_max_e(mp.mpf(no), mp.mpf(ne), [mp.mpc(x) for x in aw])))
    cond_edge = max([1.0] + [k / abs(k - beta) for k in edges if k != beta] + [1e16 if beta in edges else 1.0])
    iso = case["eta_o"] == case["eta_e"]
    sines = [angle_to_axis(w, aw) for w in out["waves_cr_down"] + out["waves_cr_up"]]
    cond_axis = 1.0 if iso else 1.0 / max(min(sines), 1e-16)
    cond = max(cond_edge, cond_axis)
    per_mode_ok = iso or min(sines) > 1e-12  # o/e split defined to better than 1e-4

    def add(q, err, c=cond):
        errors.setdefault(q, []).append((err, c, category, case))

    def power(q, got, want, c=cond):
        want = float(want)
        # Relative error above 1e-2 of the incident power, absolute below (cross-polarised
        # reflection in symmetric set-ups and evanescent waves vanish).
        add(q, abs(got - want) / max(abs(want), 1e-2), c)

    if case["side"] == "outside":
        for ab in ("ss", "sp", "ps", "pp"):
            power("R " + ab, core["R"][ab], out["R"][ab], cond_edge)
            r_ref = complex(out["r"][ab])
            if abs(r_ref) > 1e-6:
                add("phase r " + ab, abs(cx(core["r"][ab]) / r_ref - 1),
                    cond_edge * max(1.0, 1 / abs(r_ref)))
        for a in "sp":
            if per_mode_ok:
                for b in "oe":
                    power(f"T {a}{b}", core["T"][a][b], out["T"][(a, b)])
            else:
                power(f"T {a} total", core["T"][a]["o"] + core["T"][a]["e"],
                      out["T"][(a, "o")] + out["T"][(a, "e")], cond_edge)
        if per_mode_ok:
            for b in "oe":
                ts_ref, tp_ref = complex(out["t"][("s", b)]), complex(out["t"][("p", b)])
                if abs(ts_ref) > 1e-6 and abs(tp_ref) > 1e-6:
                    got = cx(core["t"]["s"][b]) / cx(core["t"]["p"][b])
                    add(f"phase t_s{b}/t_p{b}", abs(got / (ts_ref / tp_ref) - 1),
                        cond * max(1.0, 1 / abs(ts_ref), 1 / abs(tp_ref)))
        rays = [("ray o", core["waves"]["transmitted"]["o"], out["waves_cr_down"][0]),
                ("ray e", core["waves"]["transmitted"]["e"], out["waves_cr_down"][1])]
    else:
        for b in "sp":
            power("T " + b, core["T"][b], out["T"][b], cond_edge if iso else cond)
        if per_mode_ok:
            for b in "oe":
                power("R " + b, core["R"][b], out["R"][b])
        else:
            power("R total", core["R"]["o"] + core["R"]["e"], out["R"]["o"] + out["R"]["e"], cond_edge)
        ts_ref, tp_ref = complex(out["t"]["s"]), complex(out["t"]["p"])
        if abs(ts_ref) > 1e-6 and abs(tp_ref) > 1e-6 and per_mode_ok:
            got = cx(core["t"]["p"]) / cx(core["t"]["s"])
            add("phase t_p/t_s", abs(got / (tp_ref / ts_ref) - 1),
                cond * max(1.0, 1 / abs(ts_ref), 1 / abs(tp_ref)))
        rays = [("ray o (reflected)", core["waves"]["reflected"]["o"], out["waves_cr_down"][0]),
                ("ray e (reflected)", core["waves"]["reflected"]["e"], out["waves_cr_down"][1]),
                ("ray exterior", core["waves"]["transmitted"]["s"], out["waves_ext_up"][0])]
    for name, wc, wr in rays:
        d = ref.ray_direction(out["frame"], wr)
        if wc["ray_direction"] is None or d is None or wc["evanescent"]:
            continue
        if not (per_mode_ok or name == "ray exterior"):
            continue
        if abs(float(wr.flux)) < 1e-6 * float(mp.sqrt(sum(x * x for x in wr.poynting))):
            continue  # ray direction ill-defined for waves carrying (almost) no flux
        err = math.sqrt(sum((a - float(b)) ** 2 for a, b in zip(wc["ray_direction"], d)))
        add(name, err, cond)
    details["cases"] = details.get("cases", 0) + 1
    details.setdefault(category, 0)
    details[category] += 1


def run(n):
    cases = generate(n)
    core = run_core(cases)
    errors, details = {}, {}
    failures = []
    for (category, case), c in zip(cases, core):
        if "error" in c:
            failures.append((category, case, c["error"]))
            continue
        compare(category, case, c, errors, details)
    return errors, details, failures


def summary(errors):
    """quantity -> (worst raw error over the cases with cond <= 10, worst error / cond, its
    category, its case, number of comparisons, worst raw error over all cases)."""
    out = {}
    for q, es in sorted(errors.items()):
        raw = max([e[0] for e in es if e[1] <= 10] or [0.0])
        scaled = max(es, key=lambda e: e[0] / e[1])
        out[q] = (raw, scaled[0] / scaled[1], scaled[2], scaled[3], len(es),
                  max(e[0] for e in es))
    return out


def report(errors):
    for q, (raw, scaled, cat, case, count, raw_all) in summary(errors).items():
        print(f"{q:20s} n={count:4d} worst (cond <= 10) {raw:.2e}; worst overall {raw_all:.2e};"
              f" worst error/cond {scaled:.2e} ({cat})")


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100
    for runner in (run, run_slabs):
        errors, details, failures = runner(n)
        print(f"cases compared: {details}")
        print(f"core errors: {len(failures)}")
        for f in failures[:10]:
            print("  ", f)
        report(errors)


# ---- plates ----------------------------------------------------------------------------------
#
# Error model of a plate: on top of the interfaces' (above), each internal path carries the
# phase k0 q d, rounded in f64 to ~u k0 d n: cond_plate = cond_interface * (1 + k0 d n_max).

def generate_slabs(n, seed=7):
    """About 4 n plates: generic (n 1.0001..4, kappa 0..20, 1 nm .. 10 cm, 300..1000 nm),
    frustrated total internal reflection (a thin layer under a dense exterior), grazing
    incidence (89.9 .. 89.999 deg), and the degenerate axis (along the normal, eta_e = eta_o)."""
    rng = random.Random(seed)
    cases = []

    def base(lossless):
        c = {"wavelength_nm": rng.uniform(300, 1000), "ext_ior": rng.uniform(1.0, 2.5),
             "exit_ior": rng.uniform(1.0, 2.5), "eta_o": rnd_index(rng, lossless),
             "eta_e": rnd_index(rng, lossless), "optic_axis": unit(rng),
             "phi_deg": rng.uniform(0, 360),
             "thickness_um": 10 ** rng.uniform(-3, 5)}
        return c

    for k in range(n):
        c = base(k % 2 == 0)
        c["beta"] = c["ext_ior"] * math.sin(rng.uniform(0, 1.55))
        cases.append(("plate_generic", c))
    for k in range(n):
        c = base(True)
        c["ext_ior"] = rng.uniform(2.6, 4.0)
        c["eta_o"], c["eta_e"] = rng.uniform(1.3, 2.5), rng.uniform(1.3, 2.5)
        c["exit_ior"] = rng.uniform(2.6, 4.0)
        c["thickness_um"] = 10 ** rng.uniform(-3, 0)
        c["beta"] = c["ext_ior"] * math.sin(rng.uniform(1.0, 1.5))
        cases.append(("plate_frustrated_tir", c))
    for k in range(n):
        c = base(k % 2 == 0)
        c["beta"] = c["ext_ior"] * math.sin(math.radians([89.9, 89.99, 89.999][k % 3]))
        cases.append(("plate_grazing", c))
    for k in range(n):
        c = base(k % 2 == 0)
        if k % 2:
            c["optic_axis"] = tilt([0.0, 0.0, 1.0], 1e-8, rng)
        else:
            c["eta_e"] = c["eta_o"]
        c["beta"] = c["ext_ior"] * math.sin(rng.uniform(0, 1.5))
        cases.append(("plate_degenerate", c))
    return cases


def compare_slab(category, case, core, errors, details):
    out = ref.slab(case)
    beta = case["beta"]
    ns = [re_of(case["eta_o"]), re_of(case["eta_e"])]
    edges = [case["ext_ior"], case["exit_ior"]] + ns
    cond_edge = max([1.0] + [k / abs(k - beta) for k in edges if k != beta])
    k0d = 2 * math.pi * case["thickness_um"] * 1000 / case["wavelength_nm"]
    cond = cond_edge * (1 + k0d * max(ns))

    def add(q, err, c=cond):
        errors.setdefault(q, []).append((err, c, category, case))

    for ab in ("ss", "sp", "ps", "pp"):
        for which in "RT":
            want = float(out[which][ab])
            add(f"plate {which} {ab}", abs(core[which][ab] - want) / max(abs(want), 1e-2))
    for which, key in (("R", "jones_R"), ("T", "jones_T")):
        for o in range(2):
            for c in range(2):
                z = complex(out[key][o][c])
                if abs(z) > 1e-6:
                    got = cx(core["jones"][which][o][c])
                    add(f"plate phase J{which}", abs(got / z - 1), cond * max(1.0, 1 / abs(z)))
    details["plates"] = details.get("plates", 0) + 1
    details[category] = details.get(category, 0) + 1


def run_slabs(n):
    cases = generate_slabs(n)
    core = run_core(cases, "slab")
    errors, details, failures = {}, {}, []
    for (category, case), c in zip(cases, core):
        if "error" in c:
            failures.append((category, case, c["error"]))
            continue
        compare_slab(category, case, c, errors, details)
    return errors, details, failures
