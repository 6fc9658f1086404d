"""Issue 28 item 3: the promise is computed on a converged band.

The spectral figures count the variance about each 10-minute record's mean
(:func:`specdesign.wind.record_window`) on :func:`specdesign.spec.default_omega` (0.001-10 rad/s).
The issue's acceptance: halving the lowest frequency, or doubling the grid density, moves the
promise of the target specification by ≤ 0.05 pp at 15 and 19 m/s (it moved 1.2 and 0.2 pp
between 0.01 and 0.005 rad/s on the bare spectrum).
"""
from __future__ import annotations

import warnings

import control as ct
import numpy as np
import pytest

from specdesign import spec, validate, wind
from specdesign.feasibility import specification_for_target
from specdesign.rosco import rosco_baseline
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def test_the_record_window_is_the_variance_about_a_records_mean():
    # independent: the variance of x(t) = cos(ωt + φ) about its mean over [0, T], averaged over
    # φ, is ½(1 − sinc²(ωT/2)); sampled here by quadrature over t and φ
    T = 600.0
    t = np.linspace(0.0, T, 4001)
    phi = np.linspace(0.0, 2 * np.pi, 64, endpoint=False)
    for w in (0.002, 0.0105, 0.03):
        x = np.cos(w * t[None, :] + phi[:, None])
        var = np.mean(np.trapezoid(x ** 2, t, axis=1) / T - (np.trapezoid(x, t, axis=1) / T) ** 2)
        assert 2 * var == pytest.approx(float(wind.record_window(w, T)), abs=1e-5)
    with pytest.raises(ValueError, match="record_length"):
        wind.record_window(0.1, 0.0)


@pytest.mark.slow
@pytest.mark.parametrize("v", [15.0, 19.0])
def test_the_promise_is_converged_in_the_band_and_the_grid(model, v):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy: "solution may be inaccurate" on some rungs
        # the 25 % pair of before the high-frequency gain bound (refused under its default κ:
        # docs/feasibility.md); the band's convergence is the same question
        target = specification_for_target(model, v, 25.0, max_hf_gain_ratio=None)
    w = spec.default_omega()
    assert w[0] == wind.LOWEST_OMEGA
    promise = target.promise.exact_del
    assert promise >= 25.0
    per_decade = (w.size - 1) / np.log10(w[-1] / w[0])
    half_lo = np.geomspace(w[0] / 2, w[-1], int(round(per_decade * np.log10(2 * w[-1] / w[0]))) + 1)
    dense = np.geomspace(w[0], w[-1], 2 * w.size - 1)
    for grid in (half_lo, dense):
        other = spec.promise_of(target.tower, spec.baseline_analysis(model, v, omega=grid)).exact_del
        assert abs(other - promise) <= 0.05


@pytest.mark.parametrize("v", [15.0, 19.0])
def test_the_linear_prediction_is_converged_on_the_promises_band(model, v):
    # The prediction of Table 3's linear row counts the same record as the promise (S_W weighted
    # by record_window, from a tenth of the record's fundamental): halving its lowest frequency or
    # doubling its density moves the predicted DEL reduction by ≤ 0.05 pp (the acceptance
    # for the promise, applied to the prediction it is compared with). ROSCO's PI and the same PI
    # with twice the gain stand in for a baseline and a design.
    base = rosco_baseline(model, v)
    design = ct.tf(base) * 2.0
    w = validate.prediction_grid()
    assert w[0] == wind.LOWEST_OMEGA

    def reduction(grid):
        d0 = validate.linear_prediction(model, base, v, omega=grid).del_
        return 100.0 * (1.0 - validate.linear_prediction(model, design, v, omega=grid).del_ / d0)

    ref = reduction(w)
    assert abs(ref) > 1.0  # the two controllers differ: the check below can fail
    for grid in (np.geomspace(w[0] / 2, w[-1], w.size + 300), np.geomspace(w[0], w[-1], 2 * w.size - 1)):
        assert abs(reduction(grid) - ref) <= 0.05
    # a longer record's band starts lower, in proportion (a tenth of its fundamental)
    assert validate.prediction_grid(1200.0)[0] == pytest.approx(wind.LOWEST_OMEGA / 2)
