"""specdesign.fatigue: rainflow against the `rainflow` package and a pure-Python oracle,
S-N curves, Miner sums and DEL against closed forms, the variance-damage surrogate and the
economic cost."""
from __future__ import annotations

from collections import Counter

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit
from numpy.testing import assert_allclose

from specdesign.fatigue import (
    Cycles,
    SNCurve,
    del_rainflow,
    economic_cost,
    fit_variance_damage,
    goodman_ranges,
    miner_damage,
    rainflow,
)

rf = pytest.importorskip("rainflow")


def _package_cycles(x):
    """Cycles of the reference package, minus its zero-range half cycle of constant signals."""
    return [(r, mu, c) for r, mu, c, _, _ in rf.extract_cycles(list(x)) if not (np.ptp(x) == 0)]


def _oracle(x):
    """Independent pure-Python ASTM E1049 three-point counter (lists, no numpy, no numba).

    Turning points: drop repeats, keep the ends and every point where the slope changes sign.
    """
    pts = [x[0]]
    for v in x[1:]:
        if v != pts[-1]:
            pts.append(v)
    tp = [pts[0]] + [b for a, b, c in zip(pts, pts[1:], pts[2:]) if (b - a) * (c - b) < 0] + ([pts[-1]] if len(pts) > 1 else [])
    if len(x) == 2:
        tp = tp[:1]  # two samples hold a single reversal in ASTM's (and rainflow's) sense
    out, stack = [], []
    for p in tp:
        stack.append(p)
        while len(stack) >= 3:
            y = abs(stack[-2] - stack[-3])
            if abs(stack[-1] - stack[-2]) < y:
                break
            if len(stack) == 3:
                out.append((y, (stack[0] + stack[1]) / 2, 0.5))
                stack.pop(0)
            else:
                out.append((y, (stack[-3] + stack[-2]) / 2, 1.0))
                del stack[-3:-1]
    out += [(abs(a - b), (a + b) / 2, 0.5) for a, b in zip(stack, stack[1:])]
    return [] if max(x) == min(x) else out


def _as_list(c: Cycles):
    return list(zip(c.ranges.tolist(), c.means.tolist(), c.counts.tolist()))


signals = st.one_of(
    # small integers: plateaus, repeated values and ties between ranges are frequent
    st.lists(st.integers(-4, 4).map(float), min_size=2, max_size=60),
    st.lists(st.floats(-1e6, 1e6, allow_nan=False, allow_subnormal=False), min_size=2, max_size=60),
)


@settings(max_examples=400, deadline=None)
@given(signals)
def test_rainflow_matches_package_and_oracle(x):
    got = _as_list(rainflow(x))
    assert got == _package_cycles(x)
    # the oracle's means use (a+b)/2 instead of 0.5*(a+b): equal in floating point up to rounding
    ref = _oracle(x)
    assert len(got) == len(ref)
    assert_allclose(np.array(got).reshape(-1, 3), np.array(ref).reshape(-1, 3), rtol=1e-15, atol=0)


def test_rainflow_long_noise_matches_package():
    x = np.random.default_rng(7).standard_normal(20_000).round(2)  # rounding makes plateaus and ties
    c = rainflow(x)
    assert _as_list(c) == _package_cycles(x)
    assert set(np.unique(c.counts)) <= {0.5, 1.0}


@pytest.mark.parametrize("x", [[0.0, 1.0], [1.0, 1.0], [3.0] * 10, [0.0, 1.0, 1.0, 1.0]])
def test_short_and_constant_signals(x):
    c = rainflow(x)
    assert _as_list(c) == _package_cycles(x)
    if max(x) == min(x):
        assert len(c) == 0 and del_rainflow(x, 4, 10.0) == 0.0


