"""The design loop below rated and through the transition (issue 16, part 1).

Oracles:
- the closed-loop map of ``spec.baseline_analysis`` from cut-in to cut-out against an
  independent interconnection: the model's raw Jacobians at the trim (torque an input, no law
  in them), ROSCO's torque law written here as its own LTI block from the law's parameters
  (region 2: dT/dΩ = 2KΩ; region 1.5: the PI (k_p + k_i/s) on the speed error; 2.5s and 3:
  torque held) and ROSCO's pitch loop (below rated: none, the PI sits at fine pitch; above
  rated: ROSCO's PI), joined by python-control's ``interconnect``;
- ROSCO's gain table held at its ends (ROSCO's ``interp1d``) between rated and the first
  speed of ROSCO's grid.
"""
import control
import numpy as np
import pytest

from specdesign.rosco import rosco_baseline, rosco_gain_schedule
from specdesign.spec import baseline_analysis
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def _interconnected(model, v):
    """wind → (gen_speed, tower_base_my) with the torque law and pitch loop as separate blocks."""
    op = model.trim(v)
    A, B, C, D = model.jacobians(op)
    n = A.shape[0]
    outs = ["gen_speed", "tower_base_my", "rotor_speed"]
    Cr = np.vstack([C[:2], np.eye(n)[:1]])
    Dr = np.vstack([D[:2], np.zeros((1, 3))])
    plant = control.ss(A, B, Cr, Dr, inputs=["wind", "pitch_cmd", "gen_torque"], outputs=outs, name="plant")
    law = model.torque_control
    if op.region == "2":
        torque = control.tf([2 * law.k_opt * op.rotor_speed], [1.0])
    elif op.region in ("1.5", "2.5"):  # δT = −(k_p + k_i/s)·δΩ (ROSCO's sign: gains negative)
        torque = control.tf([-law.kp, -law.ki], [1.0, 0.0])
    else:
        torque = control.tf([0.0], [1.0])
    torque = control.ss(torque, inputs="rotor_speed", outputs="gen_torque", name="torque")
    if op.region == "3":
        c = rosco_gain_schedule(model)
        kp, ki = c.gains(max(v, float(c.v.min())))
        pitch = -control.tf([kp, ki], [1.0, 0.0]) * control.tf([1.0081**2], [1, 2 * 0.7 * 1.0081, 1.0081**2])
    else:
        pitch = control.tf([0.0], [1.0])
    pitch = control.ss(pitch, inputs="gen_speed", outputs="pitch_cmd", name="pitch")
    return control.interconnect([plant, torque, pitch], inplist=["wind"], outlist=outs[:2],
                                inputs=["wind"], outputs=outs[:2])


@pytest.mark.parametrize("v, region", [(4.0, "1.5"), (8.5, "2"), (10.5, "2.5s"), (10.8, "3"), (12.0, "3")])
def test_baseline_analysis_closes_the_torque_loop_from_cut_in(model, v, region):
    assert model.trim(v).region == region
    w = np.logspace(-2, 1, 60)
    ref = _interconnected(model, v)
    for k, y in enumerate(("tower_base_my", "gen_speed")):
        base = baseline_analysis(model, v, y, omega=w)
        t_ref = np.asarray(ref(1j * w))[1 if y == "tower_base_my" else 0, 0]
        np.testing.assert_allclose(base.t_response, t_ref, rtol=1e-7)
        # ΣΔD% ≈ 2 for m = 4 (damage ∝ S_y^{m/2} for a uniform 1 % step): a meaningful map
        assert base.sensitivity.sum() == pytest.approx(2.0, abs=0.01)


def test_pitch_loop_is_open_below_rated_and_rosco_holds_its_first_gains_to_rated(model):
    for v in (3.0, 7.0, 10.5):
        c = rosco_baseline(model, v)
        assert c.name.endswith("_fine_pitch") and np.all(np.asarray(c(1j * np.array([0.1, 1.0]))) == 0)
    sched = rosco_gain_schedule(model)
    lo = float(sched.v.min())
    assert model.rated_wind_speed() < 10.8 < lo
    w = 1j * np.array([0.05, 0.5, 2.0])
    np.testing.assert_allclose(np.asarray(rosco_baseline(model, 10.8)(w)), np.asarray(rosco_baseline(model, lo)(w)),
                               rtol=1e-12)
    with pytest.raises(ValueError, match="operating range"):
        rosco_baseline(model, 2.0)


