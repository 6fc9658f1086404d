"""DISCON.IN read as a gain schedule (issue 15): specdesign.rosco.from_discon.

Oracles: the ROSCO gain schedule shipped as JSON (the same ROSCO tuning that wrote the
embedded DISCON.IN), the workbench's own pole placement on the reduced model, and ROSCO's
own Python reader (rosco.toolbox.utilities.read_DISCON) on the DISCON.IN files the rosco
package ships (skipped, with the reason, when rosco is not installed; CI installs it with dev).
"""
import json
from importlib import resources

import numpy as np
import pytest
from numpy.testing import assert_allclose

from specdesign.rosco import (
    DisconSchedule,
    from_discon,
    iea15mw_discon,
    read_discon,
    rosco_gain_schedule,
    rosco_scheduled,
    speed_filter,
)
from specdesign.turbine import iea15mw


@pytest.fixture(scope="module")
def schedule():
    return from_discon(iea15mw_discon())


def test_embedded_discon_is_the_shipped_rosco_schedule(schedule):
    # rosco_gain_schedule.json holds ROSCO's tuning of the same file (pitch in degrees, full precision);
    # DISCON.IN prints 6 decimals
    g = json.loads(resources.files("specdesign").joinpath("data/iea15mw/rosco_gain_schedule.json").read_text())
    assert isinstance(schedule, DisconSchedule) and schedule.version == "2.9.4"
    assert_allclose(schedule.pitch, np.deg2rad(g["pitch_op_deg"]), rtol=0, atol=6e-7)
    assert_allclose(schedule.kp, g["Kp"], rtol=0, atol=6e-7)
    assert_allclose(schedule.ki, g["Ki"], rtol=0, atol=6e-7)
    assert schedule.rated_torque == pytest.approx(g["rated_torque"], rel=1e-9)
    assert schedule.rotor_radius == g["R"]


def test_embedded_discon_agrees_with_the_workbench_pole_placement(schedule):
    # The workbench re-tunes ROSCO on its reduced model: at DISCON's scheduling pitches its gains
    # are within 1 % (1e-3 s absolute where K_p changes sign, near 22 m/s) of ROSCO's own
    m = iea15mw()
    g = rosco_gain_schedule(m)
    v = np.interp(schedule.pitch, g.pitch_op, g.v)
    inside = (v > g.v.min()) & (v < g.v.max())
    kp, ki = g.gains(v[inside])
    assert inside.sum() >= 25
    assert np.all(np.abs(kp - schedule.kp[inside]) <= np.maximum(0.01 * np.abs(schedule.kp[inside]), 1e-3))
    assert_allclose(ki, schedule.ki[inside], rtol=0.01)
    # the speed filter and the limits are the ones the workbench's ROSCO baseline uses
    assert (schedule.filter_type, schedule.filter_corner, schedule.filter_damping) == (2, 1.0081, 0.7)
    assert (schedule.pitch_min, schedule.pitch_max) == (m.pitch_min, m.pitch_max)
    assert schedule.reference_speed == m.rated_rotor_speed and schedule.gearbox_ratio == 1.0
    assert schedule.generator_efficiency == pytest.approx(m.generator_efficiency)


def test_gains_interpolate_as_rosco_and_hold_at_the_ends(schedule):
    mid = 0.5 * (schedule.pitch[3] + schedule.pitch[4])
    kp, ki = schedule.gains([schedule.pitch[0] - 0.1, mid, schedule.pitch[-1] + 0.1])
    assert kp[0] == schedule.kp[0] and kp[2] == schedule.kp[-1] and ki[2] == schedule.ki[-1]
    assert kp[1] == pytest.approx(0.5 * (schedule.kp[3] + schedule.kp[4]), rel=1e-12)