def test_rainflow_periodic_closes_the_residue_and_is_rotation_invariant():
    rng = np.random.default_rng(3)
    x = rng.standard_normal(501).round(1)
    c = rainflow(x, residue="periodic")
    assert np.all(c.counts == 1.0)
    # A periodic record has no preferred start: every rotation gives the same cycle multiset.
    ref = Counter(zip(c.ranges.tolist(), c.means.tolist()))
    for k in (1, 17, 250, 500):
        ck = rainflow(np.roll(x, k), residue="periodic")
        assert Counter(zip(ck.ranges.tolist(), ck.means.tolist())) == ref
    # Against the package on the record rotated to its maximum and closed there, with its
    # paired half cycles merged into full ones.
    i = int(np.argmax(x))
    closed = np.r_[x[i:], x[:i], x[i]]
    pkg = Counter()
    for r, mu, n, _, _ in rf.extract_cycles(closed):
        pkg[(r, mu)] += n
    assert pkg == Counter({k: float(v) for k, v in ref.items()})


@settings(max_examples=200, deadline=None)
@given(st.lists(st.integers(-4, 4).map(float), min_size=3, max_size=40), st.integers(0, 39))
def test_rainflow_periodic_property(x, k):
    # full cycles only, the same multiset for every rotation, and every range within the record's span
    c = rainflow(x, residue="periodic")
    assert np.all(c.counts == 1.0)
    assert np.all(c.ranges <= max(x) - min(x))
    ck = rainflow(np.roll(x, k % len(x)), residue="periodic")
    assert Counter(zip(ck.ranges.tolist(), ck.means.tolist())) == Counter(zip(c.ranges.tolist(), c.means.tolist()))
    # the largest cycle of a closed record spans the whole record
    if max(x) > min(x):
        assert c.ranges.max() == max(x) - min(x)


# The counter before the one-pass kernel (commit af189e6, specdesign/fatigue.py), kept verbatim
# as the oracle of the rewrite: turning points into an array, then a stack counter on them.
@njit
def _old_reversals(x, out):
    n = x.size
    if n == 0:
        return 0
    out[0] = x[0]
    if n == 1:
        return 1
    k = 1
    xc = x[1]
    d_last = xc - x[0]
    for i in range(2, n):
        xn = x[i]
        if xn == xc:
            continue
        d_next = xn - xc
        out[k] = xc
        k += d_last * d_next < 0
        xc = xn
        d_last = d_next
    if n > 2:
        out[k] = x[n - 1]
        k += 1
    return k


@njit
def _old_count(tp, n_tp, half_rule, ranges, means, counts):
    stack = np.empty(n_tp)
    start = 0
    top = 0
    nc = 0
    for i in range(n_tp):
        stack[top] = tp[i]
        top += 1
        while top - start >= 3:
            x1 = stack[top - 3]
            x2 = stack[top - 2]
            x3 = stack[top - 1]
            if abs(x3 - x2) < abs(x2 - x1):
                break
            ranges[nc] = abs(x1 - x2)
            means[nc] = 0.5 * (x1 + x2)
            if top - start == 3 and half_rule:
                counts[nc] = 0.5
                start += 1
            else:
                counts[nc] = 1.0
                stack[top - 3] = x3
                top -= 2
            nc += 1
    while top - start > 1:
        ranges[nc] = abs(stack[start] - stack[start + 1])
        means[nc] = 0.5 * (stack[start] + stack[start + 1])
        counts[nc] = 0.5
        nc += 1
        start += 1
    return nc


@njit
def _old_rainflow(x, periodic):
    n = x.size
    tp = np.empty(n + 1)
    n_tp = _old_reversals(x, tp)
    if periodic:
        k = 0
        for i in range(1, n_tp):
            if tp[i] > tp[k]:
                k = i
        rot = np.empty(n_tp + 1)
        j = 0
        for i in range(k, n_tp):
            rot[j] = tp[i]
            j += 1
        for i in range(0, k + 1):
            rot[j] = tp[i]
            j += 1
        n_tp = _old_reversals(rot[:j], tp)
    ranges = np.empty(n_tp)
    means = np.empty(n_tp)
    counts = np.empty(n_tp)
    nc = _old_count(tp, n_tp, not periodic, ranges, means, counts)
    return ranges[:nc], means[:nc], counts[:nc]


