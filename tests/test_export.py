"""The exported DISCON library (specdesign.export) against the Python controller it was exported from.

Tolerances. The library talks through avrSWAP, a float32 array: each step the generator speed
it reads and the pitch and torque it writes are rounded to float32, a relative error of at
most EPS32 = 2**-24 ≈ 6e-8 (the library computes in double, on the same discrete matrices as
the simulator, in the same order). Those roundings enter a stable closed loop every step and
stay bounded: the pitch differs by about EPS32·β directly, plus the controller's direct gain
times EPS32·Ω (the 19 m/s QFT design's |D| is ~5 rad per rad/s, so ~10× EPS32·β), plus what the
loop makes of both. The tests allow 100·EPS32 of each signal's largest value (3e-6 rad of
pitch; measured 1.6e-8 for ROSCO's PI and 1.9e-7 for the QFT design) and 1e-5 relative on
the tower DEL (measured ~1e-7). A design with an ATD loop sees one more difference: the
library integrates the measured tower-top acceleration (avrSWAP(53); the Bladed interface has
no velocity) by the trapezoid rule, where the Python controller reads the plant's velocity;
that tolerance is derived from the integration error measured on the Python run itself.
"""
import ctypes
import dataclasses
import fnmatch
import math
import pickle
import shutil
import subprocess
import sys
import tomllib
import warnings
from pathlib import Path

import control as ct
import numpy as np
import pytest

from specdesign.export import (
    DisconParameters,
    discon_library,
    discon_parameters,
    export_discon,
    read_parameters,
    write_parameters,
)
from specdesign.export.library import SOURCE, CompilerNotFoundError
from specdesign.fatigue import del_rainflow
from specdesign.rosco import Discon, rosco_scheduled
from specdesign.simulate import ScheduledController, scheduled, simulate
from specdesign.controller.scheduled import controller_bank
from specdesign.turbine import iea15mw, rosco_baseline

EPS32 = 2.0**-24
DURATION, TRANSIENT = 60.0, 10.0
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def qft19(model):
    from specdesign import qft

    # a design with a slow mode besides its integrator, so that the export's conditional
    # integration of slow states is exercised: the 25 % design without the high-frequency gain
    # bound has a pole at −0.019 rad/s (< SLOW_OMEGA = 0.1 rad/s); the bounded default's slowest
    # besides the integrator is a pair at 0.18 rad/s (clamped integrator only)
    return qft.design_qft(model, 19.0, max_hf_gain_ratio=None)


def _runs(model, python_controller, record, speeds, **python_kw):
    kw = dict(seeds=[1], duration=DURATION, transient=TRANSIENT)
    a = simulate(model, python_controller, speeds, **kw, **python_kw)
    b = simulate(model, Discon(record.parameters, library=record.library), speeds, **kw)
    return a, b


def _assert_equal_records(a, b, scale=1.0, del_rtol=1e-5):
    """Every record within scale·100·EPS32 of its largest value, the tower DEL within del_rtol."""
    for name in ("pitch_cmd", "pitch", "gen_speed", "power", "tower_base_my"):
        x, y = a[name], b[name]
        tol = scale * 100 * EPS32 * np.abs(x).max()
        assert np.abs(x - y).max() <= tol, (name, np.abs(x - y).max(), tol)
    for i in range(a.wind_speeds.size):
        da = del_rainflow(a["tower_base_my"][i, 0], 4, DURATION)
        db = del_rainflow(b["tower_base_my"][i, 0], 4, DURATION)
        assert db == pytest.approx(da, rel=del_rtol)


