"""OpenFAST linearisation cases of a deck (specdesign.openfast.linearize).

The case writer is checked on the shipped IEA 15 MW monopile deck without OpenFAST: the keys a
trim-and-linearise case must set, the defaults it takes from the deck's DISCON.IN, the
files openfast-io writes. The run machinery (cache, failure messages) is checked with a
stand-in executable that "writes" the shipped sample .lin file. The end-to-end test runs
OpenFAST at one wind speed when one is found (required when SPECDESIGN_REQUIRE_OPENFAST
is set, as in CI).
"""
from __future__ import annotations

import json
import math
import stat
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("openfast_io")

from specdesign.openfast import (
    LinearTurbine,
    OpenFASTInstall,
    OpenFASTRunError,
    iea15mw_monopile,
)
from specdesign.openfast.linearize import (
    DEFAULT_DOFS,
    LIN_OUTPUTS,
    _read_deck,
    linearization_case,
    linearize_deck,
    write_linearization_case,
)

DATA = Path(__file__).resolve().parents[1] / "specdesign" / "data" / "iea15mw"
RATED_SPEED = 0.79168  # rad/s: PC_RefSpd of the deck's DISCON.IN (gear ratio 1)
RATED_TORQUE = 19786800.0  # N·m: VS_RtTq of the deck's DISCON.IN


@pytest.fixture(scope="module")
def deck():
    """The shipped IEA 15 MW monopile deck (OpenFAST v5.0 format)."""
    return iea15mw_monopile()


@pytest.fixture(scope="module")
def fst_vt(deck):
    return _read_deck(deck)


def test_case_sets_the_trim_and_linearisation_keys(fst_vt):
    before = json.dumps(fst_vt["Fst"], default=str)
    vt = linearization_case(fst_vt, 19.0, rotor_speed=RATED_SPEED, gen_torque=RATED_TORQUE, initial_pitch=0.29,
                            n_azimuths=6, tmax=300.0)
    f = vt["Fst"]
    assert (f["Linearize"], f["CalcSteady"], f["TrimCase"], f["NLinTimes"], f["TMax"]) == (True, True, 3, 6, 300.0)
    assert (f["LinInputs"], f["LinOutputs"], f["CompHydro"], f["CompSeaSt"]) == (1, 1, 0, 0)
    assert f["CompSub"] == 1  # the monopile's flexibility stays (SubDyn)
    ed = vt["ElastoDyn"]
    assert {k for k in ed if "DOF" in k and ed[k] is True} == set(DEFAULT_DOFS)
    # the trim target is ElastoDyn's RotSpeed (rpm); the trim starts from BlPitch (deg)
    assert ed["RotSpeed"] == pytest.approx(RATED_SPEED * 30 / math.pi, rel=1e-12)
    assert ed["BlPitch1"] == ed["BlPitch2"] == ed["BlPitch3"] == pytest.approx(math.degrees(0.29))
    sd = vt["ServoDyn"]
    assert (sd["PCMode"], sd["VSContrl"], sd["YCMode"], sd["HSSBrMode"]) == (0, 1, 0, 0)
    assert sd["VS_RtTq"] == RATED_TORQUE
    # constant-torque region at the trim point: rated generator speed of the simple law below the target
    assert sd["VS_RtGnSp"] < ed["RotSpeed"] * ed["GBRatio"]
    assert sd["VS_Rgn2K"] * sd["VS_RtGnSp"] ** 2 <= sd["VS_RtTq"]  # ServoDyn's own check
    assert (vt["InflowWind"]["WindType"], vt["InflowWind"]["HWindSpeed"]) == (1, 19.0)
    assert vt["InflowWind"]["PLExp"] == fst_vt["InflowWind"]["PLExp"]  # the deck's shear kept
    ad = vt["AeroDyn"]
    assert (ad["UA_Mod"], ad["DBEMT_Mod"], ad["NacelleDrag"]) == (0, 0, False)
    on = {(m, c) for m, chans in vt["outlist"].items() for c, v in chans.items() if v}
    assert on == {(m, c) for m, chans in LIN_OUTPUTS.items() for c in chans}
    blade = linearization_case(fst_vt, 19.0, rotor_speed=RATED_SPEED, gen_torque=RATED_TORQUE, initial_pitch=0.29,
                               blade_moments=True)
    on_blade = {(m, c) for m, chans in blade["outlist"].items() for c, v in chans.items() if v}
    assert on_blade - on == {("ElastoDyn", f"RootMyc{b}") for b in "123"}
    assert json.dumps(fst_vt["Fst"], default=str) == before  # the deck's dictionary is left alone
    # no path of the deck's location left in the case (openfast-io makes "unused" absolute):
    # the cache's digest must not depend on where the deck lies
    assert (vt["ElastoDyn"]["FurlFile"], vt["InflowWind"]["FileName_BTS"]) == ("unused", "none")


