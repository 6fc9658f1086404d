"""Numerics that never overflow, and real-valued functions that refuse complex input.

Issue "Nothing silently wrong": DEL is homogeneous of degree 1 in the load, so any Wöhler
exponent m ≤ 100 and any load scale must give the right, finite value; ΔD% is a ratio and must
stay finite at m = 50; a damage float64 cannot hold is an OverflowError, never inf or 0.

Where the expected numbers come from (each test says which):
- homogeneity, DEL(c·x) = c·DEL(x) and DEL(c²·S) = c·DEL(S), against the unit-scale value
  (which never overflowed, and which test_spectral / test_fatigue check against FLife,
  rainflow and closed forms);
- independent references that cannot overflow: Decimal arithmetic (50 digits) for Σ n S^m,
  the narrow-band closed form in logarithms (math.lgamma), and FLife at unit scale.

(The documentation of both modules, numpydoc docstrings and examples that run, is checked
with every other module's in tests/test_docstrings.py.)
"""
from __future__ import annotations

import math
import warnings
from decimal import Decimal, localcontext

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
METHODS = ["narrowband", "dirlik", "tovo_benasciutti"]

scales = st.floats(min_value=-8.0, max_value=12.0).map(lambda e: 10.0**e)
exponents = st.floats(min_value=1.0, max_value=100.0)


