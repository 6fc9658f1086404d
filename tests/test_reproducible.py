"""Issue 28 item 4: the design paths are reproducible under 1e-9 m/s.

The paper's structure (``spec_notch``, Table 3's designs) takes the same decisions (ladder rung,
dense-check rounds, order), promises and predicts the same to 0.01 pp and its controllers agree
to 1e-6 relative at every speed of Table 3. At 15 and 17 m/s they did not (1.7e-6 and 7e-6) until
the notch shaper's SLSQP end was refined to its KKT point (``spec.shape_to_target``): the end
moved the notch's width by 1.7e-7 under the nudge, which the controller tuning amplified.

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

import functools
import warnings
from dataclasses import astuple

import numpy as np
import pytest

from specdesign.closedloop import siso_response
from specdesign.feasibility import shape_whole_band
from specdesign.qft import design_qft, spec_from_certified, spec_notch, three_p_notch
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


#: The paper's structure at each speed of Table 3 and its nudge (Table 3's designs:
#: openfast_table3.py's "atd" structure, on the reduced model here).
NOTCH_CASES = [(15.0, 15.0 - 1e-9), (17.0, 17.0 - 1e-9), (19.0, 19.0 + 1e-9), (21.0, 21.0 - 1e-9),
               (23.0, 23.0 + 1e-9), (25.0, 25.0 - 1e-9)]


@functools.cache
def _notch_pair(v, nudged):
    model = iea15mw()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a rung's miss, said once per design
        return design_qft(model, v, spec=spec_notch(25.0)), design_qft(model, nudged, spec=spec_notch(25.0))


def _relative_response_change(a, b, name):
    # relative to |C| at each frequency, but for the dips of C (below 1 % of its peak): as above
    w = np.geomspace(0.005, 10.0, 800)
    ca, cb = siso_response(getattr(a, name), w), siso_response(getattr(b, name), w)
    return float(np.max(np.abs(cb - ca) / np.maximum(np.abs(ca), 1e-2 * np.max(np.abs(ca)))))


@pytest.mark.slow
@pytest.mark.parametrize("v, nudged", NOTCH_CASES)
def test_a_nudged_wind_speed_takes_the_same_decisions_in_the_paper_structure(v, nudged):
    # before qft.tuner's phase one and KKT refinement: 1.1e-3 relative in the parameters at
    # 23 m/s, and another local optimum on OpenFAST's 25 m/s linearisation (docs/openfast.md)
    a, b = _notch_pair(v, nudged)
    assert a.success and b.success
    assert b.options["speed_relax_db"] == a.options["speed_relax_db"]  # the same rung of the ladder
    assert b.options["refine_rounds"] == a.options["refine_rounds"]  # the same dense-check rounds
    assert b.n_states == a.n_states
    assert abs(b.promise.exact_del - a.promise.exact_del) <= 0.01
    assert abs(b.del_reduction - a.del_reduction) <= 0.01


@pytest.mark.slow
@pytest.mark.parametrize("v, nudged", NOTCH_CASES)
def test_a_nudged_wind_speed_gives_the_same_paper_structure_controllers(v, nudged):
    # issue 28 item 4: responses within 1e-6 relative
    a, b = _notch_pair(v, nudged)
    assert _relative_response_change(a, b, "pitch_controller") <= 1e-6
    assert _relative_response_change(a, b, "atd_controller") <= 1e-6


#: The 3P-notched paper structure (openfast_table3.py's "atd_3p", run in OpenFAST at 17 and 19 m/s):
#: the filter's poles are fixed by the rated rotor speed, so the nudge moves only the plant.
FILTERED_CASES = [(17.0, 17.0 - 1e-9), (19.0, 19.0 + 1e-9)]


@pytest.mark.slow
@pytest.mark.parametrize("v, nudged", FILTERED_CASES)
def test_a_nudged_wind_speed_gives_the_same_3p_notched_design(v, nudged):
    # issue 28 item 4 for design_qft(..., measurement_filter=...): the same decisions, promises
    # within 0.01 pp and responses within 1e-6 relative, as the unfiltered paper structure above
    model = iea15mw()
    f = three_p_notch(model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        a, b = (design_qft(model, u, spec=spec_notch(25.0), measurement_filter=f) for u in (v, nudged))
    assert a.success and b.success
    assert b.options["speed_relax_db"] == a.options["speed_relax_db"]
    assert b.options["refine_rounds"] == a.options["refine_rounds"]
    assert b.n_states == a.n_states
    assert abs(b.promise.exact_del - a.promise.exact_del) <= 0.01
    assert abs(b.del_reduction - a.del_reduction) <= 0.01
    assert _relative_response_change(a, b, "pitch_controller") <= 1e-6
    assert _relative_response_change(a, b, "atd_controller") <= 1e-6


def test_the_benchmark_prints_what_these_tests_assert(benchmark_script):
    # benchmarks/reproducible.py prints the values docs/qft_turbine.md quotes: the same nudges as
    # NOTCH_CASES and the same response measure as _relative_response_change (checked on two
    # controllers with a dip, where the floor matters: a notch and the same notch moved by 1e-3)
    import control as ct

    bench = benchmark_script("reproducible")
    assert sorted((v, v + dv) for v, dv in bench.NUDGE.items()) == sorted(NOTCH_CASES)

    def notch(w0):
        return ct.tf([1, 0.002 * w0, w0**2], [1, 0.5 * w0, w0**2]) * ct.tf([1, 0.1], [1, 0])

    a, b = (type("D", (), {"pitch_controller": notch(w)})() for w in (0.8, 0.8 * (1 + 1e-3)))
    want = _relative_response_change(a, b, "pitch_controller")
    assert bench.response_change(a.pitch_controller, b.pitch_controller) == pytest.approx(want, rel=1e-12)
    assert bench.response_change(ct.tf([0], [1]), ct.tf([0], [1])) == 0.0
