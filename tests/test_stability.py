"""Stability and divergence are errors, not results (issue "Nothing silently wrong", §2).

A controller that destabilises the loop must never be reported as a fatigue reduction: a
single linear prediction raises, a campaign keeps the other controllers' results and marks
the unstable ones NaN with a warning ("unstable" in the tables), a diverging simulation
raises naming the run; steps the integrator cannot resolve and wind records about another
mean speed are refused up front; every path that reaches a pitch limit has anti-windup.
"""
from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from specdesign import fatigue, simulate as sm, turbine, validate as va
from specdesign.closedloop import ClosedLoopUnstableWarning, turbine_loop_poles


@pytest.fixture(scope="module")
def model():
    return turbine.iea15mw()


@pytest.fixture(scope="module")
def rosco(model):
    return turbine.rosco_baseline(model, 19.0)


@pytest.mark.parametrize("factor", [-1.0, 100.0])
def test_linear_prediction_of_a_destabilising_controller_raises(model, rosco, factor):
    bad = factor * rosco
    poles = turbine_loop_poles(model, bad, 19.0)
    assert np.max(poles.real) > 0  # independent: the interconnection's poles say unstable
    with pytest.raises(ValueError, match=r"destabilises the linearised turbine at 19 m/s .*poles"):
        va.linear_prediction(model, bad, 19.0)
    # ROSCO itself is stable and predicts a finite DEL
    assert np.max(turbine_loop_poles(model, rosco, 19.0).real) < 0
    assert np.isfinite(va.linear_prediction(model, rosco, 19.0).del_)


def test_closed_loop_poles_match_the_interconnection(model, rosco):
    # the same loop closed by closedloop.closed_loop (control.interconnect on named signals)
    from specdesign import closedloop

    cl = closedloop.closed_loop(model.linearize(19.0), rosco, warn=False)
    np.testing.assert_allclose(np.sort_complex(turbine_loop_poles(model, rosco, 19.0)),
                               np.sort_complex(cl.poles()), rtol=1e-7, atol=1e-9)


def test_simulate_raises_naming_the_run_when_the_loop_diverges(model, rosco):
    # ROSCO's PI with its sign flipped: the rotor runs away past twice its rated speed
    with pytest.warns(ClosedLoopUnstableWarning, match=r"destabilises .* 19 m/s"), \
            pytest.raises(sm.SimulationDivergedError, match=r"diverged at wind speed 19 m/s, seed 3, .*gen_speed"):
        sm.simulate(model, -rosco, [19.0], seeds=[3], duration=300.0)


def test_simulate_warns_when_the_pitch_limits_keep_an_unstable_loop_bounded(model, rosco):
    # ROSCO × 100: a limit cycle between the pitch limits, bounded but no result: a warning
    with pytest.warns(ClosedLoopUnstableWarning, match=r"destabilises .* 19 m/s .*pitch limits"):
        r = sm.simulate(model, 100.0 * rosco, [19.0], seeds=[3], duration=300.0)
    assert r["pitch_cmd"].min() == model.pitch_min and r["pitch_cmd"].max() == model.pitch_max


def test_campaign_marks_an_unstable_controller_and_keeps_the_others(model, rosco):
    with pytest.warns(ClosedLoopUnstableWarning, match="'flipped'.*19 m/s"):
        camp = va.run_campaign({"ROSCO": rosco, "flipped": -rosco}, [19.0], [1, 2], model=model, duration=100.0,
                               transient=20.0, progress=False, linear_twin=True, keep_series=1)
    assert camp.unstable.tolist() == [[False], [True]]
    assert np.all(np.isnan(camp.values["tower_del"][1])) and np.all(np.isnan(camp.predicted_del[1]))
    assert np.all(np.isfinite(camp.values["tower_del"][0])) and np.isfinite(camp.predicted_del[0, 0])
    t3 = va.table3(camp, "flipped", "ROSCO").to_markdown()
    assert "| Linear prediction | unstable |" in t3 and "| Rainflow evaluation | unstable |" in t3
    assert "unstable" in va.table2(camp, "flipped", "ROSCO").to_markdown()
    assert "unstable" not in va.table2(camp, "ROSCO", "ROSCO").to_markdown()