def test_case_options_and_refusals(fst_vt):
    kw = {"rotor_speed": RATED_SPEED, "gen_torque": RATED_TORQUE, "initial_pitch": 0.2}
    vt = linearization_case(fst_vt, 15.0, dofs=("GenDOF", "TwFADOF1", "FlapDOF1"), trim_tol=1e-4, trim_gain=0.02,
                            dt=0.01, hydrodynamics=True, overrides={("InflowWind", "PLExp"): 0.0}, **kw)
    ed = vt["ElastoDyn"]
    assert {k for k in ed if "DOF" in k and ed[k] is True} == {"GenDOF", "TwFADOF1", "FlapDOF1"}
    assert (vt["Fst"]["TrimTol"], vt["Fst"]["TrimGain"], vt["Fst"]["DT"]) == (1e-4, 0.02, 0.01)
    assert vt["Fst"]["CompHydro"] == fst_vt["Fst"]["CompHydro"]
    assert vt["InflowWind"]["PLExp"] == 0.0
    with pytest.raises(ValueError, match="TwFADOF9"):
        linearization_case(fst_vt, 15.0, dofs=("GenDOF", "TwFADOF9"), **kw)
    with pytest.raises(ValueError, match="n_azimuths"):
        linearization_case(fst_vt, 15.0, n_azimuths=0, **kw)
    with pytest.raises(ValueError, match="Nonsense"):
        linearization_case(fst_vt, 15.0, overrides={("InflowWind", "Nonsense"): 1}, **kw)
    with pytest.raises(ValueError, match="wind_speed"):
        linearization_case(fst_vt, -3.0, **kw)


def test_written_case_takes_rated_point_from_the_discon(deck, fst_vt, tmp_path):
    case = write_linearization_case(deck, 19.0, tmp_path / "c19", fst_vt=fst_vt, n_azimuths=4)
    assert case.rotor_speed == pytest.approx(RATED_SPEED, rel=1e-12)
    assert case.gen_torque == RATED_TORQUE
    # the trim's starting pitch from the deck's Cp table; ROSCO's tuning of the same turbine
    # (rosco_gain_schedule.json, pitch_op_deg, from the same table) is the independent figure
    sched = json.loads((DATA / "rosco_gain_schedule.json").read_text())
    ref = float(np.interp(19.0, sched["v"], sched["pitch_op_deg"]))
    assert math.degrees(case.initial_pitch) == pytest.approx(ref, abs=0.5)
    back = _read_deck(case.fst)  # what openfast-io wrote reads back as the case
    # (openfast-io reads these two flags of the .fst back as the strings it wrote)
    assert (str(back["Fst"]["Linearize"]), str(back["Fst"]["CalcSteady"]), back["Fst"]["NLinTimes"]) == ("True", "True", 4)
    assert back["InflowWind"]["HWindSpeed"] == 19.0
    assert back["ServoDyn"]["VSContrl"] == 1 and back["ServoDyn"]["PCMode"] == 0


