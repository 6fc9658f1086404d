"""Issue 28 item 5: one W, read strictly.

The default design must keep every plant case under the nominal W_MyT the user sees (the
specification its promise is of), not only under the per-case W_i = T^ROSCO_i·W/T^ROSCO (the
issue measured the design at 23 m/s 0.47 dB over the nominal W_MyT at the 24 m/s case,
0.28 rad/s); W_Ω is read per case
(ROSCO's own speed map at each case) and its strict excess reported. Checked independently:
each case closed with python-control's interconnection on a grid of its own.
"""
from __future__ import annotations

import numpy as np
import pytest

from specdesign import closedloop
from specdesign.qft import design_qft
from specdesign.turbine import iea15mw


@pytest.mark.slow
def test_every_plant_case_meets_the_nominal_w_itself():
    model = iea15mw()
    d = design_qft(model, 23.0, 25.0)
    assert d.success
    # dense around the tower mode, where a case's ratio to the nominal map is sharpest
    w = np.unique(np.r_[np.geomspace(0.005, 20.0, 3000), np.linspace(0.9, 1.4, 20001), 0.28])
    w_tower = np.abs(d.tower_spec.response(w))
    w_speed = np.abs(d.speed_spec.response(w))
    worst = []
    for v in d.template_speeds:
        cl = closedloop.closed_loop(model.linearize(v), d.pitch_controller, warn=False)
        t = np.abs(closedloop.frequency_response(cl, w, "tower_base_my", "wind"))
        s = np.abs(closedloop.frequency_response(cl, w, "gen_speed", "wind"))
        worst.append((np.max(20 * np.log10(t / w_tower)), np.max(20 * np.log10(s / w_speed))))
    worst = np.max(worst, axis=0)
    # the order was chosen on the refined dense grid with a 0.01 dB margin; between that grid's
    # points a smooth map moves by far less than the margin
    assert worst[0] <= 0.0, worst
    recorded = d.options["strict_excess_db"]
    assert recorded[0] <= -0.01
    assert worst == pytest.approx(recorded, abs=0.05)


def test_a_target_specification_reports_its_strict_excess():
    from specdesign.feasibility import specification_for_target

    model = iea15mw()
    ts = specification_for_target(model, 19.0, 25.0)
    assert [x[0] for x in ts.strict_excess] == ["W_MyT", "W_Ω"]
    cert = ts.design.controller(model)
    # dense around the tower mode, where a case's ratio to the nominal map is sharpest
    w = np.unique(np.r_[np.geomspace(0.005, 20.0, 3000), np.linspace(0.9, 1.4, 20001)])
    for (label, excess, _, case), (out, spec_) in zip(ts.strict_excess, (("tower_base_my", ts.tower),
                                                                          ("gen_speed", ts.speed))):
        assert case in ts.case_speeds
        mine = max(float(np.max(20 * np.log10(np.abs(closedloop.frequency_response(
            closedloop.closed_loop(model.linearize(v), cert, warn=False), w, out, "wind"))
            / np.abs(spec_.response(w))))) for v in ts.case_speeds)
        # the record's grid is refined around the lightly damped roots, this one is denser
        # elsewhere: between either grid's points (~0.3 % apart) a smooth map moves by < 0.05 dB
        assert abs(mine - excess) <= 0.05, label
