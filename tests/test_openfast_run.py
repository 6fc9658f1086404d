"""The shipped IEA 15 MW monopile deck in the real OpenFAST v5.0 with ROSCO's compiled DISCON:
a short run at 19 m/s (steady wind, then a small campaign on a TurbSim field), checked against
the turbine's own limits.

Skipped when no OpenFAST is found (``specdesign.openfast.find_openfast``), unless
``SPECDESIGN_REQUIRE_OPENFAST=1`` (CI sets it after building OpenFAST): then a missing OpenFAST
fails. Cost: about 60 s of simulated time in all, ~80 s of CPU.
"""
import math
import os

import numpy as np
import pytest

pytest.importorskip("openfast_io")
pytest.importorskip("rosco")

from specdesign.openfast import OpenFASTNotFound, find_openfast, iea15mw_monopile, run_case, write_case
from specdesign.rosco.discon import rosco_library


@pytest.fixture(scope="module")
def install():
    try:
        return find_openfast()
    except OpenFASTNotFound as e:
        if os.environ.get("SPECDESIGN_REQUIRE_OPENFAST") == "1":
            pytest.fail(f"SPECDESIGN_REQUIRE_OPENFAST=1 but no OpenFAST: {e}")
        pytest.skip(f"no OpenFAST: {e}")


def _discon():
    deck = iea15mw_monopile()
    return deck, deck.fst.with_name(f"{deck.name}_DISCON.IN")


def _discon_value(discon_in, key):
    """A number of a DISCON.IN ("value ! Key - description" lines)."""
    for ln in discon_in.read_text().splitlines():
        t = ln.split()
        if len(t) > 2 and t[1] == "!" and t[2] == key:
            return float(t[0])
    raise KeyError(key)


def test_rosco_runs_the_shipped_deck_at_19_mps(install, tmp_path):
    deck, discon_in = _discon()
    # 19 m/s trim of the reduced model (docs/openfast.md): pitch and rotor speed to start near
    case = write_case(deck, tmp_path / "rosco19", tmax=30.0, wind_speed=19.0, library=rosco_library(),
                      parameters=discon_in, dt_out=0.05, initial_pitch=math.radians(15.5),
                      initial_rotor_speed=0.7917)
    out = run_case(case, install)
    for name, x in out.channels.items():
        assert np.all(np.isfinite(x)), name
    assert out.time[-1] == pytest.approx(30.0)
    lo, hi, rate = (_discon_value(discon_in, k) for k in ("PC_MinPit", "PC_MaxPit", "PC_MaxRat"))
    pitch = out.channels["BldPitch1"]
    assert np.all(pitch >= lo - 1e-6) and np.all(pitch <= hi + 1e-6)
    # pitch rate within the actuator's limit (ROSCO saturates its command at PC_MaxRat)
    assert np.max(np.abs(np.diff(pitch) / np.diff(out.time))) <= rate * 1.05
    # above rated ROSCO holds the generator near its reference speed (PC_RefSpd, rad/s)
    late = out.time > 15.0
    ref = _discon_value(discon_in, "PC_RefSpd")
    assert abs(np.mean(out.channels["GenSpeed"][late]) / ref - 1) < 0.05
    # pitched well away from fine pitch at 19 m/s (the reduced model trims at 0.27 rad)
    assert 0.15 < np.mean(pitch[late]) < 0.4


def test_exported_design_runs_in_openfast(install, tmp_path):
    """The workbench's 19 m/s ROSCO-form PI (the LTI baseline), exported as a DISCON library
    (issue 27's export), runs unchanged in ServoDyn: finite outputs, pitch within the model's
    limits, the generator held near rated speed."""
    export = pytest.importorskip("specdesign.export")
    from specdesign.turbine import iea15mw, rosco_baseline

    model = iea15mw()
    rec = export.export_discon(rosco_baseline(model, 19.0), tmp_path / "export", model=model, dt=0.01,
                               torque="power", pitch_rate_limit=model.pitch_rate_limit, atd_highpass=0.05)
    op = model.trim(19.0)
    case = write_case(iea15mw_monopile(), tmp_path / "export19", tmax=30.0, wind_speed=19.0, library=rec.library,
                      parameters=rec.parameters, controller_dt=rec.dt, dt_out=0.05, initial_pitch=op.pitch,
                      initial_rotor_speed=op.rotor_speed)
    out = run_case(case, install)
    for name, x in out.channels.items():
        assert np.all(np.isfinite(x)), name
    pitch = out.channels["BldPitch1"]
    assert np.all(pitch >= model.pitch_min - 1e-6) and np.all(pitch <= model.pitch_max + 1e-6)
    late = out.time > 15.0
    # the reduced model's rated speed on the rotor side (direct drive: the generator's)
    assert abs(np.mean(out.channels["GenSpeed"][late]) / model.rated_rotor_speed - 1) < 0.05
