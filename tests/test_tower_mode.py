"""The tower mode's pole and damping ratio in a loop (specdesign.closedloop.modes), and the designs'
warning when a design leaves it much less damped than ROSCO."""
import warnings

import control
import numpy as np
import pytest

from specdesign import closedloop, rosco, spec, turbine
from specdesign.closedloop import modes


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


def _two_modes(zeta_a, wa, ga, zeta_b, wb, gb):
    """wind → tower_base_my through two second-order modes in parallel (hand-made: their
    resonances ga/(2ζ_a) and gb/(2ζ_b) pick the 'tower' one)."""
    def mode(z, w, g):
        return control.tf([g * w ** 2], [1.0, 2 * z * w, w ** 2])
    s = control.ss(mode(zeta_a, wa, ga) + mode(zeta_b, wb, gb))
    return control.ss(s.A, s.B, s.C, s.D, inputs="wind", outputs="tower_base_my")


def test_tower_pole_is_the_highest_resonance_not_the_least_damped():
    # a 7 rad/s mode at 0.7 % damping with a residue 1e-4 of the 1.1 rad/s one at 12 %
    # (OpenFAST's monopile foundation mode beside the tower's): resonance 1/(2·0.12) = 4.2
    # against 1e-4/(2·0.007) = 0.007, so the tower's is picked
    sys = _two_modes(0.12, 1.1, 1.0, 0.007, 7.0, 1e-4)
    p = closedloop.tower_pole(sys)
    assert abs(p) == pytest.approx(1.1, rel=1e-9)
    assert -p.real / abs(p) == pytest.approx(0.12, rel=1e-9)
    # restricted to near 7 rad/s, the other one
    assert abs(closedloop.tower_pole(sys, near=7.0)) == pytest.approx(7.0, rel=1e-9)


def test_tower_pole_refuses_bad_input():
    sys = _two_modes(0.12, 1.1, 1.0, 0.007, 7.0, 1e-4)
    with pytest.raises(ValueError, match="near"):
        closedloop.tower_pole(sys, near=-1.0)
    with pytest.raises(ValueError, match="no oscillatory pole within"):
        closedloop.tower_pole(sys, near=30.0)
    with pytest.raises(ValueError, match="input='pitch_cmd'"):
        closedloop.tower_pole(sys, input="pitch_cmd")
    first = control.ss(control.tf([1.0], [1.0, 1.0]))
    with pytest.raises(ValueError, match="no oscillatory pole"):
        closedloop.tower_pole(control.ss(first.A, first.B, first.C, first.D, inputs="wind", outputs="tower_base_my"))


@pytest.mark.parametrize("v", [15.0, 19.0, 25.0])
def test_rosco_loop_damping_equals_the_tracked_tower_pole(model, v):
    # independent path: rosco.tower_mode_damping follows the tower pole from the fixed-pitch plant
    # as the damper's gain rises (here from 0 to 0: ROSCO's PI alone) in its own interconnection
    # (rosco_baseline, not spec.baseline_controller); both are the eigenvalues of the same loop,
    # so they agree to the eigensolver's accuracy on a well-separated pole (1e-9)
    plant = model.linearize(v)
    loop = closedloop.closed_loop(plant, spec.baseline_controller(model, v), warn=False)
    w, zeta = closedloop.tower_damping(plant, loop)
    assert zeta == pytest.approx(rosco.tower_mode_damping(model, v, None), rel=1e-9)
    open_w = abs(closedloop.tower_pole(plant))
    assert abs(w / open_w - 1) < 0.1  # the PI moves the mode by a few per cent, not more


def test_warning_text_only_below_the_fraction():
    f = modes.MIN_TOWER_DAMPING_FRACTION
    assert closedloop.tower_damping_message("design_qft", 19.0, f * 0.1 * 1.001, 0.1) is None
    msg = closedloop.tower_damping_message("design_qft", 19.0, f * 0.1 * 0.999, 0.1)
    assert "19 m/s" in msg and "tower damper" in msg and "spec_notch" in msg
    # a design that has a tower damper is not told to add one
    own = closedloop.tower_damping_message("design_qft", 19.0, f * 0.1 * 0.999, 0.1, tower_damper=True)
    assert "own tower damper" in own and "spec_notch" not in own and "Add a tower damper" not in own


