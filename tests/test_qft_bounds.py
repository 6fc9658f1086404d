"""Exact QFT bounds against a brute-force magnitude-grid oracle, and the QFT Toolbox example.

The oracle never uses the quadratic: it evaluates the closed-loop functions of every case
directly on a magnitude grid at each phase, then refines every allowed/forbidden transition
by bisection. The exact bound edges must agree with it to 0.01 dB.
"""
from __future__ import annotations

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from loopshaping import bounds as bounds_module
from loopshaping import qft

s = ct.tf("s")
OMEGAS = np.array([0.1, 5.0, 10.0, 100.0])
W_SENS = 0.02 * (s**3 + 64 * s**2 + 748 * s + 2400) / (s**2 + 14.4 * s + 169)
G_PUBLISHED = 379 * (s / 42 + 1) / (s**2 / 247**2 + s / 247 + 1)
G_PROPER = 379 * (s / 42 + 1) / (s / 165 + 1)


def manual_cases():
    """The QFT Toolbox manual's 40-case template: 10 points on 4 edges of the box."""
    P = lambda k, a, b: ct.tf([k], [1, a + b, a * b])  # noqa: E731
    edges = [P(10, a, 20) for a in np.linspace(1, 5, 10)]
    edges += [P(1, a, 30) for a in np.linspace(1, 5, 10)]
    edges += [P(k, 5, 30) for k in np.linspace(1, 10, 10)]
    edges += [P(k, 1, 20) for k in np.linspace(1, 10, 10)]
    return edges, 10  # nominal k=1, a=1, b=30


@pytest.fixture(scope="module")
def template():
    cases, nom = manual_cases()
    return qft.Template.from_systems(cases, OMEGAS, nominal=nom)


# Closed-loop functions written out directly (not through A, B, C, D) for the oracle.
DIRECT = {
    "stability": lambda P, G: np.abs(P * G / (1 + P * G)),
    "sensitivity": lambda P, G: np.abs(1 / (1 + P * G)),
    "input_disturbance": lambda P, G: np.abs(P / (1 + P * G)),
    "control_effort": lambda P, G: np.abs(G / (1 + P * G)),
}


def oracle_transitions(ok, phases, mags):
    """Magnitudes (dB) where ok(phase, mag) switches, per phase, refined by bisection."""
    grid = ok(phases[:, None], mags[None, :])
    out = []
    for j, ph in enumerate(phases):
        idx = np.flatnonzero(grid[j, 1:] != grid[j, :-1])
        lo, hi = mags[idx].copy(), mags[idx + 1].copy()
        left = grid[j, idx]
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            same = ok(np.full(mid.shape, ph), mid) == left
            lo, hi = np.where(same, mid, lo), np.where(same, hi, mid)
        out.append(0.5 * (lo + hi))
    return out


def exact_transitions(b, i, phases_idx, lim):
    f = b.forbidden_db[i]
    out = []
    for j in phases_idx:
        ends = f[j][~np.isnan(f[j, :, 0])].ravel()
        out.append(np.sort(ends[np.isfinite(ends) & (np.abs(ends) < lim)]))
    return out


def drop_slivers(ends, ok, phase, width=0.25):
    """Remove pairs of exact transitions closer than the oracle grid can resolve, after
    checking with the oracle's own evaluation that the sliver between them is real."""
    ends = list(ends)
    i = 0
    while i + 1 < len(ends):
        if ends[i + 1] - ends[i] < width:
            mid = 0.5 * (ends[i] + ends[i + 1])
            below = ok(np.array([phase]), np.array([ends[i] - 1e-4]))[0]
            inside = ok(np.array([phase]), np.array([mid]))[0]
            assert inside != below, f"sliver ({ends[i]}, {ends[i + 1]}) dB at {phase}° is not real"
            del ends[i : i + 2]
        else:
            i += 1
    return np.array(ends)


def make_ok(P, p0, fn, W):
    def ok(phase, mag):
        L0 = 10 ** (mag / 20) * np.exp(1j * np.deg2rad(phase))
        G = L0[..., None] / p0
        return np.all(fn(P, G) <= W, axis=-1)

    return ok