def test_case_and_its_digest_do_not_depend_on_where_the_deck_lies(deck, tmp_path):
    # the cache is keyed by the case's files: the same deck copied to two folders must write
    # byte-identical cases, or a second checkout (a worktree, a moved venv) linearises again
    import shutil

    from specdesign.openfast.deck import Deck
    from specdesign.openfast.linearize import _digest

    digests, files = [], []
    for where in ("a", "b/deeper"):
        folder = tmp_path / where / deck.fst.parent.name
        shutil.copytree(deck.fst.parent, folder)
        copy = Deck(folder / deck.fst.name, version=deck.version)
        case = write_linearization_case(copy, 19.0, tmp_path / f"case_{where.replace('/', '_')}", n_azimuths=2)
        digests.append(_digest(case.fst.parent, "5.0.0"))
        files.append({p.relative_to(case.fst.parent): p.read_bytes() for p in case.fst.parent.rglob("*") if p.is_file()})
    assert files[0].keys() == files[1].keys()
    assert [k for k in files[0] if files[0][k] != files[1][k]] == []
    assert digests[0] == digests[1]
    servodyn = next((tmp_path / "case_a").glob("*ServoDyn.dat")).read_text()
    assert '"libdiscon.so"' in servodyn and str(tmp_path) not in servodyn  # bare: no mode loads it


def _fake_openfast(folder: Path, name: str, body: str) -> OpenFASTInstall:
    """A stand-in ``openfast``: a Python script run in the case folder with the .fst as its argument."""
    exe = folder / name
    exe.write_text(f"#!{sys.executable}\nimport sys, shutil, pathlib\n{body}\n")
    exe.chmod(exe.stat().st_mode | stat.S_IXUSR)
    return OpenFASTInstall(exe, None, "5.0.0")


def test_runs_cache_and_failures_with_a_stand_in(deck, tmp_path):
    from test_openfast_outputs import write_binary  # OpenFAST's binary output layout

    outb = tmp_path / "template.outb"
    write_binary(outb, np.column_stack([np.arange(3) * 0.1, np.full(3, 7.56)]), names=["Time", "GenSpeed"],
                 units=["(s)", "(rpm)"])
    # "linearises" by copying the shipped 19 m/s sample (its header says 19 m/s) and counts its runs
    runs = tmp_path / "runs"
    sample = DATA / "sample_floating_19mps.1.lin"
    fake = _fake_openfast(tmp_path, "openfast", f"""
with open({str(runs)!r}, 'a') as f: f.write('x')
root = pathlib.Path(sys.argv[1]).stem
shutil.copy({str(sample)!r}, root + '.1.lin')
shutil.copy({str(outb)!r}, root + '.outb')
print('OpenFAST terminated normally.')""")
    cache = tmp_path / "cache"
    lt = linearize_deck(deck, [19.0], n_azimuths=1, openfast=fake, cache=cache, progress=False)
    assert isinstance(lt, LinearTurbine) and lt.wind_range == (19.0, 19.0)
    plant = lt.linearize(19.0)
    assert set(plant.input_labels) >= {"wind", "pitch_cmd"} and "tower_base_my" in plant.output_labels
    again = linearize_deck(deck, [19.0], n_azimuths=1, openfast=fake, cache=cache, progress=False)
    assert runs.read_text() == "x"  # the second call was served from the cache
    np.testing.assert_array_equal(again.linearize(19.0).A, lt.linearize(19.0).A)

    bad = _fake_openfast(tmp_path, "bad", """
print('FAST_InitializeAll:SrvD_Init:VSContrl must be 0 or 1 for linearization.'); sys.exit(1)""")
    with pytest.raises(OpenFASTRunError, match=r"(?s)17 m/s.*VSContrl must be 0 or 1"):
        linearize_deck(deck, [17.0], n_azimuths=1, openfast=bad, cache=cache, progress=False)
    nolin = _fake_openfast(tmp_path, "nolin", f"""
shutil.copy({str(outb)!r}, pathlib.Path(sys.argv[1]).stem + '.outb')""")
    with pytest.raises(OpenFASTRunError, match=r"16 m/s.*no \.lin"):
        linearize_deck(deck, [16.0], n_azimuths=1, openfast=nolin, cache=cache, progress=False)
    with pytest.raises(ValueError, match="wind_speeds"):
        linearize_deck(deck, [19.0, 19.0], openfast=fake, cache=cache)

    # the options reach the case OpenFAST runs (trim_damping was accepted and dropped), as a new case
    before = set(cache.glob("19mps-*"))
    linearize_deck(deck, [19.0], n_azimuths=1, openfast=fake, cache=cache, progress=False, trim_damping=0.0,
                   blade_moments=True)
    (made,) = set(cache.glob("19mps-*")) - before
    (kdmp,) = [line.split()[0] for line in (made / "lin.fst").read_text().splitlines() if "Twr_Kdmp" in line]
    assert float(kdmp) == 0.0
    outlist = (made / "lin_ElastoDyn.dat").read_text()
    assert all(f'"RootMyc{b}"' in outlist for b in "123")
    # the shipped sample has the triplet: its collective part is blade_root_my
    assert "blade_root_my" in linearize_deck(deck, [19.0], n_azimuths=1, openfast=fake, cache=cache,
                                             progress=False).output_names