def _assert_same_as_old(x):
    """Bitwise: the same cycles, in the same order, with the same bits (signed zeros included)."""
    x = np.asarray(x, dtype=float)
    for residue in ("half", "periodic"):
        new = rainflow(x, residue=residue)
        old = _old_rainflow(x, residue == "periodic")
        if x.size == 2 or np.ptp(x) == 0:  # the wrapper's documented special cases, unchanged
            old = tuple(o[:0] for o in old)
        for got, ref in zip((new.ranges, new.means, new.counts), old):
            assert got.dtype == ref.dtype and got.tobytes() == ref.tobytes(), residue


@settings(max_examples=400, deadline=None)
@given(st.one_of(
    signals,
    st.lists(st.sampled_from([0.0, -0.0, 1.0, -1.0, 1e300, -1e300, 5e-324]), min_size=2, max_size=40),
    st.lists(st.floats(-1e3, 1e3, allow_nan=False, width=16).map(float), min_size=2, max_size=300),
))
def test_rainflow_kernel_equals_the_previous_kernel(x):
    _assert_same_as_old(x)


@pytest.mark.parametrize("case", ["noise", "rounded", "growing", "decaying", "monotone", "plateaus", "long_block"])
def test_rainflow_kernel_equals_the_previous_kernel_on_long_edge_signals(case):
    # longer than the kernel's block of 4096 turning points, so the blocks are stitched
    rng = np.random.default_rng(11)
    k = np.arange(20_001, dtype=float)
    x = {
        "noise": rng.standard_normal(20_001),
        "rounded": rng.standard_normal(20_001).round(1),  # plateaus and ties
        "growing": (-1.0) ** k * k,  # every point pops the start: all half cycles
        "decaying": (-1.0) ** k * (20_001 - k),  # the stack grows to every point
        "monotone": k,
        "plateaus": np.repeat(rng.standard_normal(2_000), rng.integers(1, 20, 2_000)),
        "long_block": np.r_[rng.standard_normal(4_095), np.zeros(10), rng.standard_normal(8_193)],
    }[case]
    _assert_same_as_old(x)


def test_rainflow_rejects_bad_input():
    with pytest.raises(ValueError, match="x"):
        rainflow([0.0, np.nan, 1.0])
    with pytest.raises(ValueError, match="1-D"):
        rainflow(np.zeros((3, 3)))
    with pytest.raises(ValueError, match="at least 2"):
        rainflow([1.0])
    with pytest.raises(ValueError, match="residue"):
        rainflow([0.0, 1.0, 0.0], residue="drop")


def test_sine_miner_and_del_closed_form():
    # k full cycles of amplitude A: ranges 2A, Miner D = k (2A/S_ref)^m, DEL = 2A (k/N_eq)^(1/m).
    a, k, m, s_ref, duration = 3.0, 50, 4.0, 1e3, 200.0
    t = np.arange(40 * k) / 40  # exactly k periods, no repeated end point
    x = 5.0 + a * np.sin(2 * np.pi * t)
    c = rainflow(x, residue="periodic")
    assert c.total == pytest.approx(k)
    assert_allclose(c.ranges, 2 * a, rtol=1e-12)
    assert_allclose(c.means, 5.0, rtol=1e-12)
    assert miner_damage(c.ranges, c.counts, SNCurve(m, s_ref)) == pytest.approx(k * (2 * a / s_ref) ** m, rel=1e-12)
    assert del_rainflow(x, m, duration, residue="periodic") == pytest.approx(2 * a * (k / duration) ** (1 / m), rel=1e-12)
    # n_eq_rate scales N_eq: DEL at 0.5 Hz = DEL at 1 Hz × 2^(1/m)
    assert del_rainflow(x, m, duration, 0.5, residue="periodic") == pytest.approx(
        2 * a * (k / (0.5 * duration)) ** (1 / m), rel=1e-12
    )