def assert_matches_oracle(b, P_all, p0_all, fn, W_all, step_deg=5, lim=58.0):
    phases_idx = np.arange(0, len(b.phases_deg), step_deg)
    phases = b.phases_deg[phases_idx]
    mags = np.arange(-60, 60.0001, 0.1)
    for i, w in enumerate(b.omega):
        k = int(np.flatnonzero(np.isclose(OMEGAS, w))[0]) if w in OMEGAS else i
        ok = make_ok(P_all[k], p0_all[k], fn, W_all[k])
        want = [drop_slivers(t[np.abs(t) < lim], ok, ph) for t, ph in zip(oracle_transitions(ok, phases, mags), phases)]
        got = exact_transitions(b, i, phases_idx, lim)
        got = [drop_slivers(g, ok, ph) for g, ph in zip(got, phases)]
        for ph, g, o in zip(phases, got, want):
            assert len(g) == len(o), f"ω={w}, φ={ph}: exact {g} vs oracle {o}"
            np.testing.assert_allclose(g, o, atol=0.01, err_msg=f"ω={w}, φ={ph}")


@pytest.mark.parametrize("kind, weight", [("stability", 1.2), ("sensitivity", W_SENS),
                                          ("input_disturbance", 0.01), ("control_effort", 50.0)])
def test_classic_bounds_match_brute_force_oracle(template, kind, weight):
    b = qft.bounds(template, kind, weight)
    W = np.abs(qft.evaluate(weight, OMEGAS))
    assert_matches_oracle(b, template.responses, template.nominal_response, DIRECT[kind], W)


@pytest.mark.filterwarnings("ignore::loopshaping.qft.BoundsWarning")  # random data: some ω empty
def test_general_bound_matches_oracle_for_random_coefficients():
    rng = np.random.default_rng(3)
    n_w, n_c = 3, 7
    cplx = lambda: rng.normal(size=(n_w, n_c)) + 1j * rng.normal(size=(n_w, n_c))  # noqa: E731
    A, B, C, D = cplx(), cplx(), cplx(), cplx()
    w = np.array([1.0, 2.0, 3.0])
    p0 = np.array([0.5 + 0.2j, -1.0 + 0.3j, 2.0j])
    tmpl = qft.Template.from_responses(w, np.stack([p0, p0 * 1.1], 1))
    W = np.array([0.8, 1.0, 1.7])
    b = qft.bounds(tmpl, "general", W, A=A, B=B, C=C, D=D)

    phases_idx = np.arange(0, 361, 5)
    mags = np.arange(-60, 60.0001, 0.1)
    for i in range(n_w):
        def ok(phase, mag, i=i):
            G = (10 ** (mag / 20) * np.exp(1j * np.deg2rad(phase)))[..., None] / p0[i]
            return np.all(np.abs((A[i] + B[i] * G) / (C[i] + D[i] * G)) <= W[i], axis=-1)

        want = [t[np.abs(t) < 58] for t in oracle_transitions(ok, b.phases_deg[phases_idx], mags)]
        got = exact_transitions(b, i, phases_idx, 58)
        for g, o in zip(got, want):
            assert len(g) == len(o)
            np.testing.assert_allclose(g, o, atol=0.01)


def test_tracking_bound_matches_ratio_oracle():
    cases = [ct.tf([k], [1, a]) for k in (1.0, 2.0, 4.0) for a in (1.0, 3.0)]
    w = np.array([0.5, 2.0, 8.0])
    tmpl = qft.Template.from_systems(cases, w)
    up, low = 1 / (s / 3 + 1), 1 / (s / 2 + 1) ** 2
    b = qft.bounds(tmpl, "tracking", upper=up, lower=low)
    ratio = np.abs(qft.evaluate(up, w) / qft.evaluate(low, w))
    phases_idx = np.arange(0, 361, 5)
    mags = np.arange(-60, 60.0001, 0.1)
    for i in range(len(w)):
        def ok(phase, mag, i=i):
            G = (10 ** (mag / 20) * np.exp(1j * np.deg2rad(phase)))[..., None] / tmpl.nominal_response[i]
            T = np.abs(tmpl.responses[i] * G / (1 + tmpl.responses[i] * G))
            return T.max(-1) / T.min(-1) <= ratio[i]

        want = [t[np.abs(t) < 58] for t in oracle_transitions(ok, b.phases_deg[phases_idx], mags)]
        got = exact_transitions(b, i, phases_idx, 58)
        for g, o in zip(got, want):
            assert len(g) == len(o)
            np.testing.assert_allclose(g, o, atol=0.01)


