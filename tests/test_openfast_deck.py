"""Case folders written from the shipped deck, OpenFAST and TurbSim failures reported with the
case and seed, the TurbSim cache: fast, with fake executables (shell scripts) standing in for
OpenFAST and TurbSim (tests/test_openfast_run.py runs the real ones)."""
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("openfast_io")

from specdesign.openfast import (CAMPAIGN_CHANNELS, Deck, OpenFASTInstall, OpenFASTRunError, iea15mw_monopile,
                                 run_case, write_case)
from specdesign.openfast import wave_seed_for
from specdesign.openfast.turbsim import turbsim_field
from specdesign.wind import seed_for
from specdesign.validate.openfast_campaign import as_discon


def _script(path: Path, body: str) -> Path:
    path.write_text("#!/bin/sh\n" + body + "\n")
    path.chmod(0o755)
    return path


@pytest.fixture
def library(tmp_path):
    lib = tmp_path / "libfake.so"  # write_case only checks that the file exists
    lib.write_bytes(b"\x7fELF")
    return lib


def _keys(path: Path) -> dict:
    """key → first token of every 'value key - description' line of an OpenFAST input file."""
    out = {}
    for line in path.read_text().splitlines():
        t = line.split()
        if len(t) > 1 and t[1] not in out:
            out[t[1]] = t[0].strip('"')
    return out


def test_shipped_deck_is_v5_with_hydrodynamics_on():
    deck = iea15mw_monopile()
    assert deck.version == "5.0"
    fst = _keys(deck.fst)
    assert fst["CompSeaSt"] == "1" and fst["CompHydro"] == "1" and fst["CompSub"] == "1"
    # the v5.0 keys the rosco copy lacked (benchmarks/openfast_deck.py)
    assert "WvCrntMod" in _keys(deck.fst.with_name(fst["SeaStFile"]))
    hd = _keys(deck.fst.with_name(fst["HydroFile"]))
    assert "NAddDOF" in hd and "HstMod" in hd
    assert (deck.fst.parent.parent / "NOTICE.md").read_text().count("Apache") >= 1


def test_write_case_sets_wind_controller_outputs_and_length(tmp_path, library):
    params = tmp_path / "params.in"
    params.write_text("x")
    case = write_case(iea15mw_monopile(), tmp_path / "c19", tmax=30.0, wind_speed=19.0, library=library,
                      parameters=params, dt_out=0.05, initial_pitch=0.27, initial_rotor_speed=0.79, seed=3)
    assert case.fst.is_file() and case.seed == 3 and case.channels == CAMPAIGN_CHANNELS
    fst = _keys(case.fst)
    assert float(fst["TMax"]) == 30.0 and float(fst["DT_Out"]) == 0.05 and fst["OutFileFmt"] == "2"
    sd = _keys(case.folder / fst["ServoFile"])
    assert sd["DLL_FileName"] == str(library) and sd["DLL_InFile"] == str(params)
    ifw = _keys(case.folder / fst["InflowFile"])
    assert ifw["WindType"] == "1" and float(ifw["HWindSpeed"]) == 19.0
    ed_file = case.folder / fst["EDFile"]
    ed = _keys(ed_file)
    assert float(ed["BlPitch(1)"]) == pytest.approx(0.27 * 180 / 3.141592653589793)
    assert float(ed["RotSpeed"]) == pytest.approx(0.79 * 30 / 3.141592653589793)  # rpm
    # only the campaign's channels are written: the ElastoDyn OutList holds exactly its share
    lines = ed_file.read_text().splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.split()[:1] == ["OutList"])
    end = next(i for i in range(start, len(lines)) if lines[i].startswith("END"))
    listed = {ln.strip().strip('"') for ln in lines[start + 1:end] if ln.strip()}
    assert listed == {"BldPitch1", "RotSpeed", "GenSpeed", "TwrBsMyt", "RootMyb1", "YawBrTAxp"}


def test_write_case_refuses_bad_input(tmp_path, library):
    deck = iea15mw_monopile()
    with pytest.raises(ValueError, match="tmax"):
        write_case(deck, tmp_path / "a", tmax=0.0, wind_speed=19.0, library=library)
    with pytest.raises(ValueError, match="multiple of the time step"):
        write_case(deck, tmp_path / "a", tmax=10.0, wind_speed=19.0, library=library, dt_out=0.0123)
    with pytest.raises(FileNotFoundError, match="wind_file"):
        write_case(deck, tmp_path / "a", tmax=10.0, wind_speed=19.0, library=library, wind_file=tmp_path / "no.bts")
    with pytest.raises(ValueError, match="NoSuchChannel"):
        write_case(deck, tmp_path / "a", tmax=10.0, wind_speed=19.0, library=library, channels=["NoSuchChannel"])
    with pytest.raises(TypeError, match="Deck"):
        write_case(str(deck.fst), tmp_path / "a", tmax=10.0, wind_speed=19.0, library=library)
    with pytest.raises(FileNotFoundError, match="does not exist"):
        Deck(tmp_path / "none.fst")