def test_rosco_pi_exported_equals_python(model, tmp_path):
    c = rosco_baseline(model, 19.0)
    rec = export_discon(c, tmp_path, model=model, torque="constant")
    assert rec.library.is_file() and rec.parameters.is_file() and rec.torque == "constant"
    a, b = _runs(model, c, rec, [19.0])
    _assert_equal_records(a, b)
    # a campaign's worker gets the harness pickled: it stays an exported controller
    again = pickle.loads(pickle.dumps(Discon(rec.parameters, library=rec.library)))
    assert again.exported and again.gearbox_ratio == 1.0
    # the float32 interface is visible: the two are not bit for bit the same
    assert np.abs(a["pitch_cmd"] - b["pitch_cmd"]).max() > 0


def test_qft_19_design_exported_equals_python(model, qft19, tmp_path):
    assert qft19.success
    rec = export_discon(qft19, tmp_path, model=model, torque="constant")
    python = ScheduledController(np.zeros(1), (ct.tf(qft19.pitch_controller),), None, name="QFT")
    # at 19 m/s, and at 10.8 m/s where the command reaches the pitch floor: the conditional
    # integration of the design's integrator and slow mode (slow_states > 0) is exercised
    assert read_parameters(rec.parameters).slow_states[0] > 0
    a, b = _runs(model, python, rec, [10.8, 19.0])
    assert (a["pitch_cmd"][0] == model.pitch_min).any() and (b["pitch_cmd"][0] == model.pitch_min).any()
    _assert_equal_records(a, b)


def test_output_blended_schedule_exported_equals_python(model, tmp_path):
    # four locals blended in the filtered pitch, each integrator clamped (PI-like locals)
    sc = scheduled(model, {v: rosco_baseline(model, v) for v in (13.0, 17.0, 21.0, 25.0)})
    rec = export_discon(sc, tmp_path, model=model, torque="constant")
    assert read_parameters(rec.parameters).schedule_pitch.size == 4
    a, b = _runs(model, sc, rec, [12.0, 14.0, 18.0, 23.0])
    _assert_equal_records(a, b)


def test_rosco_scheduled_gains_and_torque_law_exported_equal_python(model, tmp_path):
    # ROSCO's form (one PI, gains interpolated in the filtered pitch, its clamps), ROSCO's torque
    # law with its state machine and setpoint smoother, below rated (pitch at its floor: the
    # anti-windup), near rated and above
    sc = rosco_scheduled(model, scheduling_filter="rosco")
    rec = export_discon(sc, tmp_path, model=model, torque="rosco")
    a, b = _runs(model, sc, rec, [9.0, 13.0, 19.0], torque_control="rosco")
    assert a["pitch_cmd"][0].min() == model.pitch_min  # at 9 m/s the command sits on its limit
    _assert_equal_records(a, b)


def test_rosco_power_exported_equals_the_simulators_constant_power_law(model, tmp_path):
    # ROSCO's law with VS_ConstPower = 1 (issue 27): the library's torque_mode 3 and the
    # simulator's torque_step with const_power, below rated, near rated and above
    sc = rosco_scheduled(model, scheduling_filter="rosco")
    law = dataclasses.replace(model.torque_control, const_power=True)
    rec = export_discon(sc, tmp_path, model=model, torque="rosco_power")
    assert rec.torque == "rosco_power" and read_parameters(rec.parameters).torque_law[-1] == 1.0
    # a constant-power law given as such, or the law of the model, exports as rosco_power too
    assert export_discon(sc, tmp_path / "law", model=model, torque=law).torque == "rosco_power"
    cp_model = dataclasses.replace(model, torque_control=law)
    assert export_discon(sc, tmp_path / "m", model=cp_model).torque == "rosco_power"
    assert export_discon(sc, tmp_path / "r", model=cp_model, torque="rosco").torque == "rosco_power"
    a, b = _runs(model, sc, rec, [9.0, 13.0, 19.0], torque_control=law)
    _assert_equal_records(a, b)
    # constant power above rated changes the records: the comparison can fail
    held = simulate(model, sc, [19.0], seeds=[1], duration=DURATION, transient=TRANSIENT, torque_control="rosco")
    assert np.abs(held["power"][0] - a["power"][2]).max() > 1e3 * 100 * EPS32 * np.abs(a["power"]).max()