@pytest.fixture(scope="module")
def manual_bounds(template):
    b1 = qft.bounds(template, "stability", 1.2)
    b2 = qft.bounds(template, "sensitivity", W_SENS, band=(0, 10))
    b3 = qft.bounds(template, "input_disturbance", 0.01, band=(0, 10))
    return qft.intersect(b1, b2, b3), (b1, b2, b3)


def nominal_loop(template, G, w):
    return qft.evaluate(template.systems[template.nominal] * G, w)


@pytest.mark.parametrize("G", [G_PUBLISHED, G_PROPER], ids=["published", "proper_variant"])
def test_published_controllers_meet_every_bound(template, manual_bounds, G):
    B, parts = manual_bounds
    L0 = nominal_loop(template, G, OMEGAS)
    allowed = B.is_allowed(OMEGAS, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
    assert allowed.all()
    # Independently: every spec holds for every case at the design frequencies.
    P = template.responses
    Gw = qft.evaluate(G, OMEGAS)[:, None]
    T = np.abs(P * Gw / (1 + P * Gw))
    assert T.max() <= 1.2
    lowf = OMEGAS <= 10
    assert np.all(np.abs(1 / (1 + P * Gw))[lowf] <= np.abs(qft.evaluate(W_SENS, OMEGAS))[lowf, None])
    assert np.all(np.abs(P / (1 + P * Gw))[lowf] <= 0.01)


def test_halved_gain_violates_a_bound(template, manual_bounds):
    B, _ = manual_bounds
    L0 = nominal_loop(template, G_PUBLISHED / 4, OMEGAS)
    allowed = B.is_allowed(OMEGAS, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
    P = template.responses
    Gw = qft.evaluate(G_PUBLISHED / 4, OMEGAS)[:, None]
    met = np.all(np.abs(P / (1 + P * Gw)) <= 0.01, axis=1) | (OMEGAS > 10)
    met &= np.all(np.abs(1 / (1 + P * Gw)) <= np.abs(qft.evaluate(W_SENS, OMEGAS))[:, None], axis=1) | (OMEGAS > 10)
    met &= np.all(np.abs(P * Gw / (1 + P * Gw)) <= 1.2, axis=1)
    assert not met.all()
    np.testing.assert_array_equal(allowed, met)


def test_is_allowed_agrees_with_forbidden_intervals(manual_bounds):
    B, _ = manual_bounds
    rng = np.random.default_rng(0)
    for i, w in enumerate(B.omega):
        j = rng.integers(0, len(B.phases_deg), 200)
        m = rng.uniform(-40, 60, 200)
        f = B.forbidden_db[i, j]
        inside = np.any((m[:, None] > f[..., 0]) & (m[:, None] < f[..., 1]), axis=1)
        near = np.any(np.abs(m[:, None, None] - f) < 1e-6, axis=(1, 2))
        got = B.is_allowed(w, B.phases_deg[j], m)
        np.testing.assert_array_equal(got[~near], ~inside[~near])


def test_intersection_is_and_of_parts(manual_bounds):
    B, parts = manual_bounds
    rng = np.random.default_rng(1)
    for w in B.omega:
        ph, m = rng.uniform(-360, 0, 500), rng.uniform(-40, 60, 500)
        want = np.ones(500, bool)
        for p in parts:
            if np.any(np.isclose(p.omega, w)):
                want &= p.is_allowed(w, ph, m)
        np.testing.assert_array_equal(B.is_allowed(w, ph, m), want)
    assert B.names == ("stability", "sensitivity", "input_disturbance")
    np.testing.assert_array_equal(parts[1].omega, [0.1, 5, 10])


def test_dominant_spec_sets_the_lower_bound(manual_bounds):
    B, parts = manual_bounds
    dom = B.dominant()
    total = B.lower_bound_db()
    for i, w in enumerate(B.omega):
        for j in range(0, len(B.phases_deg), 7):
            if dom[i, j] < 0:
                assert not np.isfinite(total[i, j])
                continue
            part = parts[dom[i, j]]
            k = int(np.flatnonzero(np.isclose(part.omega, w))[0])
            np.testing.assert_allclose(part.lower_bound_db()[k, j], total[i, j])
    # At 100 rad/s only the stability spec applies.
    assert set(np.unique(dom[3])) <= {-1, 0}
    table = B.to_table()
    assert "stability" in table and "100" in table


def test_empty_bound_is_reported(template):
    with pytest.warns(qft.BoundsWarning, match="empty bound"):
        b = qft.bounds(template, "tracking", 0.9)  # max|T|/min|T| < 1 is impossible
    assert b.empty.all()
    assert "EMPTY" in b.to_table()
    assert not b.is_allowed(OMEGAS, -180.0, 10.0).any()


def test_non_connected_bound_is_reported_and_exact():
    # Two cases 16 dB apart in gain: their stability U-contours do not overlap at some phases.
    w = np.array([1.0])
    tmpl = qft.Template.from_responses(w, np.array([[1.0 + 0j, 6 * np.exp(-0.2j)]]))
    b = qft.bounds(tmpl, "stability", 1.3)
    assert b.non_connected[0]
    counts = np.sum(~np.isnan(b.forbidden_db[0, :, :, 0]), -1)
    j = int(np.flatnonzero(counts >= 2)[0])
    ok = make_ok(tmpl.responses[0], tmpl.nominal_response[0], DIRECT["stability"], 1.3)
    want = oracle_transitions(ok, b.phases_deg[[j]], np.arange(-60, 60.0001, 0.05))[0]
    got = exact_transitions(b, 0, [j], 58)[0]
    np.testing.assert_allclose(got, want, atol=0.01)
    single = qft.bounds(qft.Template.from_responses(w, np.array([[1.0 + 0j]])), "stability", 1.3)
    assert not single.non_connected[0]


def test_disk_uncertainty_enlarges_the_bound_and_converges():
    w = np.array([2.0])
    P = np.array([[0.3 - 0.4j, 0.5 - 0.5j]])
    plain = qft.bounds(qft.Template.from_responses(w, P), "stability", 1.2)
    disk = qft.Template.from_responses(w, P, disk_radius=0.3)
    coarse = qft.bounds(disk, "stability", 1.2, n_disk=24)
    fine = qft.bounds(disk, "stability", 1.2, n_disk=720)
    lb = lambda b: b.lower_bound_db()[0]  # noqa: E731
    finite = np.isfinite(lb(plain))
    assert np.all(lb(coarse)[finite] >= lb(plain)[finite] - 1e-9)
    assert np.any(lb(coarse)[finite] > lb(plain)[finite] + 0.5)
    both = np.isfinite(lb(coarse)) & np.isfinite(lb(fine))
    # Sampling the disk boundary is an inner approximation: never more restrictive.
    assert np.all(lb(coarse)[both] <= lb(fine)[both] + 1e-9)
    assert np.median(lb(fine)[both] - lb(coarse)[both]) < 0.05
    assert np.max(lb(fine)[both] - lb(coarse)[both]) < 0.5


def test_per_case_weights_and_infinite_weights(template):
    W = np.full((len(OMEGAS), template.n_cases), 0.01)
    W[:, :10] = 1e12  # the first ten cases are effectively unconstrained
    b = qft.bounds(template, "input_disturbance", W)
    sub = qft.Template.from_responses(OMEGAS, template.responses[:, 10:], nominal=0)
    ref = qft.bounds(sub, "input_disturbance", 0.01)
    np.testing.assert_allclose(b.lower_bound_db(), ref.lower_bound_db(), atol=1e-6)
    inf_w = np.array([0.01, 0.01, np.inf, np.inf])
    assert list(qft.bounds(template, "input_disturbance", inf_w).omega) == [0.1, 5.0]


def test_bad_input_names_the_argument(template):
    with pytest.raises(ValueError, match="kind"):
        qft.bounds(template, "margins", 1.2)
    with pytest.raises(TypeError, match="weight"):
        qft.bounds(template, "stability")
    with pytest.raises(TypeError, match="unknown keyword"):
        qft.bounds(template, "stability", 1.2, sensor=1.0)
    with pytest.raises(TypeError, match="A, B, C and D"):
        qft.bounds(template, "general", 1.0, A=1, B=1)
    with pytest.raises(ValueError, match="band"):
        qft.bounds(template, "stability", 1.2, band=(1000, 2000))
    with pytest.raises(ValueError, match="weight"):
        qft.bounds(template, "stability", -1.0)
    with pytest.raises(ValueError, match="phases_deg"):
        qft.bounds(template, "stability", 1.2, phases_deg=[0, -10, -20])
    with pytest.raises(ValueError, match="at least one"):
        qft.intersect()
    b = qft.bounds(template, "stability", 1.2)
    other = qft.bounds(template, "stability", 1.2, phases_deg=np.linspace(-360, 0, 73))
    with pytest.raises(ValueError, match="phases_deg"):
        qft.intersect(b, other)
    with pytest.raises(ValueError, match="not design frequencies"):
        b.is_allowed(3.0, -180, 0)


def test_noise_bound_with_sensor_dynamics_matches_oracle(template):
    H = 1 / (s / 50 + 1)
    b = qft.bounds(template, "noise", 30.0, sensor=H)
    Hw = qft.evaluate(H, OMEGAS)
    for i in range(len(OMEGAS)):
        fn = lambda P, G, i=i: np.abs(G * Hw[i] / (1 + P * G * Hw[i]))  # noqa: E731
        ok = make_ok(template.responses[i], template.nominal_response[i], fn, 30.0)
        phases_idx = np.arange(0, 361, 15)
        phases = b.phases_deg[phases_idx]
        want = [drop_slivers(t[np.abs(t) < 58], ok, ph)
                for t, ph in zip(oracle_transitions(ok, phases, np.arange(-60, 60.0001, 0.1)), phases)]
        got = [drop_slivers(g, ok, ph) for g, ph in zip(exact_transitions(b, i, phases_idx, 58), phases)]
        for g, o in zip(got, want):
            assert len(g) == len(o)
            np.testing.assert_allclose(g, o, atol=0.01)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(-50, 50), st.floats(0, 30)), min_size=1, max_size=12))
