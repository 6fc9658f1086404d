"""A Python MPC in the real OpenFAST v5.0 through the forwarding DISCON library
(specdesign.export.forwarded): a short run of the IEA 15 MW monopile deck at 19 m/s.

OpenFAST comes from the ``openfast`` fixture (tests/conftest.py): skipped when none is found,
unless ``SPECDESIGN_REQUIRE_OPENFAST=1`` (then it fails). Cost: 30 s of simulated time, ~45 s
of OpenFAST CPU plus the MPC's setup (~15 s).
"""
import numpy as np
import pytest

pytest.importorskip("openfast_io")

from specdesign.export import ForwardServer, forwarded
from specdesign.mpc import QuadraticMPC
from specdesign.openfast import iea15mw_monopile, run_case, write_case
from specdesign.turbine import iea15mw


def _mpc(model):
    return QuadraticMPC(model, ts=0.1, operating_point="initial pitch")


def test_quadratic_mpc_runs_in_openfast_through_the_forwarder(openfast, tmp_path):
    model = iea15mw()
    fwd = forwarded(_mpc(model), dt=0.02, model=model, pitch_rate_limit=model.pitch_rate_limit)
    op = model.trim(19.0)
    with ForwardServer(fwd, record=True) as srv:
        case = write_case(iea15mw_monopile(), tmp_path / "mpc19", tmax=30.0, wind_speed=19.0, library=fwd.library,
                          parameters=srv.write(tmp_path / "fwd.IN"), controller_dt=fwd.dt, dt_out=0.05,
                          initial_pitch=op.pitch, initial_rotor_speed=op.rotor_speed)
        out = run_case(case, openfast)
    assert srv.error is None and srv.finished
    # ServoDyn calls DISCON at t = 0 twice (status 0, then 1) and every DLL_DT to TMax
    assert srv.calls == pytest.approx(30.0 / 0.02 + 2, abs=1)
    for name, x in out.channels.items():
        assert np.all(np.isfinite(x)), name
    pitch = out.channels["BldPitch1"]
    assert np.all(pitch >= model.pitch_min - 1e-6) and np.all(pitch <= model.pitch_max + 1e-6)
    late = out.time > 15.0
    # above rated the MPC holds the speed near rated (the reduced model's, direct drive)
    assert abs(np.mean(out.channels["GenSpeed"][late]) / model.rated_rotor_speed - 1) < 0.05
    # the measurements as the server read them: rotor speed near rated, the blades' out-of-plane
    # moment positive (downwind) as the reduced model's blade_root_my
    y = {k: np.array([r[1][k] for r in srv.records]) for k in srv.records[0][1]}
    assert abs(np.mean(y["gen_speed"]) / model.rated_rotor_speed - 1) < 0.05
    assert np.mean(y["blade_root_my"]) > 0
    # the forwarder's commands: the MPC's own on the same measured signals, stepped directly
    direct = _mpc(model)
    direct.start(*srv.started)
    again = np.array([float(direct(t, {k: np.array([v]) for k, v in yk.items()})[0]) for t, yk, _, _ in srv.records])
    assert np.array_equal(again, np.array([r[2] for r in srv.records]))