def test_a_step_too_large_is_refused_with_the_limit(model, rosco):
    # the IEA 15 MW's fastest linear mode is its pitch actuator, |λ| = 3.14 rad/s
    lam = max(np.max(np.abs(np.linalg.eigvals(np.asarray(model.linearize(v).A)))) for v in (19.0,))
    limit = sm.MAX_STEP_EIGENVALUE / lam
    with pytest.raises(ValueError, match=rf"dt=2.5 s is too large .* dt must be ≤ {limit:.3g} s"):
        sm.simulate(model, rosco, [19.0], seeds=[1], dt=2.5, record_dt=2.5, duration=100.0)
    sm.simulate(model, rosco, [19.0], seeds=[1], dt=0.1, record_dt=0.1, duration=20.0, transient=0.0)  # accepted


def test_wind_records_about_another_mean_speed_are_refused(model, rosco):
    wind = sm.wind_series(model.rotor_radius, [15.0], [1], 120.0, 0.1)
    with pytest.raises(ValueError, match=r"mean 15.* wind_speeds\[0\] = 19 m/s"):
        sm.simulate(model, rosco, [19.0], wind=wind, wind_dt=0.1, duration=60.0, transient=20.0)
    sm.simulate(model, turbine.rosco_baseline(model, 15.0), [15.0], wind=wind, wind_dt=0.1, duration=60.0,
                transient=20.0)  # its own speed: accepted


# ----------------------------------------------------------------------------- anti-windup
V_FLOOR = 12.5  # near rated the pitch reaches its minimum (0 rad) on every seed
KW = dict(seeds=[1, 2], duration=300.0, dt=0.02, record_dt=0.1, transient=20.0)


@pytest.fixture(scope="module")
def floor_runs(model):
    lti = turbine.rosco_baseline(model, V_FLOOR)
    rosco_form = sm.rosco_scheduled(model, [V_FLOOR])  # ROSCO's own clamped integrator, frozen gains
    unlimited = dataclasses.replace(sm.turbine_plant(model), pitch_limits=None)
    return dict(lti=sm.simulate(model, lti, [V_FLOOR], **KW), rosco=sm.simulate(model, rosco_form, [V_FLOOR], **KW),
                free=sm.simulate(unlimited, lti, [V_FLOOR], **KW))


def _del(r):
    return np.array([fatigue.del_rainflow(x, 4.0, r.duration) for x in r["tower_base_my"][0]])


def test_the_lti_rosco_path_does_not_wind_up_at_the_pitch_floor(model, floor_runs):
    lti, rosco, free = floor_runs["lti"], floor_runs["rosco"], floor_runs["free"]
    # the floor is reached (else this test proves nothing), and without limits the PI winds up
    assert np.mean(lti["pitch_cmd"] <= model.pitch_min + 1e-12) > 0.01
    assert free["pitch_cmd"].min() < model.pitch_min - np.radians(1.0)
    # with the limits: the command never leaves the pitch range
    assert lti["pitch_cmd"].min() >= model.pitch_min
    # conditional integration behaves as ROSCO's clamped integrator: the same loads within a
    # few percent (the wound-up PI of the issue doubled the DEL at 15 m/s: 149 vs 70 MN·m)
    assert np.all(np.abs(_del(lti) / _del(rosco) - 1) < 0.05), (_del(lti), _del(rosco))


def test_designed_lti_controllers_have_anti_windup_too(model):
    # a designed pitch + ATD pair (ROSCO's PI with more gain, a lead-lag ATD), output-blended
    import control

    pitch = 1.3 * turbine.rosco_baseline(model, V_FLOOR)
    atd = control.tf([-0.03, -0.02], [1.0, 0.3])
    sc = sm.scheduled(model, {V_FLOOR: pitch}, {V_FLOOR: atd}, name="designed")
    r = sm.simulate(model, sc, [V_FLOOR], **KW)
    unlimited = dataclasses.replace(sm.turbine_plant(model), pitch_limits=None)
    free = sm.simulate(unlimited, sc, [V_FLOOR], **KW)
    assert np.mean(r["pitch_cmd"] <= model.pitch_min + 1e-12) > 0.01 and r["pitch_cmd"].min() >= model.pitch_min
    assert free["pitch_cmd"].min() < model.pitch_min - np.radians(1.0)
    # no wind-up: every time the command leaves the floor it does so within a second of the
    # unclamped command turning upwards, never after a long recovery
    at_floor = r["pitch_cmd"][0, 0] <= model.pitch_min + 1e-12
    runs = np.diff(np.r_[0, at_floor.astype(int), 0])
    lengths = np.flatnonzero(runs == -1) - np.flatnonzero(runs == 1)
    free_below = free["pitch_cmd"][0, 0] < model.pitch_min
    fruns = np.diff(np.r_[0, free_below.astype(int), 0])
    free_lengths = np.flatnonzero(fruns == -1) - np.flatnonzero(fruns == 1)
    assert lengths.max() < free_lengths.max()