def test_sn_curve_knee_is_continuous_and_follows_second_slope():
    sn = SNCurve(m=3.0, s_ref=1e4, knee_cycles=1e7, m2=5.0)
    sk = sn.knee_range
    assert sk == pytest.approx(1e4 * 1e7 ** (-1 / 3))
    assert_allclose(sn.cycles_to_failure([sk * (1 + 1e-12), sk * (1 - 1e-12)]), 1e7, rtol=1e-9)
    assert sn.cycles_to_failure(sk / 2) == pytest.approx(1e7 * 2**5)
    assert sn.cycles_to_failure(2 * sk) == pytest.approx(1e7 / 2**3)
    assert sn.cycles_to_failure(0.0) == np.inf
    with pytest.raises(ValueError, match="m2"):
        SNCurve(3.0, knee_cycles=1e7)
    with pytest.raises(ValueError, match="m"):
        SNCurve(-1.0)


def test_miner_validation():
    with pytest.raises(TypeError, match="sn"):
        miner_damage([1.0], [1.0], 4.0)
    with pytest.raises(ValueError, match="same length"):
        miner_damage([1.0, 2.0], [1.0], SNCurve(4))
    with pytest.raises(ValueError, match="ranges"):
        miner_damage([-1.0], [1.0], SNCurve(4))


def test_goodman_correction():
    s = goodman_ranges([2.0, 2.0, 2.0], [0.0, 50.0, -50.0], ultimate=100.0)
    assert_allclose(s, [2.0, 4.0, 4.0])
    with pytest.raises(ValueError, match="ultimate"):
        goodman_ranges([1.0], [100.0], 100.0)
    # del_rainflow with a Goodman correction on a sine with mean M: ranges scale by 1/(1-M/Su)
    t = np.arange(400) / 40
    x = 20.0 + np.sin(2 * np.pi * t)
    plain = del_rainflow(x - 20.0, 4, 10.0, residue="periodic")
    assert del_rainflow(x, 4, 10.0, ultimate=100.0, residue="periodic") == pytest.approx(plain / 0.8, rel=1e-12)


def test_fit_variance_damage_recovers_the_scaling_law():
    # Scaling a record by c multiplies Var by c² and every range by c, so D by c^m:
    # ln D = (m/2) ln Var + b exactly, whatever the record.
    base = np.random.default_rng(0).standard_normal(3000)
    m, su = 4.0, 50.0
    scales = [0.5, 1.0, 2.0, 4.0]
    fit = fit_variance_damage([c * base for c in scales], m, ultimate=su)
    assert fit.a == pytest.approx(m / 2, rel=1e-10)
    c = rainflow(base)
    d1 = np.sum(c.counts * c.ranges**m) / su**m
    assert fit.b == pytest.approx(np.log(su**m * d1) - fit.a * np.log(np.var(base)), rel=1e-9, abs=1e-9)
    assert_allclose(fit.predict(9.0 * np.var(base)), d1 * 3.0**m, rtol=1e-9)
    assert fit.residual_std < 1e-9
    with pytest.raises(ValueError, match="records"):
        fit_variance_damage([base], m)


def test_economic_cost_is_weighted_sum_over_last_axis():
    d = np.random.default_rng(1).uniform(size=(5, 3))
    w = np.array([1.0, 10.0, 0.5])
    j = economic_cost(d, w)
    assert_allclose(j, [sum(wi * di for wi, di in zip(w, row)) for row in d], rtol=1e-14)
    assert economic_cost(d[2], w) == pytest.approx(j[2])
    with pytest.raises(ValueError, match="weights"):
        economic_cost(d, [1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="damages"):
        economic_cost(d, [1.0, 1.0])