def test_openfast_runs_with_the_chosen_blas(deck, tmp_path, monkeypatch):
    # the BLAS folder of specdesign.openfast.install.run_environment reaches the OpenFAST process:
    # the stand-in prints its LD_LIBRARY_PATH and fails, and the error quotes OpenFAST's last words
    blas = tmp_path / "blas"
    blas.mkdir()
    (blas / "libblas.so.3").write_bytes(b"")
    monkeypatch.setenv("SPECDESIGN_OPENFAST_BLAS", str(blas))
    monkeypatch.setenv("LD_LIBRARY_PATH", "/opt/mine")
    echo = _fake_openfast(tmp_path, "echo", """
import os; print('LD_LIBRARY_PATH=' + os.environ.get('LD_LIBRARY_PATH', '')); sys.exit(1)""")
    with pytest.raises(OpenFASTRunError, match=f"LD_LIBRARY_PATH={blas.resolve()}:/opt/mine"):
        linearize_deck(deck, [17.0], n_azimuths=1, openfast=echo, cache=tmp_path / "cache", progress=False)


@pytest.mark.slow
def test_openfast_linearisation_at_19_mps(deck, tmp_path, openfast):
    """One speed, one azimuth: OpenFAST's plant has the rotor and the tower of the references.

    Reference figures: rotor_linearization_reference.json (OpenFAST linearisations of the
    IEA 15 MW rotor, floating, 12 azimuths): ∂Ω̇/∂β = -0.865 rad/s² per rad at 19 m/s;
    ROSCO's tuning (rosco_gain_schedule.json): 16.5° of pitch at 19 m/s; the first tower
    fore-aft mode of monopile + tower + rotor-nacelle assembly, tower_fe.json: 0.172 Hz.
    Measured here: the trim converges after ~31 s of simulated time (~50 s of CPU); the one
    linearisation takes 285 s of CPU on Debian's reference BLAS, 50-58 s on a serial OpenBLAS
    (CI installs one), most of it in the LU solve of OpenFAST's glue system
    (docs/openfast_linearization.md).
    """
    install = openfast  # tests/conftest.py: found, or built in CI; skipped or failed without one
    t0 = time.perf_counter()
    lt = linearize_deck(deck, [19.0], n_azimuths=1, openfast=install, cache=tmp_path, progress=False)
    print(f"end-to-end linearisation at 19 m/s: {time.perf_counter() - t0:.0f} s")
    from specdesign.openfast.linear_turbine import rotor_speed_model

    plant = lt.linearize(19.0)
    _, b_beta, _ = rotor_speed_model(plant)
    ref = {r["U"]: r for r in json.loads((DATA / "rotor_linearization_reference.json").read_text())}[19.0]
    assert b_beta == pytest.approx(ref["OF_B_beta"], rel=0.15)
    op = lt.trim(19.0)
    assert op.rotor_speed == pytest.approx(RATED_SPEED, rel=2e-3)
    assert math.degrees(op.pitch) == pytest.approx(16.5, abs=1.0)
    fe = json.loads((DATA / "tower_fe.json").read_text())["with gravity (P-delta)"]["f1_Hz"]
    lam = np.linalg.eigvals(np.asarray(plant.A, float))
    f = np.abs(lam[lam.imag > 0]) / (2 * np.pi)
    assert np.min(np.abs(f - fe)) < 0.05 * fe
