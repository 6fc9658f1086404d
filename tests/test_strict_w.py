"""Issue 28 item 5: one W, read strictly.

The plant cases meet the pair per case, W_i = T^ROSCO_i·W/T^ROSCO (the specification at each
case's own speed); the strict reading, each case against the nominal W the user sees, is
reported beside it (the issue measured the design at 23 m/s 0.47 dB over the nominal W_MyT at
the 24 m/s case, 0.28 rad/s). Checked here: the reported strict excess equals an independent
computation, each case closed with python-control's interconnection on a grid of its own.
"""
from __future__ import annotations

import numpy as np
import pytest

from specdesign import closedloop
from specdesign.feasibility import specification_for_target
from specdesign.qft import design_qft
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def _worst(model, controller, speeds, pairs, w):
    """Largest 20·log10(|T_{out,w}|/|W|) over ``speeds`` for each (output, W) of ``pairs``, dB."""
    out = []
    for name, spec_ in pairs:
        bound = np.abs(spec_.response(w))
        out.append(max(float(np.max(20 * np.log10(np.abs(closedloop.frequency_response(
            closedloop.closed_loop(model.linearize(v), controller, warn=False), w, name, "wind")) / bound)))
            for v in speeds))
    return out


# dense around the tower mode, where a case's ratio to the nominal map is sharpest
W = np.unique(np.r_[np.geomspace(0.005, 20.0, 3000), np.linspace(0.9, 1.4, 20001), 0.28])


@pytest.mark.slow
def test_the_design_reports_how_far_a_case_exceeds_the_nominal_w(model):
    d = design_qft(model, 23.0, 25.0)
    assert d.success
    worst = _worst(model, d.pitch_controller, d.template_speeds,
                   (("tower_base_my", d.tower_spec), ("gen_speed", d.speed_spec)), W)
    # the record's grid is refined around the lightly damped roots, this one is denser elsewhere:
    # between either grid's points (~0.3 % apart) a smooth map moves by < 0.05 dB
    assert worst == pytest.approx(d.options["strict_excess_db"], abs=0.05)


def test_a_target_specification_reports_its_strict_excess(model):
    ts = specification_for_target(model, 19.0, 25.0)
    assert [x[0] for x in ts.strict_excess] == ["W_MyT", "W_Ω"]
    assert all(x[3] in ts.case_speeds for x in ts.strict_excess)
    worst = _worst(model, ts.design.controller(model), ts.case_speeds,
                   (("tower_base_my", ts.tower), ("gen_speed", ts.speed)), W)
    assert worst == pytest.approx([x[1] for x in ts.strict_excess], abs=0.05)
