"""The core's interface and plate (calculator `interface --batch`, `slab --batch`) against the
independent 50-digit reference of mp_reference.py: 100 plates, and 540 adversarial interface cases (mp_compare.py: generic, grazing to
89.999 deg, beta within 1e-9 of K_max on both sides, optic axis within 1e-8..1e-10 rad of the
wave vector and of the normal, eta_e = eta_o exactly and to 1e-12, n 1.0001..4, kappa 0..20).

Tolerance (mp_compare.py explains the model): every quantity's error <= 1e-12 * cond, where
cond = max(1, K/|K - beta| at the TIR edges, 1/sin(angle between the wave vector and the
optic axis) for per-mode quantities). 1e-12 is ~1e4 unit roundoffs: the core's 4x4 solve and
mode construction take a few dozen operations with condition numbers up to ~1e2 away from those
two singularities. Powers are compared relative to max(P, 1e-2) (absolute below 1% of the
incident power, where relative errors of vanishing cross-polarised terms are meaningless);
phases as |z_core / z_ref - 1| for amplitudes above 1e-6, with cond also multiplied by
1/|z_ref| (an amplitude near a zero, e.g. at Brewster's angle, has an absolute error ~u).
"""

import os

import pytest

import mp_compare

N_PER_CATEGORY = 90  # 6 categories -> 540 cases, ~15-30 s


@pytest.fixture(scope="module")
def comparison():
    if not os.path.exists(mp_compare.BIN):
        pytest.fail(f"{mp_compare.BIN} missing: run make setup")
    return mp_compare.run(N_PER_CATEGORY)


def test_core_answers_every_case(comparison):
    _, details, failures = comparison
    assert not failures, failures[:5]
    assert details["cases"] >= 500


def check(errors, required):
    worst = mp_compare.summary(errors)
    mp_compare.report(errors)
    bad = {q: (w[1], w[2], w[3]) for q, w in worst.items() if w[1] > mp_compare.TOL}
    assert not bad, bad
    # Every quantity family was exercised.
    for q in required:
        assert q in worst and worst[q][4] >= 50, q


def test_every_quantity_within_the_conditioned_tolerance(comparison):
    errors, details, _ = comparison
    print(f"\n{details['cases']} cases: {details}")
    check(errors, ("R ss", "R pp", "T so", "T pe", "T s", "T p", "R o", "R e", "phase r ss",
                   "phase t_p/t_s", "ray o", "ray e", "ray exterior"))


def test_plates_within_the_conditioned_tolerance():
    """100 plates (mp_compare.generate_slabs: generic 1 nm - 10 cm with kappa to 20, frustrated
    TIR in thin layers, grazing to 89.999 deg, degenerate axis or indices), each an 8x8
    boundary system at 50 digits; same tolerance model, with the phase rounding of the
    internal paths (1 + k0 d n) in cond."""
    errors, details, failures = mp_compare.run_slabs(25)
    assert not failures, failures[:5]
    assert details["plates"] == 100
    print(f"\n{details}")
    check(errors, ("plate R ss", "plate R pp", "plate T ss", "plate T pp", "plate phase JR",
                   "plate phase JT"))