def test_hinf_design_with_atd_exported_equals_python(model, tmp_path):
    from specdesign.hinf import design_hinf

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="the given specifications are not met", category=RuntimeWarning)
        h = design_hinf(model, 19.0, measurements=("gen_speed", "tower_top_vel"))
    assert h.atd_controller is not None and h.atd_controller.nstates > 0
    rec = export_discon(h, tmp_path, model=model, torque="constant")
    python = ScheduledController(np.zeros(1), (h.pitch_controller,), (h.atd_controller,), name="Hinf")
    a, b = _runs(model, python, rec, [19.0])
    # the library's velocity: the trapezoid integral of the acceleration, whose error against the
    # plant's velocity is measured here on the Python run (recorded every step)
    r = simulate(model, python, [19.0], seeds=[1], duration=DURATION + TRANSIENT, transient=0.0, record_dt=0.02)
    acc, vel = r["tower_top_acc"][0, 0], r["tower_top_vel"][0, 0]
    integral = np.concatenate([[0.0], np.cumsum(0.01 * (acc[1:] + acc[:-1]))])
    dv = np.abs(integral - vel).max()
    assert 0 < dv < 1e-3 * np.abs(vel).max()
    # the pitch that velocity error makes through the ATD controller (open loop), ×10 for the loop
    t = np.arange(acc.size) * 0.02
    dbeta = ct.forced_response(h.atd_controller, t, integral - vel).outputs
    extra = 10 * float(np.abs(dbeta).max())
    # every record's tolerance widened in the ratio of that pitch error to the float32 one
    scale = 1 + extra / (100 * EPS32 * float(np.abs(a["pitch_cmd"]).max()))
    _assert_equal_records(a, b, scale=scale, del_rtol=scale * 1e-5)


def test_parameter_file_round_trips_the_simulators_matrices(model, qft19, tmp_path):
    rec = export_discon(qft19, tmp_path, model=model)
    p = read_parameters(rec.parameters)
    assert p.same(discon_parameters(qft19, model=model))
    # the very matrices the simulator runs (controller_bank at the same dt), bit for bit
    python = ScheduledController(np.zeros(1), (ct.tf(qft19.pitch_controller),), None)
    _, mats, _, pi = controller_bank(python, 0.02)
    A, B, C, D, r, ns = mats[0]
    n = A.shape[0]
    assert pi is None and p.A.shape == (1, n, n)
    assert p.A[0].tobytes() == A.tobytes() and p.B[0].tobytes() == np.ascontiguousarray(B).tobytes()
    assert p.C[0].tobytes() == C.tobytes() and p.D[0].tobytes() == D.tobytes()
    assert p.integrator_gain[0] == r and p.slow_states[0] == ns
    # the ROSCO form's PI part and torque law too
    sc = rosco_scheduled(model)
    q = discon_parameters(sc, model=model)
    write_parameters(q, tmp_path / "rosco.IN")
    back = read_parameters(tmp_path / "rosco.IN")
    assert back.same(q) and back.pi_kp is not None and back.torque_mode == 2
    assert not back.same(discon_parameters(sc, model=model, dt=0.01))



