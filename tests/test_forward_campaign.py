"""Forwarded Python controllers in OpenFAST campaigns, with a fake OpenFAST that calls the real
forwarding library through ctypes as ServoDyn does (status 0, then 1 every DLL_DT, then −1) and
writes the commanded pitch as its BldPitch1: the campaign's pitch series is the Python
controller's command, a Python exception fails its run with the case, seed and traceback while
the other runs are kept, and the store resumes and refuses another controller under a stored name.
"""
import math

import numpy as np
import pytest

pytest.importorskip("openfast_io")

from specdesign.export import forwarded
from specdesign.openfast import iea15mw_monopile
from specdesign.turbine import iea15mw
from specdesign.validate.openfast_campaign import run_openfast_campaign

# The fake OpenFAST: ServoDyn's calls of DISCON (the swap records forward.c and the server read),
# then a binary .outb (file ID 3) of the campaign's channels, BldPitch1 the commanded pitch (deg).
_FAKE = '''\
    k = keys(fst); sd = keys(k["ServoFile"])
    dt, tmax, ddt = float(k["DT_Out"]), float(k["TMax"]), float(sd["DLL_DT"])
    fn = ctypes.CDLL(sd["DLL_FileName"]).DISCON
    fn.restype = None
    sw = np.zeros(1000, np.float32); fail = ctypes.c_int(0); msg = ctypes.create_string_buffer(1025)
    infile = sd["DLL_InFile"].encode() + b"\\0"
    sw[2], sw[3], sw[19], sw[22], sw[26], sw[48], sw[49] = ddt, 0.25, 0.79, 2e7, 19.0, 1024, len(infile)
    n = int(round(tmax / ddt)) + 1
    cmd = np.empty(n)
    for i in range(n):
        sw[0], sw[1] = (0 if i == 0 else 1), i * ddt
        fn(sw.ctypes.data_as(ctypes.c_void_p), ctypes.byref(fail), infile, b"out\\0", msg)
        if fail.value < 0:
            print("DISCON: " + msg.value.decode(errors="replace"))
            print("Aborting OpenFAST.")
            sys.exit(1)
        cmd[i] = sw[44]
    sw[0] = -1
    fn(sw.ctypes.data_as(ctypes.c_void_p), ctypes.byref(fail), infile, b"out\\0", msg)
    t = np.arange(int(round(tmax / dt)) + 1) * dt
    pitch = np.interp(t, np.arange(n) * ddt, cmd)
    ch = {{"Wind1VelX": ("(m/s)", 19 + 0 * t), "BldPitch1": ("(deg)", np.degrees(pitch)),
          "RotSpeed": ("(rpm)", 7.56 + 0 * t), "GenSpeed": ("(rpm)", 7.56 + 0.2 * np.sin(t)),
          "GenTq": ("(kN-m)", 2e4 + 0 * t), "GenPwr": ("(kW)", 1.5e4 + 0 * t),
          "TwrBsMyt": ("(kN-m)", 1e5 + 2e4 * np.sin(1.1 * t)), "RootMyb1": ("(kN-m)", 3e4 + 8e3 * np.sin(0.8 * t)),
          "YawBrTAxp": ("(m/s^2)", 0.1 * np.sin(t))}}
'''


@pytest.fixture
def fake(fake_openfast):
    return fake_openfast(_FAKE)


class Sine:
    """β = β₀ + a·sin(t) (rad), β₀ the pitch at the start."""

    def __init__(self, a):
        self.a = a

    def start(self, dt, wind, pitch, torque):
        self.beta0 = pitch.copy()

    def __call__(self, t, y):
        return self.beta0 + self.a * math.sin(t)


class Failing(Sine):
    def __call__(self, t, y):
        if t > 1.0:
            raise ZeroDivisionError("the controller's own error")
        return self.beta0


def test_forwarded_controllers_in_a_campaign(tmp_path, fake):
    inst, calls = fake
    model = iea15mw()
    ctrls = {"fwd": forwarded(Sine(0.01), dt=0.02, model=model), "bad": forwarded(Failing(0.0), dt=0.02, model=model)}
    kw = dict(deck=iea15mw_monopile(), duration=20.0, transient=5.0, record_dt=0.05, install=inst, processes=2,
              folder=tmp_path / "camp", initial_conditions=False, keep_series=1)
    with pytest.warns(RuntimeWarning, match=r"(?s)bad at 19 m/s, seed 0: the Python controller 'Failing' failed.*"
                                            r"ZeroDivisionError: the controller's own error"):
        camp = run_openfast_campaign(ctrls, [19.0], [0], **kw)
    assert camp.unstable.tolist() == [[False], [True]]
    assert "ZeroDivisionError" in (tmp_path / "camp" / "failures.txt").read_text()
    # the pitch OpenFAST applied is the Python command: 0.25 + 0.01 sin(t), through float32
    t = 5.0 + np.arange(400) * 0.05
    pitch = camp.series["fwd"].outputs["pitch"][0, 0]
    np.testing.assert_allclose(pitch, 0.25 + 0.01 * np.sin(t), atol=1e-6)
    n_calls = len(calls.read_text().split())
    assert n_calls == 2
    # resumed: the finished run is read back, the failed one runs again
    with pytest.warns(RuntimeWarning, match="ZeroDivisionError"):
        run_openfast_campaign(ctrls, [19.0], [0], **kw)
    assert calls.read_text().split().count("fwd_19mps_seed0") == 1
    # another Python controller under a stored name is refused
    with pytest.raises(ValueError, match="another controller under the name 'fwd'"):
        run_openfast_campaign({"fwd": forwarded(Sine(0.02), dt=0.02, model=model)}, [19.0], [0], **kw)


def test_a_forwarded_controller_runs_as_itself_on_the_reduced_model(tmp_path):
    # one controllers dict serves both plants: on the reduced model the wrapper runs the
    # controller it wraps, the same indicators as the bare controller and the same store entry
    from specdesign.validate import run_campaign

    model = iea15mw()
    kw = dict(model=model, duration=20.0, transient=5.0, predict=False)
    bare = run_campaign({"sine": Sine(0.01)}, [19.0], [1], **kw, store=tmp_path / "store")
    wrapped = run_campaign({"sine": forwarded(Sine(0.01), model=model)}, [19.0], [1], **kw, store=tmp_path / "store")
    for k, v in bare.values.items():
        np.testing.assert_array_equal(wrapped.values[k], v, err_msg=k)
