"""qft.design_torque: the torque-loop design below rated (issue 16 part 1)."""
from __future__ import annotations

import dataclasses

import control as ct
import numpy as np
import pytest

from specdesign import qft
from specdesign.fatigue import del_rainflow
from specdesign.qft.torque_design import (
    _form,
    _law_tf,
    _responses,
    law_promise,
    torque_law_response,
)
from specdesign.rosco import rosco_scheduled
from specdesign.simulate import simulate
from specdesign.spectral import del_spectral
from specdesign.turbine import iea15mw
from specdesign.wind import rotor_effective_spectrum


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def design(model):
    return qft.design_torque(model, 8.0, target_reduction=20.0, max_power_loss_pct=1.0)


def _closed_by_interconnect(model, v, law):
    """T_MyT,w with ``law`` as simulated in place of linearize's: τ_add = (L − L_lin)·Ω_g, closed by python-control."""
    P = model.linearize(v)
    lin = 2 * model.torque_control.k_opt * model.trim(v).rotor_speed  # region 2: linearize closes 2KΩ
    K = ct.ss(_law_tf(model, law, v) - lin, inputs=["gen_speed"], outputs=["gen_torque"], name="K")
    return ct.interconnect([P, K], inplist=["wind"], outlist=["tower_base_my"], check_unused=False)


def test_closed_loop_map_matches_interconnect(model, design):
    T = _closed_by_interconnect(model, 8.0, design.torque_law(model.torque_control))
    ref = ct.frequency_response(T, design.omega).complex.ravel()
    assert np.max(np.abs(design.t_response - ref)) <= 1e-8 * np.max(np.abs(ref))
    assert np.all(np.real(T.poles()) < 0)


def test_promise_recomputed_independently(model, design):
    # Dirlik on |T|²S_W (interconnect maps, wind spectrum from specdesign.wind), design law vs ROSCO's law
    w = design.omega
    # variance about each 600 s record's mean (wind.record_window), written out: 1 − sinc²(ωT/2)
    s_w = rotor_effective_spectrum(w, 8.0, model.rotor_radius, turbulence_class="B") * (1 - (np.sin(300.0 * w) / (300.0 * w)) ** 2)

    def dlt(law):
        t = ct.frequency_response(_closed_by_interconnect(model, 8.0, law), w).complex.ravel()
        return del_spectral(w, np.abs(t) ** 2 * s_w, 4.0)

    base = dlt(model.torque_control)
    assert base == pytest.approx(design.baseline_del, rel=1e-9)
    promise = 100 * (1 - dlt(design.torque_law(model.torque_control)) / base)
    assert promise == pytest.approx(design.promise, abs=1e-6)
    assert promise >= 20.0 - 1e-6
    # "smallest gain": 1 % less gain misses the target
    less = dataclasses.replace(design, gain=0.99 * design.gain).torque_law(model.torque_control)
    assert 100 * (1 - dlt(less) / base) < 20.0
    assert law_promise(model, design) == pytest.approx(design.promise, abs=1e-9)
    # the costs are those of the stiffer loop: the rotor speed moves less, the torque more, the power is lost
    assert design.speed_sd < design.baseline_speed_sd
    assert design.torque_sd > design.baseline_torque_sd
    assert -1.0 <= design.power_change_pct < 0


def test_design_is_continuous_in_the_inputs(model, design):
    d = qft.design_torque(model, 8.0 + 1e-9, target_reduction=20.0 + 1e-9, max_power_loss_pct=1.0)
    assert d.gain == pytest.approx(design.gain, rel=1e-6)


def test_torque_law(model, design):
    law = design.torque_law(model.torque_control)
    # region 2: the law's stiffness is 2KΩ at the trim; the PI's proportional gain is that plus k (ROSCO's sign)
    stiff = 2 * model.torque_control.k_opt * model.trim(8.0).rotor_speed
    assert design.law_stiffness == pytest.approx(stiff)
    assert law.mode == 3 and law.kp == pytest.approx(-(stiff + design.gain))
    assert law.ki / law.kp == pytest.approx(model.torque_control.ki / model.torque_control.kp)
    assert law.reference_corner == design.reference_corner == 0.02
    with pytest.raises(ValueError, match="reference_corner"):
        qft.design_torque(model, 8.0, target_reduction=20.0, reference_corner=0.0)


def test_refusals(model):
    with pytest.raises(ValueError, match="pitch loop acts"):
        qft.design_torque(model, 13.0, target_reduction=10.0)
    # at 8 m/s the mode-3 PI on the filtered speed reaches at most 22.7 %, the limit G → ∞ ≈ 41.8 %
    # (docs/below_rated.md section 3: DEL Ω held −42 %; the filter's lag at the tower mode caps the PI)
    with pytest.raises(ValueError, match=r"reaches at most 22\.7 % .* G -> inf \(rotor speed held\) gives 41"):
        qft.design_torque(model, 8.0, target_reduction=25.0)
    # 20 % costs ≈ 0.67 % power (docs/below_rated.md section 3): a 0.5 % budget is refused, naming the loss and the gain
    with pytest.raises(ValueError, match=r"power loss 0\.6\d % exceeds max_power_loss_pct=0\.5 at k = "):
        qft.design_torque(model, 8.0, target_reduction=20.0, max_power_loss_pct=0.5)
    for kw, name in (({"target_reduction": 0.0}, "target_reduction"), ({"target_reduction": float("nan")}, "target_reduction"),
                     ({"max_power_loss_pct": -1.0}, "max_power_loss_pct"), ({"m": 0.0}, "m="),
                     ({"omega": [1.0, 0.5]}, "omega")):
        with pytest.raises(ValueError, match=name):
            qft.design_torque(model, 8.0, **({"target_reduction": 10.0} | kw))
    with pytest.raises(ValueError, match="wind_speed"):
        qft.design_torque(model, float("nan"), target_reduction=10.0)
    with pytest.raises(TypeError, match="torque law"):
        qft.design_torque(dataclasses.replace(model, torque_control=None), 8.0, target_reduction=10.0)