# ----------------------------------------------------------------------------- design requests below the design range
@pytest.mark.parametrize("v, reason", [(8.0, "below rated"), (10.8, "between rated")])
def test_pitch_design_below_the_design_range_is_refused_with_its_reason(model, v, reason):
    from specdesign import qft

    with pytest.raises(ValueError, match=reason):
        qft.check_design_speed(model, v)
    with pytest.raises(ValueError, match=reason):
        qft.design_qft(model, v, 25.0)
    with pytest.raises(ValueError, match=reason):  # before any design of the other speeds
        qft.design_schedule(model, (15.0, v), progress=False)
    assert qft.check_design_speed(model, 11.0) == 11.0


@pytest.mark.slow
def test_unstable_certificate_near_rated_is_not_a_success(model):
    """At 11 m/s the certificate for 20 % (the Youla design, C = Y/(1 − P·Y)) had a pole pair
    at +0.146 ± 2.38j 1/s (benchmarks/below_rated_design.py); in the lulls the pitch sits at
    fine pitch, the loop opens and that pair grows (the 9-15 m/s campaign diverges). The
    certificate search now counts a certificate that is itself unstable as no design
    (feasibility.target's UNSTABLE_POLE_TOL), so the target is refused before any design, with
    the speed, the target and the best stable promise named (the stable certificates promise
    a few per cent there), and never returned as a success."""
    import re
    import warnings

    from specdesign import qft

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        with pytest.raises(ValueError, match="no pitch specification promises 20 % at 11 m/s") as err:
            # without the high-frequency gain bound, as measured above: under it the best stable
            # certificate at 11 m/s promises −12.0 % (more DEL than ROSCO), a refusal as well
            qft.design_qft(model, 11.0, 20.0, max_hf_gain_ratio=None)
    best = float(re.search(r"best ([0-9.]+) %", str(err.value)).group(1))
    assert 0.0 < best < 20.0


# ----------------------------------------------------------------------------- a design held below rated
def test_fine_pitch_lift_against_an_independent_step_response(model):
    """Oracle: scipy.signal.step of the same transfer function (another integrator than
    python-control's), β = −C·δΩ_g for δΩ_g = −deficit. ROSCO's PI pushes the pitch into fine
    pitch (lift ≤ 0); a controller with the same integral action plus a lightly damped mode of
    the opposite sign (0.1 rad/s², ζ = 0.1 at 1 rad/s) swings the pitch up first."""
    from scipy import signal

    from specdesign.qft import fine_pitch_lift

    deficit = model.torque_control.pitch_reference_speed - model.torque_control.min_speed
    rosco = rosco_baseline(model, 13.0)
    assert fine_pitch_lift(rosco, deficit) <= 1e-12
    swing = control.tf([-0.6, -0.08], [1.0, 0.0]) + control.tf([30.0, 0.0], [1.0, 0.2, 1.0])
    t = np.linspace(0.0, 60.0, 6001)
    _, y = signal.step(signal.TransferFunction(swing.num[0][0], swing.den[0][0]), T=t)
    expected = float(np.max(deficit * y))
    assert expected > model.torque_control.pitch_switch  # lifted beyond ROSCO's region-3 switch
    assert fine_pitch_lift(swing, deficit) == pytest.approx(expected, rel=1e-6)
    with pytest.raises(ValueError, match="deficit"):
        fine_pitch_lift(rosco, -0.1)
    with pytest.raises(ValueError, match="SISO"):
        fine_pitch_lift(control.ss(np.zeros((1, 1)), np.zeros((1, 2)), np.zeros((1, 1)), np.zeros((1, 2))), 0.2)


def test_the_held_design_keeps_fine_pitch_below_rated(model):
    """A schedule holds its lowest design below rated (the lifetime demo holds it again, issue 28):
    made with held_below_rated=True its certificate and its reduced controller answer the torque
    law's speed deficit with at most pitch_switch of lift (fine_pitch_lift, checked here on the
    returned controllers). Without the high-frequency gain bound the certificates at 15 m/s promise
    up to 47.6 % over the relaxation ladder, those that keep fine pitch up to 42.5 % (the ladder's
    best with and without held_below_rated, 0.5 dB slack): a 45 % target is refused when held,
    the search naming the constraint."""
    from specdesign import feasibility as fz
    from specdesign.qft import design_qft, fine_pitch_lift, held_lift

    law = model.torque_control
    deficit = law.pitch_reference_speed - law.min_speed
    d = design_qft(model, 15.0, 18.0, held_below_rated=True)  # 18 %: feasible under the default bound
    assert d.success and d.options["held_lift_limit"] == pytest.approx((deficit, law.pitch_switch))
    assert held_lift(model, d) <= law.pitch_switch
    target = fz.specification_for_target(model, 15.0, 18.0, held_below_rated=True)
    assert fine_pitch_lift(target.design.controller(model), deficit) <= law.pitch_switch
    with pytest.raises(ValueError, match="held_below_rated"):
        fz.specification_for_target(model, 15.0, 45.0, max_hf_gain_ratio=None, held_below_rated=True)
