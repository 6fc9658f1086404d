"""Dense-grid check: the QFT Toolbox example's two controllers, stability, margins."""
from __future__ import annotations

import control as ct
import numpy as np
import pytest

from loopshaping import qft
from loopshaping.check import check, feedback_poles
from loopshaping.controller import Controller, complex_pole, gain, real_zero

from test_qft_bounds import G_PROPER, G_PUBLISHED, OMEGAS, W_SENS, manual_cases

s = ct.tf("s")
DENSE = np.logspace(-2, 3, 2000)


@pytest.fixture(scope="module")
def setup():
    cases, nom = manual_cases()
    tmpl = qft.Template.from_systems(cases, OMEGAS, nominal=nom)
    b = qft.intersect(qft.bounds(tmpl, "stability", 1.2),
                      qft.bounds(tmpl, "sensitivity", W_SENS, band=(0, 10)),
                      qft.bounds(tmpl, "input_disturbance", 0.01, band=(0, 10)))
    return tmpl, b


def max_T(G, cases, w):
    """Independent: peak |T| over cases from python-control's feedback."""
    peaks = [np.abs(np.squeeze(ct.frequency_response(ct.feedback(P * G, 1), w).complex)) for P in cases]
    peaks = np.array(peaks)
    c, j = np.unravel_index(peaks.argmax(), peaks.shape)
    return peaks.max(), w[j]


def test_published_controller_passes(setup):
    tmpl, b = setup
    C = Controller((gain(379), real_zero(42), complex_pole(247, 0.5)))
    res = check(tmpl, C, b, DENSE)
    assert res.passed, res.summary()
    assert res.stable.all() and len(res.stable) == 40
    peak, _ = max_T(G_PUBLISHED, tmpl.systems, DENSE)
    w, m, _ = res.worst("stability")
    np.testing.assert_allclose(1.2 * 10 ** (-m / 20), peak, rtol=1e-9)
    assert peak < 1.2
    # Sensitivity is only checked inside its band.
    assert np.all(np.isnan(res.margins_db[1][DENSE > 10]))


def test_proper_variant_fails_between_design_frequencies(setup):
    tmpl, b = setup
    res = check(tmpl, G_PROPER, b, DENSE)
    assert not res.passed
    assert list(res.spec_passed) == [False, True, True]
    w, m, case = res.worst("stability")
    peak, w_peak = max_T(G_PROPER, tmpl.systems, DENSE)
    assert peak == pytest.approx(1.24, abs=0.01)
    assert 1.2 * 10 ** (-m / 20) == pytest.approx(peak, rel=1e-9)
    assert w == pytest.approx(w_peak) and 60 < w < 75
    lo, hi = res.violated_ranges("stability")[0]
    assert lo > 10 and hi < 100  # strictly between design frequencies 10 and 100 rad/s
    assert "FAIL" in res.summary() and "stability" in res.summary()


def test_margins_agree_with_python_control(setup):
    tmpl, _ = setup
    res = check(tmpl, G_PUBLISHED, [qft.Spec("stability", 1.2)], np.logspace(-2, 4, 20000))
    for i in (0, 10, 39):
        gm, pm, *_ = ct.stability_margins(tmpl.systems[i] * G_PUBLISHED)
        assert res.phase_margin_deg[i] == pytest.approx(pm, abs=0.05)
        if np.isfinite(gm):
            assert res.gain_margin_db[i] == pytest.approx(20 * np.log10(gm), abs=0.05)
    # |T| ≤ 1.2 guarantees PM ≥ 2·asin(1/(2·1.2)) and GM ≥ 20·log10(1 + 1/1.2).
    assert res.phase_margin_deg.min() >= np.degrees(2 * np.arcsin(1 / 2.4)) - 0.05
    assert np.all(np.abs(res.gain_margin_db) >= 20 * np.log10(1 + 1 / 1.2) - 0.05)


def test_unstable_cancellation_is_caught():
    P = 1 / (s - 1)
    G = 10 * (s - 1) / (s + 1)
    res = check([P], G, [qft.Spec("sensitivity", 10.0)], np.logspace(-2, 2, 200))
    assert not res.passed and not res.stable[0]
    assert res.max_pole_real[0] == pytest.approx(1.0)
    # Without a cancellation the poles equal python-control's feedback poles.
    P2, G2 = 2 / ((s + 1) * (s + 3)), 5 * (s + 2) / (s + 10)
    want = np.sort_complex(ct.feedback(P2 * G2, 1).poles())
    np.testing.assert_allclose(np.sort_complex(feedback_poles(P2, G2)), want, rtol=1e-9)


def test_bad_input(setup):
    tmpl, b = setup
    with pytest.raises(ValueError, match="improper"):
        check(tmpl, s**3, b, DENSE)
    with pytest.raises(ValueError, match="omega"):
        check(tmpl, G_PUBLISHED, b, DENSE[::-1])
    no_sys = qft.Template.from_responses(tmpl.omega, tmpl.responses)
    with pytest.raises(ValueError, match="systems"):
        check(no_sys, G_PUBLISHED, b, DENSE)
    arr = qft.bounds(tmpl, "stability", np.full(4, 1.2))
    with pytest.raises(ValueError, match="callable"):
        check(tmpl, G_PUBLISHED, arr, DENSE)
    with pytest.raises(TypeError, match="specs"):
        check(tmpl, G_PUBLISHED, [], DENSE)


def test_general_form_reproduces_a_classic_spec(setup):
    tmpl, _ = setup
    P = list(tmpl.systems)
    # |P·G/(1+P·G)| written as (A + B·G)/(C + D·G) with per-case LTI lists.
    general = qft.Spec("general", 1.2, name="T as general", kind_args=dict(A=0.0, B=P, C=1.0, D=P))
    res = check(tmpl, G_PUBLISHED, [qft.Spec("stability", 1.2), general], DENSE)
    np.testing.assert_allclose(res.margins_db[1], res.margins_db[0], rtol=1e-12)
    # The same at the design frequencies, with arrays (n_omega, n_cases) as the wind side builds them.
    Pw = tmpl.responses
    bg = qft.bounds(tmpl, "general", 1.2, A=np.zeros_like(Pw), B=Pw, C=np.ones_like(Pw), D=Pw)
    bs = qft.bounds(tmpl, "stability", 1.2)
    np.testing.assert_allclose(bg.forbidden_db, bs.forbidden_db, atol=1e-9)


def test_tracking_spec_on_the_dense_grid(setup):
    tmpl, _ = setup
    up, low = 1.5 / (s / 5 + 1), 1 / (s / 2 + 1) ** 2
    res = check(tmpl, G_PUBLISHED, [qft.Spec("tracking", None, kind_args=dict(upper=up, lower=low))], DENSE)
    L = np.stack([np.squeeze(ct.frequency_response(P * G_PUBLISHED, DENSE).complex) for P in tmpl.systems], 1)
    T = np.abs(L / (1 + L))
    ratio = np.abs(np.squeeze(ct.frequency_response(up / low, DENSE).complex))
    np.testing.assert_allclose(res.margins_db[0], 20 * np.log10(ratio) - 20 * np.log10(T.max(1) / T.min(1)), atol=1e-9)