# --- DEL(c·x) = c·DEL(x) --------------------------------------------------------------------
@settings(max_examples=60, deadline=None)
@given(c=scales, m=exponents)
def test_rainflow_del_is_homogeneous_of_degree_one(c, m):
    d1 = fatigue.del_rainflow(SIGNAL, m, 600.0)
    dc = fatigue.del_rainflow(c * SIGNAL, m, 600.0)
    assert np.isfinite(dc) and dc > 0
    assert dc == pytest.approx(c * d1, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(c=scales, m=exponents, method=st.sampled_from(METHODS))
def test_spectral_del_is_homogeneous_of_degree_one(c, m, method):
    # S → c²·S scales the load by c
    d1 = spectral.del_spectral(OMEGA, PSD, m, method=method)
    dc = spectral.del_spectral(OMEGA, c**2 * PSD, m, method=method)
    assert np.isfinite(dc) and dc > 0
    assert dc == pytest.approx(c * d1, rel=1e-9)


@pytest.mark.parametrize("c", [1e-8, 1e12])
@pytest.mark.parametrize("method", METHODS)
def test_spectral_del_at_the_corners(c, method):
    # the extreme corners of the range the issue asks for, m = 100 at both ends of the scale,
    # on a stack (one call, two spectra): against the unit-scale value
    d1 = spectral.del_spectral(OMEGA, PSD, 100.0, method=method)
    dc = spectral.del_spectral(OMEGA, np.stack([c**2 * PSD, PSD]), 100.0, method=method)
    np.testing.assert_allclose(dc, [c * d1, d1], rtol=1e-12)


# --- the three cases ------------------------------------------------------------------
def test_rainflow_del_m40_loads_1e8_against_decimal_arithmetic():
    x = 1e8 * SIGNAL
    cyc = fatigue.rainflow(x)
    # expected: DEL = (Σ n S^40 / 600)^(1/40) in 50-digit Decimal arithmetic, which has no
    # overflow (Σ n S^40 ~ 1e370 here); the same cycles, so only the arithmetic differs
    with localcontext() as ctx:
        ctx.prec = 50
        total = sum(Decimal(float(n)) * Decimal(float(s)) ** 40 for n, s in zip(cyc.counts, cyc.ranges))
        expected = float((total / 600) ** (Decimal(1) / 40))
    assert total > Decimal("1e308")  # the plain float64 sum would have been inf
    assert fatigue.del_rainflow(x, 40.0, 600.0) == pytest.approx(expected, rel=1e-12)
    # and homogeneity against the unit-scale record
    assert fatigue.del_rainflow(x, 40.0, 600.0) == pytest.approx(1e8 * fatigue.del_rainflow(SIGNAL, 40.0, 600.0), rel=1e-12)


def test_spectral_del_m40_psd_1e14_against_closed_form_and_flife():
    big = 1e14 * PSD
    # narrow band, expected from the closed form in logarithms (no power of a load is formed):
    # DEL = 2√(2 m0) · (ν0 Γ(1 + m/2))^(1/m), ν0 = √(m2/m0)/(2π), moments by the trapezoid rule
    m0, m2 = np.trapezoid(big, OMEGA), np.trapezoid(OMEGA**2 * big, OMEGA)
    nu0 = math.sqrt(m2 / m0) / (2 * math.pi)
    expected_nb = 2 * math.sqrt(2 * m0) * math.exp((math.log(nu0) + math.lgamma(21.0)) / 40)
    assert spectral.del_spectral(OMEGA, big, 40.0, method="narrowband") == pytest.approx(expected_nb, rel=1e-12)
    # Dirlik, expected from FLife at unit scale times the load scale 1e7 (FLife itself
    # overflows at 1e14·S: its damage is ~1e330); FLife's units: PSD per Hz, amplitude S-N
    # curve with C = 2^-m (see tests/test_spectral.py::flife_damage_rate)
    FLife = pytest.importorskip("FLife")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sd = FLife.SpectralData(input={"PSD": 2 * np.pi * PSD, "f": OMEGA / (2 * np.pi)})
        rate = 1.0 / FLife.Dirlik(sd).get_life(2.0**-40, 40.0)
    big_del = spectral.del_spectral(OMEGA, big, 40.0)
    assert np.isfinite(big_del)
    assert big_del == pytest.approx(1e7 * rate ** (1 / 40), rel=1e-10)


@pytest.mark.parametrize("analytic", [False, True])
def test_sensitivity_m50_is_finite_and_scale_free(analytic):
    # ΔD% is a ratio, so the 1e14·S curve equals the unit-scale one (at unit scale the damage
    # is ~1e70, no overflow; test_spectral checks that curve against naive loops and FLife)
    s50 = spectral.sensitivity(OMEGA, 1e14 * PSD, 50.0, analytic=analytic)
    assert np.all(np.isfinite(s50)) and np.max(s50) > 0
    np.testing.assert_allclose(s50, spectral.sensitivity(OMEGA, PSD, 50.0, analytic=analytic), rtol=1e-9, atol=1e-12)


def test_unit_scale_results_are_unchanged_by_the_scaling():
    # at m = 4 and unit loads nothing could overflow: the scaled formula equals the plain one
    # (DEL = (damage rate / 1 Hz)^(1/m) and Σ n S^m computed directly) to round-off
    d = spectral.damage_rate(OMEGA, PSD, 4.0)
    assert spectral.del_spectral(OMEGA, PSD, 4.0) == pytest.approx(d ** 0.25, rel=1e-13)
    c = fatigue.rainflow(SIGNAL)
    assert fatigue.del_rainflow(SIGNAL, 4.0, 600.0) == pytest.approx((np.sum(c.counts * c.ranges**4) / 600.0) ** 0.25, rel=1e-13)
    assert fatigue.miner_damage(c.ranges, c.counts, fatigue.SNCurve(4.0, 50.0)) == pytest.approx(
        np.sum(c.counts / (50.0 / c.ranges) ** 4), rel=1e-13)


# --- ratios at any scale, damages that float64 cannot hold --------------------------------------
def test_exact_change_is_exact_at_any_scale():
    # a pure scaling 0.8·S multiplies every range by √0.8: D by 0.8^(m/2), the DEL by √0.8
    for scale in (1.0, 1e14, 1e-14):
        ch = spectral.exact_change(OMEGA, scale * PSD, scale * 0.8 * PSD, 50.0)
        assert float(ch.damage_reduction) == pytest.approx(100 * (1 - 0.8**25), rel=1e-12)
        assert float(ch.del_reduction) == pytest.approx(100 * (1 - np.sqrt(0.8)), rel=1e-12)
    # the damages themselves are formed only when read, and 1e14·S at m = 50 does not fit
    with pytest.raises(OverflowError, match="damage rate at m=50"):
        spectral.exact_change(OMEGA, 1e14 * PSD, 0.8e14 * PSD, 50.0).damage_before
    unit = spectral.exact_change(OMEGA, PSD, 0.8 * PSD, 4.0)
    assert unit.damage_before == pytest.approx(spectral.damage_rate(OMEGA, PSD, 4.0), rel=1e-13)
    assert unit.damage_after == pytest.approx(spectral.damage_rate(OMEGA, 0.8 * PSD, 4.0), rel=1e-13)


def test_damage_rate_out_of_float64_range_is_an_error_not_inf_or_zero():
    # √m0 ~ 1e7 at m = 50: ~1e350 (overflow); √m0 ~ 1e-7 at m = 50: ~1e-350 (underflow to 0)
    with pytest.raises(OverflowError, match="exceeds .*del_spectral"):
        spectral.damage_rate(OMEGA, 1e14 * PSD, 50.0)
    with pytest.raises(OverflowError, match="underflows .*del_spectral"):
        spectral.damage_rate(OMEGA, 1e-14 * PSD, 50.0)
    with pytest.raises(OverflowError, match="m=50"):
        spectral.spectral_stats(OMEGA, 1e14 * PSD).damage_rate(50.0)
    # an all-zero spectrum has a true zero damage: no error
    assert spectral.damage_rate(OMEGA, np.zeros_like(PSD), 50.0) == 0.0


def test_time_domain_damage_out_of_range_is_an_error_and_the_fit_works_in_logs():
    c = fatigue.rainflow(1e8 * SIGNAL)
    with pytest.raises(OverflowError, match="Miner damage.*del_rainflow"):
        fatigue.miner_damage(c.ranges, c.counts, fatigue.SNCurve(40.0))
    with pytest.raises(OverflowError, match="underflows"):
        fatigue.miner_damage(c.ranges, c.counts, fatigue.SNCurve(40.0, s_ref=1e20))
    # with S_ref at the load's scale the same damage is ordinary
    assert np.isfinite(fatigue.miner_damage(c.ranges, c.counts, fatigue.SNCurve(40.0, s_ref=1e10)))
    # the variance-damage fit on 1e8-scaled records at m = 40 with ultimate = 1e8 is the
    # unit-scale fit (Σ n (cS/c)^m is unchanged, Var scales by c²): same slope, and the same
    # prediction at c²·Var; L_ult^m = 1e320 alone would have overflowed
    base = np.random.default_rng(0).standard_normal(2000)
    recs = [k * base for k in (0.5, 1.0, 2.0)]
    unit = fatigue.fit_variance_damage(recs, 40.0, ultimate=1.0)
    big = fatigue.fit_variance_damage([1e8 * r for r in recs], 40.0, ultimate=1e8)
    assert big.a == pytest.approx(unit.a, rel=1e-12) and unit.a == pytest.approx(20.0, rel=1e-10)
    v = np.var(base)
    assert big.predict(1e16 * v) == pytest.approx(unit.predict(v), rel=1e-9)
    with pytest.raises(OverflowError, match="predicted damage"):
        big.predict(1e40 * v)


def test_an_exponent_beyond_float64_at_unit_variance_is_an_error():
    # Dirlik's Γ(1 + m) overflows above m ≈ 171 whatever the scale; the narrow-band fallback
    # for Dirlik's 0/0 near a single line must not quietly stand in for it
    with pytest.raises(OverflowError, match="m=200 is too large"):
        spectral.del_spectral(OMEGA, PSD, 200.0)


def test_a_method_outside_its_validity_is_an_error_not_nan():
    # Zhao-Baker's Rayleigh weight (1 − w) is negative on a very wide-band spectrum (here a
    # low-frequency peak and a faint high-frequency plateau, α2 ≈ 0.08): its damage is negative
    # already at m = 4 (FLife's ZhaoBaker "method 1" returns a life of −4.7 s for it) and the DEL
    # would be NaN
    wide = np.exp(-(((OMEGA - 0.3) / 0.1) ** 2)) + 1e-4 * (OMEGA > 5.0)
    for m in (4.0, 40.0):
        with pytest.raises(ValueError, match="zhao_baker.*dirlik"):
            spectral.del_spectral(OMEGA, wide, m, method="zhao_baker")
        assert np.isfinite(spectral.del_spectral(OMEGA, wide, m, method="dirlik"))


# --- complex input ---------------------------------------------------------------------------------
ONES = np.ones_like(OMEGA)


@pytest.mark.parametrize("name, call", [
    ("psd", lambda: spectral.moments(OMEGA, PSD.astype(complex))),
    ("omega", lambda: spectral.moments(OMEGA.astype(complex), PSD)),
    ("orders", lambda: spectral.moments(OMEGA, PSD, orders=[0, 2 + 1j])),
    ("t_mag2", lambda: spectral.predicted_change(OMEGA, ONES, (1 + 1j) * ONES, ONES)),
    ("w_mag2", lambda: spectral.predicted_change(OMEGA, ONES, ONES, (1 + 1j) * ONES)),
    ("sensitivity", lambda: spectral.predicted_change(OMEGA, ONES + 0j, ONES, ONES)),
    ("x", lambda: fatigue.rainflow(SIGNAL + 0j)),
    ("x", lambda: fatigue.del_rainflow(SIGNAL + 0j, 4.0, 600.0)),
    ("omega", lambda: spectral.del_spectral(OMEGA.astype(complex), PSD, 4.0)),
    ("psd", lambda: spectral.damage_rate(OMEGA, PSD + 0j, 4.0)),
    ("ranges", lambda: fatigue.miner_damage([1.0 + 0j], [1.0], fatigue.SNCurve(4.0))),
    ("ranges", lambda: spectral.dirlik_range_pdf(OMEGA, PSD, [1.0 + 1j])),
])
def test_complex_input_is_a_type_error_naming_the_argument(name, call):
    # even a zero imaginary part: the caller probably passed T where |T|² belongs
    with pytest.raises(TypeError, match=f"^{name} is complex"):
        call()