def test_response_change_compares_what_the_controller_does_not_its_realisation(model):
    # the report's test of "runs of this code's design" (benchmarks/openfast_report.py
    # SAME_DESIGN_RTOL): a controller is compared by its discrete responses, so an equivalent
    # realisation is 0 apart, a gain change of 1e-7 is 1e-7 apart (the responses are linear in it),
    # and anything else than the controller (here the sample time) is another export
    c = ct.tf([-2.0, -0.9, -0.1], [1.0, 1.2, 0.0]) * ct.tf([1.0], [0.2, 1.0])
    p = discon_parameters(c, model=model)
    assert p.response_change(p) == 0.0
    T = np.array([[2.0, 1.0, 0.0], [0.0, 1.0, 3.0], [1.0, 0.0, 1.0]])[: p.A.shape[1], : p.A.shape[1]]
    Ti = np.linalg.inv(T)
    similar = dataclasses.replace(p, A=np.array([T @ a @ Ti for a in p.A]), B=np.array([T @ b for b in p.B]),
                                  C=np.array([c_ @ Ti for c_ in p.C]))
    assert not similar.same(p)
    # the realisation's round-off: the similarity transform's condition number times eps
    assert p.response_change(similar) < 1e3 * np.linalg.cond(T) * np.finfo(float).eps
    nudged = dataclasses.replace(p, C=p.C * (1 + 1e-7), D=p.D * (1 + 1e-7))
    assert p.response_change(nudged) == pytest.approx(1e-7, rel=1e-3)
    assert p.response_change(dataclasses.replace(p, integrator_gain=p.integrator_gain * 1.01)) == pytest.approx(0.01)
    assert p.response_change(discon_parameters(c, model=model, dt=0.01)) == math.inf

# ----------------------------------------------------------------------------- the library through ctypes
def _swap(dt=0.02, infile=b"", pitch=0.3, speed=0.79, torque=1.9e7, power=1.5e7, acc=0.0):
    sw = np.zeros(300, dtype=np.float32)
    sw[1], sw[2], sw[3] = 0.0, dt, pitch
    sw[14], sw[19], sw[20], sw[22], sw[52] = power, speed, speed, torque, acc
    sw[48], sw[49] = 1024, len(infile) + 1
    return sw


def _call(lib, sw, infile, status):
    fn = ctypes.CDLL(str(lib)).DISCON
    fn.restype = None
    fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p, ctypes.c_char_p]
    fail = ctypes.c_int(0)
    msg = ctypes.create_string_buffer(1025)
    sw[0] = status
    fn(sw.ctypes.data, ctypes.addressof(fail), infile + b"\0", b"run\0", msg)
    return fail.value, msg.value.decode()


def _fresh(lib, tmp_path, tag):
    # one library copy per test: its state (one struct per loaded library) starts clean
    copy = tmp_path / f"lib_{tag}{lib.suffix}"
    copy.write_bytes(lib.read_bytes())
    return copy


def test_bad_parameter_file_fails_with_its_name_and_line(model, tmp_path):
    rec = export_discon(rosco_baseline(model, 19.0), tmp_path, model=model)
    lib = _fresh(rec.library, tmp_path, "bad")
    missing = str(tmp_path / "nowhere.IN").encode()
    fail, msg = _call(lib, _swap(infile=missing), missing, 0)
    assert fail < 0 and "nowhere.IN" in msg
    lines = rec.parameters.read_text().splitlines()
    i = next(k for k, s in enumerate(lines) if s.startswith("rated_speed"))
    lines[i] = "rated_speed fast"
    bad = tmp_path / "bad.IN"
    bad.write_text("\n".join(lines) + "\n")
    fail, msg = _call(lib, _swap(infile=str(bad).encode()), str(bad).encode(), 0)
    assert fail < 0 and f"bad.IN:{i + 1}:" in msg and "'fast' is not a number (for 'rated_speed')" in msg
    with pytest.raises(ValueError, match=rf"bad.IN:{i + 1}: 'fast' is not a number"):
        read_parameters(bad)
    # a ROSCO DISCON.IN is not this library's file; the wrong call interval is refused
    rosco_in = tmp_path / "DISCON.IN"
    rosco_in.write_text("! Controller parameter input file\n0  ! LoggingLevel\n")
    fail, msg = _call(lib, _swap(infile=str(rosco_in).encode()), str(rosco_in).encode(), 0)
    assert fail < 0 and "DISCON.IN:1: not a specdesign DISCON parameter file" in msg
    good = str(rec.parameters).encode()
    fail, msg = _call(lib, _swap(dt=0.005, infile=good), good, 0)
    assert fail < 0 and "dt = 0.02 s" in msg and "every 0.005" in msg
    # and a step before any initialisation
    fail, msg = _call(_fresh(rec.library, tmp_path, "noinit"), _swap(), good, 1)
    assert fail < 0 and "before its initialisation" in msg
    # through the harness: a ValueError naming the file
    with pytest.raises(ValueError, match="refused its parameter file.*bad.IN:"):
        simulate(model, Discon(bad, library=rec.library), [19.0], seeds=[1], duration=1.0, transient=0.0)


