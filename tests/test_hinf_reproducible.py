"""Issue 28 item 4 for the H∞ path: ``design_hinf`` under a 1e-9 m/s change of the wind speed.

Its decisions are taken with documented room: the suboptimal γ on a relative grid
(``loopshaping.hinf.GAMMA_GRID``, tested in tests/test_hinf.py) and the controller's order with
``hinf.ORDER_ROOM_DB`` (here). The multi-model step (``hinf.refine_on_cases``, L-BFGS-B on a
non-convex minimax) is not yet reproducible: its result moves by 20 % with data 1e-7 apart from
the same start (docs/hinf.md), which the strict xfail below records.
"""
from __future__ import annotations

import warnings

import control as ct
import numpy as np
import pytest

from specdesign.closedloop import siso_response
from specdesign.hinf import ORDER_ROOM_DB, CaseCheck, design_hinf
from specdesign.hinf.design import _lowest_order
from specdesign.turbine import iea15mw


class _Design:
    """The one field ``_lowest_order`` reads."""

    def __init__(self, order, excess_db, decay_rate=0.02):
        self.order = order
        self.case_check = CaseCheck(case_speeds=(19.0,), tower_excess_db=(excess_db,), speed_excess_db=(-1.0,),
                                    tower_omega=(1.0,), speed_omega=(1.0,), max_sensitivity=1.5, decay_rate=decay_rate,
                                    omega=np.array([1.0]), hf_excess_db=-1.0, proper=True)


@pytest.mark.parametrize("excess_8, excess_10, kept", [
    (-2 * ORDER_ROOM_DB, -0.3, 8),  # met with room: kept
    (-ORDER_ROOM_DB / 2, -0.3, 10),  # met (excess ≤ 0) without room: passed over for one with room
    (0.1, -0.3, 10),
    (-ORDER_ROOM_DB / 2, 0.5, 8),  # ... unless the highest order misses: then the lower one that met
    (-ORDER_ROOM_DB / 2, -ORDER_ROOM_DB / 2, 8),  # ... or meets without room too: the lowest
    (0.1, 0.5, 10),  # none meets: the highest, said by its warning
])
def test_a_lower_order_is_kept_only_when_it_meets_the_pair_with_room(excess_8, excess_10, kept):
    # 8 states meeting the pair by less than ORDER_ROOM_DB is passed over when 10 meet it with
    # room, so a rounding error that moves its excess across 0 dB cannot change the order
    designs = {8: _Design(8, excess_8), 10: _Design(10, excess_10)}
    assert _lowest_order((8, 10), designs.__getitem__, min_decay=0.01).order == kept


def test_a_lower_order_with_a_marginal_pole_is_passed_over():
    # met (decay > 0) by a pole at −1.5e-15 1/s, as a 10-state design at 21 m/s was: a rounding
    # error from unstable, so not "with room" (min_decay: half the step's decay rate)
    designs = {8: _Design(8, -0.3, decay_rate=1.5e-15), 10: _Design(10, -0.3)}
    assert _lowest_order((8, 10), designs.__getitem__, min_decay=0.01).order == 10


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="the multi-model step (refine_on_cases) is path-dependent: "
                   "19 and 19 + 1e-9 m/s gave predictions 0.053 pp apart (0.069 before the γ grid) "
                   "and controllers 13 % apart (docs/hinf.md)")
def test_a_nudged_wind_speed_gives_the_same_hinf_design():
    model = iea15mw()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a missed pair is said; not what is tested here
        # 10 states, the order chosen at both (8 miss the pair): one multi-model step each
        a, b = design_hinf(model, 19.0, order=10), design_hinf(model, 19.0 + 1e-9, order=10)
    assert b.controller.nstates == a.controller.nstates
    assert abs(b.promised_del_reduction - a.promised_del_reduction) <= 0.01
    assert abs(b.predicted_del_reduction - a.predicted_del_reduction) <= 0.01
    # relative to |C| at each frequency, floored at 1 % of its peak (as tests/test_reproducible.py)
    w = np.geomspace(0.01, 10.0, 400)
    ca, cb = siso_response(ct.ss(a.pitch_controller), w), siso_response(ct.ss(b.pitch_controller), w)
    assert np.max(np.abs(cb - ca) / np.maximum(np.abs(ca), 1e-2 * np.max(np.abs(ca)))) <= 1e-6
