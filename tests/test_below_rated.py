"""Below rated and the transition (issue 16, part 1): ROSCO's torque law in the trim, the
linearisation and the compiled simulator.

Oracles:
- the trim: the equilibrium itself (the model's own derivatives vanish at the trim with the
  law's torque) and the law (K·Ω² in region 2, the PI's speed in regions 1.5 and 2.5);
- the linearisation: the derivative of the closed-loop right-hand side by an independent
  central difference (region 2), and the PI's integral action (regions 1.5 and 2.5: zero
  steady-state speed deviation for a wind step);
- above rated: the model without a torque law (the code path of every documented number),
  bit for bit;
- the simulator: ROSCO's own compiled controller (``specdesign.rosco.Discon``, the rosco
  package's libdiscon 2.10) in the loop, on a copy of ROSCO's IEA 15 MW DISCON.IN with
  ``VS_ControlMode`` 1 (and 3) and peak shaving off (``PS_Mode`` 0: its minimum pitch belongs
  to the pitch controller, tests/test_peak_shaving.py), driven by the same wind.
  The compiled real controller exists for this turbine, so it is the oracle rather than a
  second Python transcription of the same Fortran. Acceptance of the issue: rotor speed,
  torque and pitch SD within 2 % at 5, 9, 11 and 13 m/s (measured: ≤ 0.08 % in mode 1,
  ≤ 0.7 % in mode 3). The DISCON tests skip, with the reason, without the rosco package
  (CI installs it with the dev extra).
"""
import dataclasses
import re
from pathlib import Path

import control
import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign.rosco import (
    Discon,
    TorqueLaw,
    from_discon,
    iea15mw_discon,
    read_discon,
    rosco_scheduled,
    rosco_test_cases,
    torque_law_from_discon,
    write_discon,
)
from specdesign.simulate import simulate
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def model():
    return iea15mw()


# ----------------------------------------------------------------------------- trim
def test_trim_from_cut_in_to_cut_out_is_an_equilibrium_of_the_law(model):
    law = model.torque_control
    regions = []
    for v in np.arange(3.0, 25.01, 0.5):
        op = model.trim(v)
        regions.append(op.region)
        dx = model.derivatives(op.x, v, op.pitch, op.gen_torque)
        assert np.all(np.abs(dx[[0, 2]]) < [1e-9, 1e-9]), (v, dx)  # rotor and tower at rest
        assert op.power == pytest.approx(model.generator_efficiency * op.gen_torque * op.rotor_speed, rel=1e-12)
        if op.region == "3":
            continue
        assert op.pitch == law.fine_pitch
        if op.region == "2":
            assert op.gen_torque == pytest.approx(law.k_opt * op.rotor_speed**2, rel=1e-12)
            assert law.min_speed < op.rotor_speed < law.reference_speed
        elif op.region == "1.5":
            assert op.rotor_speed == law.min_speed and op.gen_torque < law.min_speed_torque
        else:  # the IEA 15 MW tuning reaches rated torque on K·Ω² before the reference speed
            assert op.region == "2.5s" and op.gen_torque == law.rated_torque
    # the regions in order, from cut-in to cut-out
    order = ["1.5", "2", "2.5s", "3"]
    assert [r for i, r in enumerate(regions) if i == 0 or r != regions[i - 1]] == order
    # continuous through rated in speed and torque; the pitch steps by 0.13°: just above rated
    # the pitch-regulated trim takes the root on the falling side of Cp(β) (Cp peaks at a
    # slightly positive pitch at this tip-speed ratio), as it always has
    vr = model.rated_wind_speed()
    lo, hi = model.trim(vr - 1e-6), model.trim(vr + 1e-6)
    assert lo.region == "2.5s" and hi.region == "3"
    assert abs(lo.rotor_speed - hi.rotor_speed) < 1e-6 and lo.gen_torque == hi.gen_torque
    assert 0 <= hi.pitch - lo.pitch < 0.0025


def test_above_rated_is_bitwise_the_pitch_regulated_model(model):
    bare = dataclasses.replace(model, torque_control=None)
    for v in (11.0, 15.0, 25.0):
        a, b = model.trim(v), bare.trim(v)
        assert a.region == b.region == "3"
        assert np.array_equal(a.x, b.x) and a.pitch == b.pitch and a.gen_torque == b.gen_torque
        la, lb = model.linearize(v), bare.linearize(v)
        for M in "ABCD":
            assert np.array_equal(getattr(la, M), getattr(lb, M))
    c = rosco_scheduled(model)
    kw = dict(seeds=[1], duration=30.0, transient=5.0)
    a = simulate(model, c, [13.0, 19.0], **kw)
    b = simulate(bare, c, [13.0, 19.0], **kw)
    for k in ("gen_speed", "pitch", "tower_base_my", "power"):
        assert np.array_equal(a[k], b[k])