def test_results_are_unchanged_where_no_limit_is_reached(model, rosco):
    # 19 m/s stays far from the pitch limits: the saturated loop equals the unsaturated one exactly
    kw = dict(seeds=[1], duration=200.0, transient=20.0)
    a = sm.simulate(model, rosco, [19.0], **kw)
    b = sm.simulate(dataclasses.replace(sm.turbine_plant(model), pitch_limits=None), rosco, [19.0], **kw)
    assert a["pitch_cmd"].min() > model.pitch_min + 0.05
    np.testing.assert_array_equal(a["tower_base_my"], b["tower_base_my"])


def test_blended_locals_with_integrators_are_stable_between_their_speeds(model):
    # Two locals that integrate the same error, blended at 16 m/s: one integrator, as the
    # simulator runs them (a parallel realisation would add a spurious pole at s = 0 and call
    # a stable loop unstable); the blend equals the explicit sum of the two responses.
    sc = sm.scheduled(model, {15.0: turbine.rosco_baseline(model, 15.0), 17.0: turbine.rosco_baseline(model, 17.0)})
    poles = turbine_loop_poles(model, sc, 16.0)
    assert np.max(poles.real) < 0
    assert np.isfinite(va.linear_prediction(model, sc, 16.0).del_)
    assert np.max(turbine_loop_poles(model, sm.rosco_scheduled(model), 16.3).real) < 0


# ----------------------------------------------------------------------------- hidden modes at s = 0
def test_an_integrating_atd_leaves_a_conserved_mode_at_zero_not_an_instability(model, rosco):
    # An ATD controller with a pole at 0 integrates the tower-top velocity: ∫ẋ_top − x_top is
    # conserved, a closed-loop pole at s = 0 the wind cannot excite (what a 1×2 H∞ controller
    # split into SISO pitch and ATD parts carries). Its rounding (here +1.5e-16) decided
    # "unstable": linear_prediction raised and a campaign dropped the controller.
    import control

    sc = sm.scheduled(model, {19.0: rosco}, {19.0: control.tf([0.05], [1.0, 0.0])}, name="ATD-I")
    poles = turbine_loop_poles(model, sc, 19.0)
    assert np.min(np.abs(poles)) < 1e-12  # the conserved mode is there
    assert np.max(poles.real[np.abs(poles) > 1e-9]) < -0.05  # every other mode decays
    from specdesign import closedloop

    assert closedloop.unstable_poles(model, sc, 19.0).size == 0
    assert np.isfinite(va.linear_prediction(model, sc, 19.0).del_)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClosedLoopUnstableWarning)
        r = sm.simulate(model, sc, [19.0], seeds=[1], duration=100.0, transient=20.0)
    assert np.all(np.isfinite(r["tower_base_my"]))
    # with the opposite sign the loop is truly unstable (a tower-mode pair): still reported
    bad = closedloop.unstable_poles(model, sm.scheduled(model, {19.0: rosco}, {19.0: control.tf([-0.05], [1.0, 0.0])}), 19.0)
    assert bad.size == 2 and np.all(np.abs(np.abs(bad.imag) - 1.27) < 0.05)


def test_hidden_origin_poles_is_the_pbh_test():
    from specdesign.closedloop import hidden_origin_poles

    A = np.array([[0.0, 1.0], [0.0, -2.0]])
    assert hidden_origin_poles(A, np.array([1.0, 0.0])).tolist() == [False, False]  # the wind drives it: a drift
    assert sorted(hidden_origin_poles(A, np.array([-1.0, 2.0])).tolist()) == [False, True]  # left eigvec [2, 1] ⟂ b


# ----------------------------------------------------------------------------- the sampled loop
def test_sampled_loop_radius_predicts_the_simulated_decay(model):
    # Independent of the formula: the slowest mode of the linear simulation (kernel: RK4 with
    # the command held, Tustin controller) decays per second at log(ρ)/dt.
    c = 5.0 * turbine.rosco_baseline(model, 19.0)
    dt = 0.1
    rate = np.log(sm.sampled_loop_radius(model, c, 19.0, dt)) / dt
    n = int(400.0 / dt) + 2
    wind = np.full((1, 1, n), 19.0)
    wind[..., 10:30] += 0.2  # a 2 s gust from t = 1 s
    free = dataclasses.replace(sm.turbine_plant(model), pitch_limits=None)
    r = sm.simulate(free, c, [19.0], wind=wind, wind_dt=dt, duration=400.0, dt=dt, record_dt=dt, transient=0.0,
                    linear=True)
    y = np.abs(r["gen_speed"][0, 0] - model.rated_rotor_speed)
    win = int(40.0 / dt)
    starts = np.arange(int(60.0 / dt), int(300.0 / dt), win)
    env = np.array([y[i:i + win].max() for i in starts])
    fitted = np.polyfit(starts * dt, np.log(env), 1)[0]
    assert rate < 0 and abs(fitted / rate - 1) < 0.05, (fitted, rate)