def test_interval_union_matches_a_sequential_merge(pairs):
    lo = np.array([p[0] for p in pairs])
    hi = lo + np.array([p[1] for p in pairs])
    got_lo, got_hi = bounds_module._merge(lo[None], hi[None])
    got = [(a, b) for a, b in zip(got_lo[0], got_hi[0]) if not np.isnan(a)]
    want = []
    for a, b in sorted((a, b) for a, b in zip(lo, hi) if b > a):
        if want and a <= want[-1][1]:
            want[-1] = (want[-1][0], max(want[-1][1], b))
        else:
            want.append((a, b))
    assert got == want


def test_bounds_do_not_depend_on_the_block_size(monkeypatch):
    rng = np.random.default_rng(5)
    w = np.array([0.5, 20.0, 80.0])
    k, a, b = rng.uniform(1, 10, 300), rng.uniform(1, 5, 300), rng.uniform(20, 30, 300)
    tmpl = qft.Template.from_responses(w, k / ((1j * w[:, None] + a) * (1j * w[:, None] + b)))
    ref = qft.bounds(tmpl, "stability", 1.2)
    monkeypatch.setattr(bounds_module, "_BLOCK", 700)  # a couple of phases per block
    small = qft.bounds(tmpl, "stability", 1.2)
    np.testing.assert_array_equal(small.forbidden_db, ref.forbidden_db)
    assert ref.non_connected.any()  # the sort-and-merge path was exercised