def test_outside_cut_in_to_cut_out_is_refused(model):
    for v in (2.9, 25.1):
        with pytest.raises(ValueError, match="operating range"):
            model.trim(v)
    # a law whose minimum torque the rotor cannot give at its minimum speed: below its cut-in
    strict = dataclasses.replace(model, torque_control=dataclasses.replace(model.torque_control, min_torque=1e6))
    with pytest.raises(ValueError, match="below cut-in"):
        strict.trim(3.0)


# ----------------------------------------------------------------------------- linearisation
def test_region_2_linearisation_closes_k_omega_squared(model):
    law, v = model.torque_control, 8.5
    op = model.trim(v)
    assert op.region == "2"
    sys = model.linearize(v)
    assert sys.nstates == 5 and list(sys.input_labels) == ["wind", "pitch_cmd", "gen_torque"]
    # independent: d/dΩ of (Q(Ω) − K·Ω²)/J at the trim, by a central difference of the model
    J, h = model.drivetrain_inertia, 1e-5
    x = np.array(op.x, float)

    def f(w):
        z = x.copy()
        z[0] = w
        return model.derivatives(z, v, op.pitch, law.k_opt * w * w)[0]

    assert sys.A[0, 0] == pytest.approx((f(op.rotor_speed + h) - f(op.rotor_speed - h)) / (2 * h), rel=1e-6)
    # the torque input still acts on the rotor as a torque (−1/J)
    assert sys.B[0, 2] == pytest.approx(-1.0 / J, rel=1e-9)
    assert np.all(np.linalg.eigvals(sys.A).real < 0)


@pytest.mark.parametrize("v", [5.0, 3.5])
def test_transition_pi_holds_the_minimum_speed(model, v):
    op = model.trim(v)
    assert op.region == "1.5"
    sys = model.linearize(v)
    assert sys.nstates == 6 and list(sys.state_labels)[-1] == "torque_pi"
    assert np.all(np.linalg.eigvals(sys.A).real < 0)
    # integral action: a wind step leaves no steady speed deviation; the torque takes it
    assert abs(control.dcgain(sys["gen_speed", "wind"])) < 1e-9
    assert control.dcgain(sys["power", "wind"]) > 0


def test_linear_simulation_below_rated_follows_the_nonlinear_one(model):
    # the linearisation leaves out the speed filter (1 rad/s, above the torque loop's
    # 0.1 rad/s) and the aerodynamic nonlinearity: measured within 2-8 % in speed and tower SD
    c = rosco_scheduled(model)
    kw = dict(seeds=[1, 2], duration=600.0, turbulence_class="C")
    for v in (5.0, 8.0):
        a = simulate(model, c, [v], **kw)
        b = simulate(model, c, [v], linear=True, **kw)
        for k in ("gen_speed", "tower_base_my"):
            sa, sb = a[k].std(axis=2).mean(), b[k].std(axis=2).mean()
            assert abs(sb / sa - 1) < 0.12, (v, k, sa, sb)
        assert a["pitch_cmd"].max() == model.pitch_min  # ROSCO's pitch PI stays at fine pitch


# ----------------------------------------------------------------------------- DISCON.IN
def test_torque_law_read_from_discon_in():
    path = iea15mw_discon()
    entries, _ = read_discon(path)
    raw = {k: float(entries[k].values[0]) for k in ("VS_Rgn2K", "VS_KP", "VS_KI", "VS_MinOMSpd", "VS_RefSpd",
                                                     "VS_RtTq", "VS_ArSatTq", "VS_MaxRat", "F_SSCornerFreq")}
    assert float(entries["WE_GearboxRatio"].values[0]) == 1.0  # direct drive: no conversion
    with pytest.raises(ValueError, match=r"VS_ControlMode = 2 .*mode=3"):
        torque_law_from_discon(path)
    law = torque_law_from_discon(path, mode=1)
    assert (law.k_opt, law.kp, law.ki, law.min_speed, law.reference_speed, law.rated_torque, law.transition_torque,
            law.max_rate, law.ss_corner) == tuple(raw.values())