def test_design_qft_reports_and_warns_on_the_tower_mode(model):
    # the default pitch-only design at 19 m/s lowers the tower mode's damping on the reduced model
    # (0.058 against ROSCO's 0.093, measured when this check was added; on OpenFAST's linearisation
    # 0.055-0.064 against 0.125, docs/openfast.md): the record carries both ratios and the design warns
    from specdesign import feasibility, qft
    pair = feasibility.specification_for_target(model, 19.0, 25.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        d = qft.design_qft(model, 19.0, spec=qft.spec_from_certified(pair))
    plant = model.linearize(19.0)
    assert d.tower_damping_ratio == pytest.approx(closedloop.tower_damping(plant, d.closed_loop)[1], rel=1e-12)
    assert d.baseline_tower_damping_ratio == pytest.approx(rosco.tower_mode_damping(model, 19.0, None), rel=1e-9)
    row = d.row()
    assert row["tower_damping_ratio"] == d.tower_damping_ratio
    weak = d.tower_damping_ratio < modes.MIN_TOWER_DAMPING_FRACTION * d.baseline_tower_damping_ratio
    assert weak  # what OpenFAST showed; if a design change lifts it, this test should be revised, not loosened
    hits = [r for r in rec if issubclass(r.category, closedloop.TowerDampingWarning)]
    assert len(hits) == 1 and "19 m/s" in str(hits[0].message) and "Add a tower damper" in str(hits[0].message)
    assert "ROSCO" in d.summary() and f"{d.tower_damping_ratio:.3f}" in d.summary()
    # the paper's structure (tower damper) damps the mode more than ROSCO: no warning
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        atd = qft.design_qft(model, 19.0, spec=qft.spec_notch(25.0))
    assert atd.tower_damping_ratio > d.baseline_tower_damping_ratio
    assert not [r for r in rec if issubclass(r.category, closedloop.TowerDampingWarning)]
    assert np.isfinite(atd.baseline_tower_damping_ratio)


def test_a_design_with_its_own_tower_damper_is_not_told_to_add_one(model, monkeypatch):
    # no design of the paper's structure at the default target leaves the mode below the fraction
    # (the 15 m/s warning benchmarks printed, ζ 0.072 against ROSCO's 0.106, came from a speed
    # relaxation design_qft passed over): the fraction is raised so that the 19 m/s design, which
    # has its tower damper, warns; its advice is about that damper, not to add one
    from specdesign import qft
    monkeypatch.setattr(modes, "MIN_TOWER_DAMPING_FRACTION", 100.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        d = qft.design_qft(model, 19.0, spec=qft.spec_notch(25.0))
    assert d.atd_controller is not None
    hits = [str(r.message) for r in rec if issubclass(r.category, closedloop.TowerDampingWarning)]
    assert len(hits) == 1 and "own tower damper" in hits[0] and "spec_notch" not in hits[0]


def test_design_qft_warns_of_the_design_it_returns_only(model):
    # spec_notch(35) at 19 m/s: a speed relaxation passed over had five unstable plant cases
    # (poles 0.07-0.11 1/s at 1.95 rad/s) and ζ 0.063, and said both, though the design returned
    # meets every spec with every case stable (measured 2026-11-28); the warnings are the result's
    from specdesign import qft
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always")
        d = qft.design_qft(model, 19.0, spec=qft.spec_notch(35.0))
    assert d.success and d.all_stable
    assert not [r for r in rec if issubclass(r.category, closedloop.ClosedLoopUnstableWarning)]
    weak = d.tower_damping_ratio < modes.MIN_TOWER_DAMPING_FRACTION * d.baseline_tower_damping_ratio
    assert weak == bool([r for r in rec if issubclass(r.category, closedloop.TowerDampingWarning)])