def test_rosco_scheduled_runs_a_discon_schedule(schedule):
    m = iea15mw()
    sc = rosco_scheduled(m, schedule=schedule, scheduling_filter="rosco")
    assert_allclose(sc.schedule_pitch, schedule.pitch, rtol=0, atol=0)
    assert_allclose(sc.kp, schedule.kp, rtol=0, atol=0)  # gearbox ratio 1
    w = 1j * np.array([0.1, 1.0, 5.0])
    assert_allclose(np.asarray(sc.error_filter(w), complex), np.asarray(speed_filter(1.0081, 0.7)(w), complex),
                    rtol=1e-12)
    assert sc.filter_omega == pytest.approx(0.25 * 1.0081) and sc.filter_damping == 0.7
    # the default keeps the workbench's first-order scheduling filter (documented numbers)
    default = rosco_scheduled(m, schedule=schedule)
    assert default.filter_damping is None and default.filter_omega == 0.1
    assert rosco_scheduled(m).filter_damping is None
    with pytest.raises(ValueError, match="wind_speeds must be None"):
        rosco_scheduled(m, [15.0, 20.0], schedule=schedule)
    with pytest.raises(ValueError, match="form must be 'gains'"):
        rosco_scheduled(m, schedule=schedule, form="output")
    with pytest.raises(ValueError, match="scheduling_filter"):
        rosco_scheduled(m, scheduling_filter="second")
    with pytest.raises(TypeError, match="schedule must be"):
        rosco_scheduled(m, schedule={"Kp": 1})


def _write(tmp_path, text, old, new):
    assert old in text
    p = tmp_path / "DISCON.IN"
    p.write_text(text.replace(old, new))
    return p


def test_bad_files_name_the_file_line_and_key(tmp_path):
    text = iea15mw_discon().read_text()
    lines = text.splitlines()
    ki_line = next(ln for ln in lines if "! PC_GS_KI" in ln)
    angles = next(ln for ln in lines if "! PC_GS_angles" in ln)
    cases = [
        (ki_line, "", r"key 'PC_GS_KI' is missing"),
        (ki_line, ki_line.replace("-0.120737", "", 1), r"line 57: PC_GS_KI has 29 values but PC_GS_n = 30"),
        (angles, angles.replace("0.090642", "0.01", 1), r"line 55: PC_GS_angles must strictly increase"),
        ("1.00810             ! F_LPFCornerFreq", "abc  ! F_LPFCornerFreq", r"F_LPFCornerFreq = 'abc' is not numeric"),
        ("0.034900000000      ! PC_MaxRat", "-0.1 ! PC_MaxRat", r"PC_MinRat .* must be negative"),
        ("2                   ! F_LPFType", "3 ! F_LPFType", r"F_LPFType = 3 must be 1 or 2"),
    ]
    for old, new, msg in cases:
        p = _write(tmp_path, text, old, new)
        with pytest.raises(ValueError, match=msg) as e:
            from_discon(p)
        assert str(p) in str(e.value)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        from_discon(tmp_path / "none.IN")
    entries, _ = read_discon(iea15mw_discon())
    assert entries["PC_GS_KI"].line == 57


def test_rosco_shipped_discon_files_read_as_rosco_reads_them(rosco_cases):
    utilities = pytest.importorskip("rosco.toolbox.utilities")
    files = [rosco_cases / "NREL-5MW/DISCON.IN", rosco_cases / "BAR_10/BAR_10_DISCON.IN",
             rosco_cases / "NREL_2p8_127/NREL-2p8-127_DISCON.IN",
             rosco_cases / "IEA-15-240-RWT/IEA-15-240-RWT-Monopile/IEA-15-240-RWT-Monopile_DISCON.IN"]
    for f in files:
        ref = utilities.read_DISCON(str(f))
        s = from_discon(f)
        assert s.version == "2.10.6"
        assert_allclose(s.pitch, ref["PC_GS_angles"], rtol=0, atol=0)
        assert_allclose(s.kp, ref["PC_GS_KP"], rtol=0, atol=0)
        assert_allclose(s.ki, ref["PC_GS_KI"], rtol=0, atol=0)
        for attr, key in (("filter_corner", "F_LPFCornerFreq"), ("reference_speed", "PC_RefSpd"),
                          ("gearbox_ratio", "WE_GearboxRatio"), ("rated_torque", "VS_RtTq"), ("pitch_max", "PC_MaxPit"),
                          ("pitch_rate_max", "PC_MaxRat"), ("filter_type", "F_LPFType")):
            assert getattr(s, attr) == ref[key], (f.name, key)
    # the NREL 5 MW: geared (97:1), first-order speed filter at 1.5708 rad/s (ROSCO's tuning)
    nrel = from_discon(files[0])
    assert (nrel.gearbox_ratio, nrel.filter_type, nrel.filter_corner) == (97.0, 1, 1.5708)
    with pytest.raises(ValueError, match="PC_RefSpd / WE_GearboxRatio = 1.26711 rad/s .* another turbine"):
        rosco_scheduled(iea15mw(), schedule=nrel)
