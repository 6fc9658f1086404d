"""The cvxpy shaper on the 19 m/s wind-turbine pitch loop (issue 5: "the automatic shaper
finds a controller for both").

The pitch loop of ``design_qft`` at 19 m/s (ATD closed, the design's own template and specs)
is re-shaped by ``loopshaping.auto.refine`` with the designed controller's poles fixed: it
must meet every bound at the design frequencies (the design's and the ones refine added),
pass the dense check over every plant case, keep every closed loop stable in the full
interconnection, and be proper. ``refine`` is generic; the turbine is only the user here.
"""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from loopshaping import auto
from loopshaping.check import check
from specdesign import closedloop, qft, turbine, wind


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


@pytest.fixture(scope="module")
def design(model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return qft.design_qft(model, 19.0, spec=qft.spec_notch())


@pytest.fixture(scope="module")
def shaped(design):
    poles = np.roots(design.pitch_controller.den[0][0])
    return auto.refine(design.pitch_template, design.pitch_bounds, design.dense_omega, poles, n_zeros=3,
                       initial=design.pitch_controller, margin_db=0.01)


def _met(bounds, template, controller):
    L0 = template.nominal_response * controller.response(template.omega)
    return bounds.is_allowed(template.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))


def test_auto_shaped_pitch_controller_meets_every_bound_at_the_design_frequencies(design, shaped):
    ok = _met(design.pitch_bounds, design.pitch_template, shaped.controller)
    assert ok.all(), design.pitch_template.omega[~ok]
    ok = _met(shaped.bounds, shaped.template, shaped.controller)  # with the added frequencies
    assert ok.all(), shaped.template.omega[~ok]
    assert set(design.design_omega) <= set(shaped.template.omega)


def test_auto_shaped_pitch_controller_passes_the_dense_check(design, shaped):
    assert shaped.passed, shaped.check.summary()
    # independently of refine's own check, on the design's dense grid and specs
    res = check(design.pitch_template, shaped.controller, design.pitch_bounds, design.dense_omega)
    assert res.passed, res.summary()
    assert res.stable.all()
    assert set(res.names) == {"speed", "tower", "margin", "actuator_margin"}


def test_every_case_is_stable_with_the_atd_closed(model, design, shaped):
    g = shaped.controller.tf()
    for v in design.template_speeds:
        cl = closedloop.closed_loop(model.linearize(v), g, design.atd_controller, warn=False)
        assert np.max(cl.poles().real) < 0, v


def test_auto_shaped_pitch_controller_is_proper_with_the_designed_poles(design, shaped):
    num, den = shaped.controller.polys()
    assert len(np.trim_zeros(num, "f")) <= len(np.trim_zeros(den, "f"))
    np.testing.assert_allclose(np.sort_complex(np.roots(den)), np.sort_complex(np.roots(design.pitch_controller.den[0][0])),
                               rtol=1e-8, atol=1e-10)


def test_auto_shaped_controller_reduces_tower_fatigue(model, design, shaped):
    # Fatigue-blind objective (least high-frequency gain): it still reduces the tower-base DEL
    # through the tower spec's bounds, but less than design_qft's 25 % target. "Reduces" is read
    # as more than 1 pp, twenty times the linear prediction's grid convergence (0.05 pp,
    # tests/test_spectral_band.py); the size is not a property of the method (9.6 % under the
    # default high-frequency bound, more without it).
    cl = closedloop.closed_loop(model.linearize(19.0), shaped.controller.tf(), design.atd_controller, warn=False)
    w = design.baseline.omega
    # variance about each 600 s record's mean (wind.record_window), written out: 1 − sinc²(ωT/2)
    s_w = wind.rotor_effective_spectrum(w, 19.0, model.rotor_radius) * (1 - (np.sin(300.0 * w) / (300.0 * w)) ** 2)
    red = 100 * (1 - closedloop.closed_loop_del(cl, w, s_w, 4.0) / design.baseline.del_1hz)
    assert 1.0 < red <= design.del_reduction + 1.0