def test_a_step_the_sampled_loop_cannot_take_is_refused_with_its_limit(model):
    # ROSCO × 2 at 13 m/s: stable in continuous time (max Re −0.015 1/s), but the command held
    # over a 0.3 s step adds enough lag to destabilise it; 0.3 s passes the plant's own bound (0.32 s)
    import re

    c = 2.0 * turbine.rosco_baseline(model, 13.0)
    assert np.max(turbine_loop_poles(model, c, 13.0).real) < 0
    with pytest.raises(ValueError, match=r"dt=0.3 s is too large for controller .* at 13 m/s.*dt must be ≤ 0.2\d\d s") as err:
        sm.simulate(model, c, [13.0], seeds=[1], dt=0.3, record_dt=0.3, duration=60.0)
    limit = float(re.search(r"dt must be ≤ ([0-9.]+) s", str(err.value)).group(1))
    assert sm.sampled_loop_radius(model, c, 13.0, limit) < 1.0 < sm.sampled_loop_radius(model, c, 13.0, 0.3)
    assert sm.sampled_loop_radius(model, c, 13.0, 0.02) < 1.0
    sm.simulate(model, c, [13.0], seeds=[1], dt=0.25, record_dt=0.25, duration=60.0)  # accepted


def test_a_campaign_refuses_the_step_before_simulating_anything(model, rosco, monkeypatch):
    def no_simulation(*a, **k):
        raise AssertionError("simulated before the step was checked")

    monkeypatch.setattr(sm, "simulate", no_simulation)
    bad = 2.0 * turbine.rosco_baseline(model, 13.0)
    with pytest.raises(ValueError, match=r"campaign controller 'strong'.*13 m/s.*dt must be ≤"):
        va.run_campaign({"ROSCO": rosco, "strong": bad}, [19.0, 13.0], [1], model=model, dt=0.3, record_dt=0.3,
                        duration=60.0, progress=False)


def test_a_campaign_keeps_the_stable_speeds_of_a_controller_unstable_at_one(model):
    # ROSCO(19 m/s) × 6: stable at 13 m/s (max Re −0.022 1/s), unstable at 25 m/s (+0.007 1/s)
    c = 6.0 * turbine.rosco_baseline(model, 19.0)
    base = turbine.rosco_baseline(model, 19.0)
    with pytest.warns(ClosedLoopUnstableWarning, match="'x6'.*25 m/s"):
        camp = va.run_campaign({"base": base, "x6": c}, [13.0, 25.0], [1], model=model, duration=60.0, transient=20.0,
                               progress=False, keep_series=1)
    assert camp.unstable.tolist() == [[False, False], [False, True]]
    s = camp.series["x6"]["tower_base_my"]
    assert np.all(np.isfinite(s[0])) and np.all(np.isnan(s[1]))  # 13 m/s kept, 25 m/s NaN
    md = va.table2(camp, "x6", "base").to_markdown()
    row = next(line for line in md.splitlines() if line.startswith("| Tower base DEL |"))
    cells = [c.strip() for c in row.strip().strip("|").split("|")]
    assert cells[1].endswith("%") and cells[2] == "unstable" and cells[3] == "unstable"  # 13, 25 m/s, the Mean


# ----------------------------------------------------------------------------- anti-windup, slow modes
# A designed controller whose rest has a slow pole: ROSCO's PI times a lag (s + 0.05)/(s + 0.02).
# Its integral alone is not the pitch it holds: the lag's mode (0.02 rad/s) carries a residue
# of the opposite sign. Clamping the integral alone at the limits (as ROSCO clamps its own)
# changed this loop at 15-25 m/s with the pitch 4.7° above its floor (by 3 load SDs).
def _lagged(model, v):
    import control

    return control.tf([1.0, 0.05], [1.0, 0.02]) * turbine.rosco_baseline(model, v)


def test_a_slow_controller_is_unchanged_where_no_limit_is_reached(model):
    c = _lagged(model, 19.0)
    r, rest = sm.split_integrator(c)
    assert r != 0 and sm.split_slow(rest)[0] is not None  # it has a slow part
    kw = dict(seeds=[1, 2], duration=300.0, transient=30.0)
    a = sm.simulate(model, c, [15.0, 19.0, 25.0], **kw)
    b = sm.simulate(dataclasses.replace(sm.turbine_plant(model), pitch_limits=None), c, [15.0, 19.0, 25.0], **kw)
    assert a["pitch_cmd"].min() > model.pitch_min + np.radians(3.0)
    np.testing.assert_array_equal(a["tower_base_my"], b["tower_base_my"])