def test_failed_run_names_case_seed_and_tail(tmp_path, library):
    case = write_case(iea15mw_monopile(), tmp_path / "c", tmax=5.0, wind_speed=19.0, library=library, seed=7)
    exe = _script(tmp_path / "openfast", 'echo "FAST_InitializeAll:SeaSt_Init:Invalid numerical input for WvCrntMod"\n'
                                         'echo "Aborting OpenFAST."\nexit 1')
    inst = OpenFASTInstall(exe, None, "5.0.0")
    with pytest.raises(OpenFASTRunError, match=r"(?s)'c' \(19 m/s, seed 7\) failed.*WvCrntMod.*Aborting") as err:
        run_case(case, inst)
    assert err.value.case == case and "Aborting OpenFAST." in err.value.tail
    # a run that hangs is stopped at the timeout and reported the same way
    slow = OpenFASTInstall(_script(tmp_path / "slow", "echo started\nsleep 30"), None, "5.0.0")
    with pytest.raises(OpenFASTRunError, match="did not finish in 0.5 s of wall time"):
        run_case(case, slow, timeout=0.5)
    # a run that burns its CPU allowance (a busy loop: 1 s of CPU) is stopped by the CPU limit
    busy = OpenFASTInstall(_script(tmp_path / "busy", "echo spinning\nwhile :; do :; done"), None, "5.0.0")
    with pytest.raises(OpenFASTRunError, match="(?s)more than its 1 s of CPU time.*spinning"):
        run_case(case, busy, cpu_limit=1.0, timeout=120.0)


def test_deck_of_another_version_is_refused_before_running(tmp_path, library):
    case = write_case(iea15mw_monopile(), tmp_path / "c", tmax=5.0, wind_speed=19.0, library=library)
    inst = OpenFASTInstall(_script(tmp_path / "openfast", "exit 1"), None, "4.1.2")
    with pytest.raises(ValueError, match=r"written for OpenFAST v5\.0 but the OpenFAST found is v4\.1\.2"):
        run_case(case, inst)


def test_turbsim_field_is_cached_by_its_inputs(tmp_path):
    calls = tmp_path / "calls"
    # a fake TurbSim: writes <root>.bts next to its input and counts its calls
    ts = _script(tmp_path / "turbsim", f'echo x >> {calls}\nroot="${{1%.inp}}"\necho bts > "$root.bts"')
    inst = OpenFASTInstall(tmp_path / "openfast", ts, "5.0.0")
    a = turbsim_field(19.0, 2, length=100.0, cache=tmp_path / "cache", install=inst)
    b = turbsim_field(19.0, 2, length=100.0, cache=tmp_path / "cache", install=inst)
    c = turbsim_field(19.0, 3, length=100.0, cache=tmp_path / "cache", install=inst)
    assert a.path == b.path and a.path.is_file() and c.path != a.path
    assert calls.read_text().count("x") == 2  # the second call came from the cache
    assert a.settings["RandSeed1"] == 2190 and c.settings["RandSeed1"] == 3190  # specdesign.wind.seed_for
    inp = a.path.with_suffix(".inp").read_text()
    assert '"IECKAI"' in inp and '"NTM"' in inp and '"B"' in inp and "13 " in inp
    bad = OpenFASTInstall(tmp_path / "openfast", _script(tmp_path / "bad", "echo 'Invalid grid'\nexit 3"), "5.0.0")
    with pytest.raises(RuntimeError, match="(?s)seed 4.*exit code 3.*Invalid grid"):
        turbsim_field(19.0, 4, length=100.0, cache=tmp_path / "cache", install=bad)
    with pytest.raises(ValueError, match="twice the hub height"):
        turbsim_field(19.0, 4, grid_size=300.0, install=inst)


def test_campaign_controllers_must_be_compiled(tmp_path, library):
    par = tmp_path / "p.in"
    par.write_text("x")

    class Exported:  # what export_discon returns: anything with .library and .parameters
        pass

    e = Exported()
    e.library, e.parameters = library, par
    assert as_discon(e).parameters == par.resolve()
    with pytest.raises(TypeError, match="export_discon"):
        as_discon(lambda t, y: 0.0)
    e.parameters = tmp_path / "missing.in"
    with pytest.raises(FileNotFoundError, match="missing.in"):
        as_discon(e)


def test_each_run_has_its_own_sea(tmp_path, library):
    # SeaState's WaveSeed(1) from the (speed, seed) of the run: the wind seed + WAVE_SEED_OFFSET,
    # distinct from every TurbSim seed (seed_for: 1000·seed + round(10·speed)) and the same for
    # every controller at that (speed, seed)
    assert wave_seed_for(19.0, 2) == seed_for(19.0, 2) + 500 == 2690
    seeds = {seed_for(v, s) for v in np.arange(3.0, 30.5, 0.5) for s in range(1, 9)}
    assert not seeds & {wave_seed_for(v, s) for v in np.arange(3.0, 30.5, 0.5) for s in range(1, 9)}
    deck = iea15mw_monopile()
    case = write_case(deck, tmp_path / "w", tmax=10.0, wind_speed=19.0, library=library, wave_seed=wave_seed_for(19.0, 2))
    fst = _keys(case.fst)
    assert _keys(case.folder / fst["SeaStFile"])["WaveSeed(1)"] == "2690"
    default = write_case(deck, tmp_path / "d", tmax=10.0, wind_speed=19.0, library=library)
    assert _keys(default.folder / _keys(default.fst)["SeaStFile"])["WaveSeed(1)"] == "123456789"  # the deck's
    with pytest.raises(TypeError, match="wave_seed"):
        write_case(deck, tmp_path / "x", tmax=10.0, wind_speed=19.0, library=library, wave_seed=2.5)
    with pytest.raises(ValueError, match="wave_seed"):
        write_case(deck, tmp_path / "x", tmax=10.0, wind_speed=19.0, library=library, wave_seed=2**31)