def test_nonlinear_direction(model, design):
    """8 m/s, 2 paired seeds x 600 s, ROSCO's pitch PI: the designed law lowers the rainflow tower DEL.

    The linear promise is 20 %; over 20 paired seeds the law gives −14.5 ± 1.7 % (72 % of it), the
    gap measured row by row in docs/below_rated.md section 3 (the torque ceiling in gusts, the
    minimum-speed region, Dirlik vs rainflow and the aerodynamics: nonlinear, not the law's
    linearisation). The acceptance on the pair is the direction on every seed and at least 40 % of
    the promise (measured −19.7 / −11.0 %).
    """
    ros = rosco_scheduled(model)
    dels = {}
    for name, law in (("rosco", model.torque_control), ("design", design.torque_law(model.torque_control))):
        r = simulate(model, ros, [8.0], seeds=range(1, 3), duration=600.0, torque_control=law)
        dels[name] = np.array([del_rainflow(x, 4.0, 600.0) for x in r["tower_base_my"][0]])
    change = 100 * (dels["design"] / dels["rosco"] - 1)
    assert np.all(change < 0)
    assert change.mean() <= -0.4 * design.promise


@pytest.mark.parametrize("w0", [0.1, 0.3, 1.0])
def test_law_linearisation_matches_small_amplitude_response(model, design, w0):
    """The mode-3 law linearised as simulated (torque_law_response) is the nonlinear loop's small-amplitude response.

    8 m/s, the 20 % design's law (TorqueDesign.torque_law), pitch held (a zero pitch controller), wind
    8 + 0.02·sin(ω₀t) m/s: the tower-base moment's first harmonic over 600 s after 600 s of transient
    against T_MyT,w with G = L_lin − L (the general form). Measured: within 0.13 % and 0.05°
    (benchmarks/below_rated_design.py --part torque_gap); the K·Ω² + k·δΩ map the promise uses is off
    by 4-13 % and 1.5-10° there, so the tolerance (1 %, 0.5°) separates the two.
    """
    d = design
    law = d.torque_law(model.torque_control)
    A, B, _, D = (x[0] for x in _form(_responses(model.linearize(8.0), np.array([w0]))))
    G = 2 * law.k_opt * model.trim(8.0).rotor_speed - ct.frequency_response(_law_tf(model, law, 8.0), [w0]).complex.ravel()[0]
    linear, promised = (A + B * G) / (1 + D * G), (A - B * d.gain) / (1 - D * d.gain)
    amp, per = 0.02, 2 * np.pi / w0
    dur = np.ceil(600.0 / per) * per
    t = np.arange(0.0, 600.0 + dur + 1.0, 0.1)
    r = simulate(model, ct.tf([0.0], [1.0]), [8.0], wind=(8.0 + amp * np.sin(w0 * t))[None, None], duration=round(dur, 1),
                 transient=600.0, torque_control=law, wind_dt=0.1)
    tt = r.time + 600.0
    c = np.linalg.lstsq(np.column_stack([np.sin(w0 * tt), np.cos(w0 * tt), np.ones_like(tt)]), r["tower_base_my"][0, 0],
                        rcond=None)[0]
    measured = (c[0] + 1j * c[1]) / amp
    assert abs(abs(measured / linear) - 1) < 0.01
    assert abs(np.degrees(np.angle(measured / linear))) < 0.5
    assert abs(abs(measured / promised) - 1) > 0.01 or abs(np.degrees(np.angle(measured / promised))) > 1.0


def test_law_promise(model, design):
    # the law's own curve at s → 0: ROSCO's mode 1 and the design's mode 3 both give 2KΩ (N·m per rad/s)
    stiff = 2 * model.torque_control.k_opt * model.trim(8.0).rotor_speed
    law = design.torque_law(model.torque_control)
    for tl in (model.torque_control, law):
        assert torque_law_response(model, tl, 8.0, [1e-7])[0] == pytest.approx(stiff, rel=1e-4)
    # the baseline's own law as the design promises nothing; the design's law without ROSCO's speed filter
    # (corner 30 rad/s) promises more: the filter's lag at the tower mode is what caps the family
    assert law_promise(model, design, model.torque_control) == pytest.approx(0.0, abs=1e-9)
    assert law_promise(model, design, dataclasses.replace(law, filter_corner=30.0)) > design.promise + 0.5
    with pytest.raises(ValueError, match="torque region"):
        torque_law_response(model, model.torque_control, 15.0, [1.0])


def test_region_one_and_a_half(model):
    # 7 m/s trims at the minimum speed (region 1.5): both laws are PIs on the filtered speed there, and the
    # linearised law's PI state and G's integrator share a mode at s = 0 that must not read as unstable
    assert model.trim(7.0).region == "1.5"
    d = qft.design_torque(model, 7.0, target_reduction=10.0)
    assert d.gain > 0 and d.promise == pytest.approx(10.0, abs=1e-6)
    assert law_promise(model, d) == pytest.approx(d.promise, abs=1e-9)