def test_split_slow_is_exact():
    import control

    c = control.tf([1.0, 3.0, 0.5], np.poly([-0.04, -1.0, -2.0]))  # one pole under SLOW_OMEGA
    slow, fast = sm.split_slow(c)
    np.testing.assert_allclose(control.ss(slow).poles(), [-0.04], rtol=1e-9)
    assert np.all(np.abs(control.ss(fast).poles()) > sm.SLOW_OMEGA)
    w = 1j * np.logspace(-3, 2, 40)
    np.testing.assert_allclose(np.asarray(slow(w)) + np.asarray(fast(w)), np.asarray(c(w)), rtol=1e-10)
    assert sm.split_slow(control.tf([1.0], [1.0, 1.0]))[0] is None


def test_a_slow_controller_does_not_wind_up_at_the_pitch_floor(model, floor_runs):
    c = _lagged(model, V_FLOOR)
    r = sm.simulate(model, c, [V_FLOOR], **KW)
    free = sm.simulate(dataclasses.replace(sm.turbine_plant(model), pitch_limits=None), c, [V_FLOOR], **KW)
    pc, fc = r["pitch_cmd"][0, 0], free["pitch_cmd"][0, 0]
    assert np.mean(pc <= model.pitch_min + 1e-12) > 0.05 and pc.min() >= model.pitch_min  # seed 1 sits on the floor
    assert fc.min() < model.pitch_min - np.radians(10.0)  # unclamped it winds up (−30°)

    def longest(mask):
        d = np.diff(np.r_[0, mask.astype(int), 0])
        return (np.flatnonzero(d == -1) - np.flatnonzero(d == 1)).max()

    # on the floor for 27 s at most, where the wound-up command stays below it for 67 s
    assert longest(pc <= model.pitch_min + 1e-12) < 0.6 * longest(fc < model.pitch_min)
    # loads: those of ROSCO's clamped PI within 15 % (54 vs 56 MN·m), where the wound-up loop doubles them (101)
    d, d_rosco, d_free = _del(r)[0], _del(floor_runs["rosco"])[0], _del(free)[0]
    assert abs(d / d_rosco - 1) < 0.15 and d_free > 1.5 * d_rosco, (d, d_rosco, d_free)


def test_a_scheduled_pi_without_its_own_limits_takes_the_plants(model, floor_runs):
    # ROSCO's form with pitch_limits=None used to run its integrator unclamped while the plant
    # saturated the command (wind-up); it now clamps at the plant's limits: ROSCO exactly.
    sc = dataclasses.replace(sm.rosco_scheduled(model, [V_FLOOR]), pitch_limits=None)
    r = sm.simulate(model, sc, [V_FLOOR], **KW)
    np.testing.assert_array_equal(r["pitch_cmd"], floor_runs["rosco"]["pitch_cmd"])


@pytest.mark.parametrize("v", [5.0, 9.0])
def test_below_rated_the_pitch_loop_is_open(model, v):
    # the simulator's pitch PI sits at fine pitch below rated: the loop the checks and the
    # prediction see is the plant's linearisation (torque loop closed in it) alone. Oracle:
    # the linearisation's own poles and its open-loop wind-to-moment response.
    from specdesign.closedloop import local_response

    sched = sm.rosco_scheduled(model)
    G = model.linearize(v)
    for c in (sched, turbine.rosco_baseline(model, 19.0), 100.0 * turbine.rosco_baseline(model, 19.0)):
        np.testing.assert_allclose(np.sort_complex(turbine_loop_poles(model, c, v)),
                                   np.sort_complex(np.linalg.eigvals(np.asarray(G.A))), rtol=1e-10, atol=1e-12)
        cb, ca = local_response(model, c, v, 1j * np.array([0.1, 1.0]))
        assert not np.any(cb) and not np.any(ca)
    omega = np.array([0.3, 1.1])
    k = list(G.output_labels).index("tower_base_my")
    open_loop = np.array([G(1j * w)[k, 0] for w in omega])
    np.testing.assert_allclose(va.closed_loop_response(model, sched, v, omega, "tower_base_my"), open_loop, rtol=1e-9)
    # above rated nothing changes: the same controller closes the loop
    assert turbine_loop_poles(model, sched, 13.0).size > G.nstates
