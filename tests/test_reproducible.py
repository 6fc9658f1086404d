"""Issue 28 item 4: the default (transfer-function) design path is reproducible under 1e-9 m/s
(the paper's structure, `spec_notch`, is not yet: a strict xfail, last).

At 17 and 17 − 1e-9 m/s, and at 23 and 23 + 1e-9 m/s (the two cases the issue measured: the
promise moved by 7.9 pp and the controller order by 7 states), ``design_qft(model, v, 25.0)``
must give the same controller order, promise and prediction within 0.01 pp, and pitch
controllers whose responses agree to 1e-6 relative. What a 1e-9 m/s step may legitimately
change is ~1e-9 relative (the plant is smooth in the wind speed); the interior-point solver's
path amplifies it to ~1e-8-1e-7 relative, which sets the tolerance's margin.

The element path (``feasibility.shape_whole_band`` then ``design_qft`` on its certified pair)
is held to the same at 15 − 1e-9 and 19 + 1e-9 m/s here and at 25 − 1e-9 m/s in
tests/test_shape_whole_band.py: its envelope fit runs on rounded inputs
(``feasibility.elements.FIT_INPUT_DB``), so the elements are the same, and the certificate for
them keeps ``feasibility.target.TOWER_ROOM_DB`` below them, so the design step's order is not
decided by a hair.
"""
from __future__ import annotations

import warnings
from dataclasses import astuple

import numpy as np
import pytest

from specdesign.closedloop import siso_response
from specdesign.feasibility import shape_whole_band
from specdesign.qft import design_qft, spec_from_certified, spec_notch
from specdesign.spec import baseline_analysis
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.mark.slow
@pytest.mark.parametrize("v, nudged", [(17.0, 17.0 - 1e-9), (23.0, 23.0 + 1e-9)])
def test_a_nudged_wind_speed_gives_the_same_design(model, v, nudged):
    # the default design: 25 % under the measured high-frequency gain bound, the plant cases'
    # margin shaped (a converged fit of its bumps: a continuous function of the wind speed)
    a, b = design_qft(model, v, 25.0), design_qft(model, nudged, 25.0)
    assert a.success and b.success
    assert b.parameters["order"] == a.parameters["order"]
    assert abs(b.promise.exact_del - a.promise.exact_del) <= 0.01
    assert abs(b.del_reduction - a.del_reduction) <= 0.01
    assert b.options["speed_relax_db"] == pytest.approx(a.options["speed_relax_db"], abs=1e-6)
    # over the control band and 3P up to 10 rad/s, relative to |C| at each frequency except
    # within the dips of C (|C| < 1 % of its peak), where the ratio measures how well a dip's depth
    # is conditioned rather than the controller; there the error is bounded relative to the peak
    w = np.geomspace(0.005, 10.0, 800)
    ca, cb = siso_response(a.pitch_controller, w), siso_response(b.pitch_controller, w)
    floor = 1e-2 * np.max(np.abs(ca))
    assert np.max(np.abs(cb - ca) / np.maximum(np.abs(ca), floor)) <= 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("v, nudged", [(15.0, 15.0 - 1e-9), (19.0, 19.0 + 1e-9)])
def test_a_nudged_wind_speed_gives_the_same_element_specification_and_design(model, v, nudged):
    # the element path with the default options (the high-frequency gain bound on): measured
    # before the fix at 25 m/s, 5 notches at v and 4 at v − 1e-9, predictions 0.49 pp apart
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy accuracy notes on some rungs
        a, b = (shape_whole_band(baseline_analysis(model, x), 25.0).certified for x in (v, nudged))
    # the same elements: their types and, but for the settled gain (elements[0], which follows the
    # promise's continuous change), their values to rounding
    assert [type(e) for e in b.tower.elements] == [type(e) for e in a.tower.elements]
    for ea, eb in zip(a.tower.elements[1:], b.tower.elements[1:]):
        assert np.allclose(astuple(eb), astuple(ea), rtol=1e-9, atol=0.0), (ea, eb)
    assert abs(b.promise.exact_del - a.promise.exact_del) <= 0.01
    assert b.speed_relax_db == pytest.approx(a.speed_relax_db, abs=1e-6)
    da, db = (design_qft(model, x, spec=spec_from_certified(t)) for x, t in ((v, a), (nudged, b)))
    assert da.success and db.success
    assert db.parameters["order"] == da.parameters["order"]
    assert abs(db.del_reduction - da.del_reduction) <= 0.01


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="the paper's structure (spec_notch, fixed PI + notch + low-pass and ATD) is tuned "
                   "by searches that decide by a hair: under 23 − 1e-9 m/s its parameters moved by 1.1e-3 relative on "
                   "the reduced model, and on OpenFAST's 25 m/s linearisation the tuning returned another design "
                   "(tower-mode ζ 0.112 vs 0.124; docs/openfast.md)")
def test_a_nudged_wind_speed_gives_the_same_paper_structure_design(model):
    # what Table 3's designs (openfast_table3.py's "atd" structure) must meet, as the default path does
    a, b = (design_qft(model, x, spec=spec_notch(25.0)) for x in (23.0, 23.0 - 1e-9))
    assert a.success and b.success
    assert abs(b.del_reduction - a.del_reduction) <= 0.01
    for key, value in a.parameters.items():
        assert b.parameters[key] == pytest.approx(value, rel=1e-6), key