def test_torque_law_gearbox_conversion(tmp_path):
    # a geared turbine: speeds / N, torques × N, K × N³, gains × N²
    text = iea15mw_discon().read_text()
    text, n = re.subn(r"^\S+(\s+! WE_GearboxRatio)", r"50.0\1", text, flags=re.M)
    assert n == 1
    p = tmp_path / "DISCON.IN"
    p.write_text(text)
    a, b = torque_law_from_discon(iea15mw_discon(), mode=1), torque_law_from_discon(p, mode=1)
    assert torque_law_from_discon(write_discon(p, tmp_path / "cp.IN", VS_ConstPower=1), mode=1).const_power
    assert not b.const_power  # the IEA 15 MW's VS_ConstPower = 0
    with pytest.raises(ValueError, match="VS_ConstPower = 2 must be 0"):
        torque_law_from_discon(write_discon(p, tmp_path / "cp2.IN", VS_ConstPower=2), mode=1)
    assert b.min_speed == pytest.approx(a.min_speed / 50) and b.rated_torque == pytest.approx(a.rated_torque * 50)
    assert b.k_opt == pytest.approx(a.k_opt * 50**3) and b.kp == pytest.approx(a.kp * 50**2)
    with pytest.raises(ValueError, match="mode"):
        dataclasses.replace(a, mode=2)


def test_simulate_torque_control_options(model):
    kw = dict(seeds=[1], duration=20.0, transient=5.0)
    c = rosco_scheduled(model)
    with pytest.raises(ValueError, match="torque_control"):
        simulate(model, c, [9.0], torque_control="pi", **kw)
    with pytest.raises(ValueError, match="callable"):
        simulate(model, lambda t, y: np.zeros(1), [9.0], torque_control="rosco", **kw)
    # "auto" below rated runs the model's law, which is "rosco" there; None holds the trim torque
    a = simulate(model, c, [9.0], **kw)
    b = simulate(model, c, [9.0], torque_control="rosco", **kw)
    n = simulate(model, c, [9.0], torque_control=None, **kw)
    assert np.array_equal(a["power"], b["power"])
    tq = n["power"] / (model.generator_efficiency * n["gen_speed"])
    assert_allclose(tq, model.trim(9.0).gen_torque, rtol=1e-12)
    law = dataclasses.replace(model.torque_control, mode=3)
    assert isinstance(law, TorqueLaw)
    d = simulate(model, c, [9.0], torque_control=law, **kw)
    assert not np.array_equal(d["power"], a["power"])


# ----------------------------------------------------------------------------- ROSCO's DISCON
def _oracle_discon(tmp_path, mode):
    try:
        deck = rosco_test_cases() / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile"
    except ModuleNotFoundError as e:
        pytest.skip(f"the rosco package is not installed ({e})")
    p = write_discon(deck / "IEA-15-240-RWT-Monopile_DISCON.IN", tmp_path / f"DISCON_mode{mode}.IN",
                     VS_ControlMode=mode, PS_Mode=0)
    entries, _ = read_discon(p)
    assert Path(entries["PerfFileName"].values[0].strip('"')).is_file()
    return p


def _sds(r, model):
    omega = r["gen_speed"]
    torque = r["power"] / (model.generator_efficiency * omega)
    return {"speed": omega, "torque": torque, "pitch": r["pitch"]}


@pytest.mark.parametrize("mode, seeds", [(1, [1, 2, 3, 4]), (3, [1, 2])])
def test_compiled_torque_law_matches_roscos_discon(model, tmp_path, mode, seeds):
    path = _oracle_discon(tmp_path, mode)
    vs = [5.0, 9.0, 11.0, 13.0]
    kw = dict(seeds=seeds, duration=600.0)
    d = simulate(model, Discon(path), vs, **kw)
    s = simulate(model, rosco_scheduled(model, schedule=from_discon(path), scheduling_filter="rosco"), vs,
                 torque_control=torque_law_from_discon(path), **kw)
    for name, (a, b) in {k: (v, _sds(s, model)[k]) for k, v in _sds(d, model).items()}.items():
        sd_d, sd_s = a.std(axis=2).mean(axis=1), b.std(axis=2).mean(axis=1)
        level = np.abs(a).mean(axis=(1, 2))
        for i, v in enumerate(vs):
            if sd_d[i] > 1e-4 * level[i]:  # the acceptance: SD within 2 %
                assert abs(sd_s[i] / sd_d[i] - 1) < 0.02, (mode, name, v, sd_s[i], sd_d[i])
            else:  # held at a limit (rated torque above rated, fine pitch at 5 m/s) in both
                assert sd_s[i] <= 1e-4 * max(level[i], 1.0), (mode, name, v, sd_s[i], sd_d[i])
        assert_allclose(b.mean(axis=(1, 2)), a.mean(axis=(1, 2)), rtol=2e-3, atol=1e-6)