def test_first_command_is_bumpless_and_serves_openfast_records(model, tmp_path):
    rec = export_discon(rosco_baseline(model, 19.0), tmp_path, model=model, torque="constant", gearbox_ratio=2.0)
    lib = _fresh(rec.library, tmp_path, "bump")
    infile = str(rec.parameters).encode()
    sw = _swap(infile=infile, pitch=0.25, speed=2.0 * model.rated_rotor_speed)
    assert _call(lib, sw, infile, 0) == (0, "")
    # at the reference speed the first command is the measured pitch (float32), the torque the
    # rated torque on the generator side (divided by the gearbox ratio)
    assert sw[44] == np.float32(0.25) and sw[41] == sw[42] == sw[43] == sw[44]
    assert sw[46] == np.float32(model.rated_generator_torque / 2.0)
    assert sw[34] == 1 and sw[35] == 0 and sw[54] == 0 and sw[55] == 0 and sw[64] == 0 and sw[101] == 0
    assert _call(lib, sw, infile, 1)[0] == 0 and _call(lib, sw, infile, -1)[0] == 0


def test_constant_power_torque(model, tmp_path):
    rec = export_discon(rosco_baseline(model, 19.0), tmp_path, model=model, torque="power")
    assert read_parameters(rec.parameters).torque_mode == 1
    lib = _fresh(rec.library, tmp_path, "power")
    infile = str(rec.parameters).encode()
    speed = np.float32(1.05 * model.rated_rotor_speed)
    sw = _swap(infile=infile, speed=float(speed))
    for status in (0, 1, 1):
        assert _call(lib, sw, infile, status)[0] == 0
    # the speed filter starts at its input: at a constant speed T = P/(η·Ω) at once
    expected = model.rated_power / (model.generator_efficiency * float(speed))
    assert sw[46] == pytest.approx(expected, rel=EPS32 * 4)


def test_rosco_law_with_constant_power_in_region_3(model, tmp_path):
    # ROSCO's VS_ConstPower = 1 (Controllers.f90): in region 3 (pitch above PC_Switch) the torque
    # is P/(η·Ω_f), the speed filter starting at its input; without it, the rated torque
    law = model.torque_control
    speed = np.float32(1.05 * model.rated_rotor_speed)
    out = {}
    for torque in ("rosco", "rosco_power"):
        rec = export_discon(rosco_baseline(model, 19.0), tmp_path / torque, model=model, torque=torque)
        lib = _fresh(rec.library, tmp_path, torque)
        infile = str(rec.parameters).encode()
        sw = _swap(infile=infile, speed=float(speed), pitch=0.3, power=law.rated_power)
        for status in (0, 1):
            assert _call(lib, sw, infile, status)[0] == 0
        out[torque] = float(sw[46])
    assert out["rosco"] == np.float32(law.rated_torque)
    expected = law.rated_power / law.generator_efficiency / float(speed)
    assert expected < law.rated_torque and out["rosco_power"] == pytest.approx(expected, rel=4 * EPS32)


