"""Numerics that never overflow, and real-valued functions that refuse complex input.

Issue "Nothing silently wrong", §3: DEL is homogeneous of degree 1 in the load, so any
Wöhler exponent m ≤ 100 and any load scale must give the right, finite value; ΔD% is a ratio
and must stay finite at m = 50. The expected values come from the same computation on the
unscaled load (the homogeneity DEL(c·x) = c·DEL(x)), not from stored numbers.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specdesign import fatigue, spectral

OMEGA = np.linspace(0.0, 10.0, 401)
# a two-peak (wide-band) spectrum: Dirlik's four terms all matter
PSD = np.exp(-0.5 * ((OMEGA - 1.0) / 0.15) ** 2) + 0.3 * np.exp(-0.5 * ((OMEGA - 5.0) / 0.8) ** 2)
SIGNAL = np.random.default_rng(7).standard_normal(3000).cumsum()
SIGNAL -= np.convolve(SIGNAL, np.ones(50) / 50, mode="same")  # a band-limited, bounded record

scales = st.floats(min_value=-8.0, max_value=12.0).map(lambda e: 10.0**e)
exponents = st.floats(min_value=1.0, max_value=100.0)


@settings(max_examples=60, deadline=None)
@given(c=scales, m=exponents)
def test_rainflow_del_is_homogeneous_of_degree_one(c, m):
    d1 = fatigue.del_rainflow(SIGNAL, m, 600.0)
    dc = fatigue.del_rainflow(c * SIGNAL, m, 600.0)
    assert np.isfinite(dc) and dc > 0
    assert dc == pytest.approx(c * d1, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(c=scales, m=exponents, method=st.sampled_from(["narrowband", "dirlik", "tovo_benasciutti"]))
def test_spectral_del_is_homogeneous_of_degree_one(c, m, method):
    # S → c²·S scales the load by c
    d1 = spectral.del_spectral(OMEGA, PSD, m, method=method)
    dc = spectral.del_spectral(OMEGA, c**2 * PSD, m, method=method)
    assert np.isfinite(dc) and dc > 0
    assert dc == pytest.approx(c * d1, rel=1e-9)


def test_issue_cases_are_finite_and_exact():
    # the three cases the issue names, each against its unit-scale twin
    assert fatigue.del_rainflow(1e8 * SIGNAL, 40.0, 600.0) == pytest.approx(1e8 * fatigue.del_rainflow(SIGNAL, 40.0, 600.0), rel=1e-12)
    big = spectral.del_spectral(OMEGA, 1e14 * PSD, 40.0)
    assert big == pytest.approx(1e7 * spectral.del_spectral(OMEGA, PSD, 40.0), rel=1e-12)
    s50 = spectral.sensitivity(OMEGA, 1e14 * PSD, 50.0)
    assert np.all(np.isfinite(s50))
    np.testing.assert_allclose(s50, spectral.sensitivity(OMEGA, PSD, 50.0), rtol=1e-9, atol=1e-12)
    # analytic (complex-step) variant too
    a50 = spectral.sensitivity(OMEGA, 1e14 * PSD, 50.0, analytic=True)
    np.testing.assert_allclose(a50, spectral.sensitivity(OMEGA, PSD, 50.0, analytic=True), rtol=1e-9, atol=1e-12)


def test_unit_scale_results_are_unchanged_by_the_scaling():
    # at m = 4 and unit loads nothing could overflow: the scaled formula equals the plain one
    # (DEL = (damage rate / 1 Hz)^(1/m) and Σ n S^m computed directly) to round-off
    d = spectral.damage_rate(OMEGA, PSD, 4.0)
    assert spectral.del_spectral(OMEGA, PSD, 4.0) == pytest.approx(d ** 0.25, rel=1e-13)
    c = fatigue.rainflow(SIGNAL)
    assert fatigue.del_rainflow(SIGNAL, 4.0, 600.0) == pytest.approx((np.sum(c.counts * c.ranges**4) / 600.0) ** 0.25, rel=1e-13)


def test_damage_that_float64_cannot_hold_is_an_error_not_inf():
    with pytest.raises(OverflowError, match="del_spectral"):
        spectral.damage_rate(OMEGA, 1e14 * PSD, 50.0)


def test_exact_change_at_a_large_exponent_matches_the_unit_scale():
    small = spectral.exact_change(OMEGA, PSD, 0.8 * PSD, 30.0)
    # a pure scaling 0.8·S reduces the DEL by exactly 1 − √0.8
    assert float(small.del_reduction) == pytest.approx(100 * (1 - np.sqrt(0.8)), rel=1e-10)


@pytest.mark.parametrize("call", [
    lambda: spectral.moments(OMEGA, PSD.astype(complex)),
    lambda: spectral.predicted_change(OMEGA, np.ones_like(OMEGA), (1 + 1j) * np.ones_like(OMEGA), np.ones_like(OMEGA)),
    lambda: fatigue.rainflow(SIGNAL + 0j),
    lambda: spectral.del_spectral(OMEGA.astype(complex), PSD, 4.0),
])
def test_complex_input_is_a_type_error(call):
    with pytest.raises(TypeError, match="complex"):
        call()