def test_pitch_rate_limit_limits_the_command(model, tmp_path):
    rec = export_discon(rosco_baseline(model, 19.0), tmp_path, model=model, pitch_rate_limit=0.01)
    lib = _fresh(rec.library, tmp_path, "rate")
    infile = str(rec.parameters).encode()
    sw = _swap(infile=infile, pitch=0.3)
    _call(lib, sw, infile, 0)
    sw[19] = sw[20] = 1.5 * model.rated_rotor_speed  # a large overspeed: the PI asks for much more pitch
    cmds = []
    for _ in range(200):  # 4 s: the speed filter and the PI then ask for far more than 0.01 rad/s
        _call(lib, sw, infile, 1)
        cmds.append(float(sw[44]))
    steps = np.diff(cmds)
    # at most 0.01 rad/s × 0.02 s per step (float32 rounding of ~0.3 rad aside), and at it at the end
    assert steps.max() <= 0.01 * 0.02 + 2 * EPS32 * 0.4
    assert steps[-1] == pytest.approx(0.01 * 0.02, abs=2 * EPS32 * 0.4)


def test_library_is_compiled_once_and_shipped(tmp_path, monkeypatch):
    lib = discon_library(cache=tmp_path)
    stamp = lib.stat().st_mtime_ns
    assert discon_library(cache=tmp_path) == lib and lib.stat().st_mtime_ns == stamp
    assert lib.parent.name and len(lib.parent.name) == 16
    # nothing of Python at run time: the C library and libm only (what ldd lists, where it exists)
    ldd = shutil.which("ldd")
    if ldd is not None and sys.platform.startswith("linux"):
        needed = subprocess.run([ldd, str(lib)], capture_output=True, text=True, check=True).stdout
        assert "libc.so" in needed and "python" not in needed.lower()
    monkeypatch.delenv("CC", raising=False)
    with pytest.raises(CompilerNotFoundError, match="no C compiler 'no-such-cc'"):
        discon_library(cache=tmp_path / "other", compiler="no-such-cc")
    # the source is package data: a wheel carries it
    with open(ROOT / "pyproject.toml", "rb") as f:
        patterns = tomllib.load(f)["tool"]["setuptools"]["package-data"]["specdesign"]
    rel = SOURCE.relative_to(ROOT / "specdesign").as_posix()
    assert any(fnmatch.fnmatch(rel, p) for p in patterns)


def test_a_library_in_use_is_never_rewritten_in_place(model, tmp_path):
    """An export into a folder whose library a running OpenFAST has mapped (a campaign exporting
    beside a running one) must not truncate that file: the same library is left alone (same inode,
    same mtime), another one is renamed over it (a new inode; the old file stays whole for its reader)."""
    c = rosco_baseline(model, 19.0)
    lib = export_discon(c, tmp_path, model=model).library
    before = lib.stat()
    assert export_discon(c, tmp_path, model=model, name="again").library == lib
    assert (lib.stat().st_ino, lib.stat().st_mtime_ns) == (before.st_ino, before.st_mtime_ns)
    lib.unlink()
    lib.write_bytes(b"another build")  # stands for the library of another source digest, in use
    with open(lib, "rb") as reader:
        export_discon(c, tmp_path, model=model)
        assert reader.read() == b"another build"
    assert lib.read_bytes() == discon_library().read_bytes()
    assert not list(tmp_path.glob(".*.tmp"))


def test_bad_arguments(model, tmp_path):
    c = rosco_baseline(model, 19.0)
    with pytest.raises(TypeError, match="controller_or_design"):
        export_discon(lambda t, y: 0.0, tmp_path)
    with pytest.raises(ValueError, match="torque="):
        export_discon(c, tmp_path, torque="fast")
    with pytest.raises(ValueError, match="pitch_rate_limit"):
        export_discon(c, tmp_path, pitch_rate_limit=0.0)
    with pytest.raises(ValueError, match="dt"):
        export_discon(c, tmp_path, dt=-1.0)
    with pytest.raises(ValueError, match="atd_highpass"):
        export_discon(c, tmp_path, atd_highpass=math.nan)
    assert isinstance(discon_parameters(c, model=model), DisconParameters)
