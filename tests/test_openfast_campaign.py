"""OpenFAST campaigns with fake OpenFAST and TurbSim executables (Python scripts writing a
binary .outb of known signals): the Campaign record, the transient cut and SI units checked
against indicators computed directly on the same signals, a failed run reported with its case,
seed and OpenFAST's tail while the rest is kept, resuming without rerunning, refusing a folder
of another campaign, and the dispatch from run_campaign(plant=Deck)."""
import dataclasses
import math
import shutil

import control as ct
import numpy as np
import pytest
from numpy.testing import assert_allclose

pytest.importorskip("openfast_io")

from specdesign.openfast import Deck, iea15mw_monopile
from specdesign.openfast.deck import named_digest
from specdesign.validate import indicators, read_openfast_runs, run_campaign, welch_psd
from specdesign.validate.openfast_campaign import run_openfast_campaign

# The fake OpenFAST: reads TMax and DT_Out from the .fst, the seed from the wind file's name,
# and writes the campaign's 9 channels (OpenFAST's units) as a binary .outb (file ID 3). It
# fails like OpenFAST when the controller's parameter file says FAIL. Each call is counted.
_FAKE_OPENFAST = '''\
    k = keys(fst)
    sd, ifw = keys(k["ServoFile"]), keys(k["InflowFile"])
    if "FAIL" in Path(sd["DLL_InFile"]).read_text():
        print("ROSCO:ReadControlParameterFileSub:Invalid parameter file")
        print("Aborting OpenFAST.")
        sys.exit(1)
    seed = int(re.search(r"seed(\\d+)", ifw["FileName_BTS"]).group(1))
    words = Path(sd["DLL_InFile"]).read_text().split()
    gain = 1.0 if words[0] == "specdesign-discon" else float(words[0])
    dt, tmax = float(k["DT_Out"]), float(k["TMax"])
    t = np.arange(int(round(tmax / dt)) + 1) * dt
    w = 1.0 + 0.1 * seed
    ch = {{"Wind1VelX": ("(m/s)", 19 + np.sin(w * t)), "BldPitch1": ("(deg)", 15 + gain * np.sin(0.3 * w * t)),
          "RotSpeed": ("(rpm)", 7.56 + 0.1 * np.sin(w * t)), "GenSpeed": ("(rpm)", 7.56 + 0.2 * np.sin(1.3 * w * t)),
          "GenTq": ("(kN-m)", 2e4 + 0 * t), "GenPwr": ("(kW)", 1.5e4 + 50 * np.sin(t)),
          "TwrBsMyt": ("(kN-m)", 1e5 + gain * 2e4 * np.sin(1.1 * w * t) + 5e3 * np.sin(2.4 * t)),
          "RootMyb1": ("(kN-m)", 3e4 + 8e3 * np.sin(0.8 * t + seed)), "YawBrTAxp": ("(m/s^2)", 0.1 * np.sin(t))}}
'''


@pytest.fixture(scope="module")
def model():
    from specdesign.turbine import iea15mw
    return iea15mw()


@pytest.fixture
def fake(tmp_path, fake_openfast):
    inst, calls = fake_openfast(_FAKE_OPENFAST)
    lib = tmp_path / "libfake.so"
    lib.write_bytes(b"\x7fELF")
    return inst, calls, lib


class Exported:
    """What an export returns: a library and a parameter file (here the fake's gain)."""

    def __init__(self, library, parameters):
        self.library, self.parameters = library, parameters


def _controller(tmp_path, lib, name, text):
    p = tmp_path / f"{name}.in"
    p.write_text(text)
    return Exported(lib, p)


def test_campaign_in_fake_openfast(tmp_path, fake):
    inst, calls, lib = fake
    ctrls = {"A": _controller(tmp_path, lib, "a", "1.0"), "B": _controller(tmp_path, lib, "b", "0.5")}
    kw = dict(deck=iea15mw_monopile(), duration=40.0, transient=10.0, record_dt=0.05, install=inst, processes=2,
              folder=tmp_path / "camp", initial_conditions=False, keep_series=1)
    camp = run_openfast_campaign(ctrls, [19.0], [0, 2], **kw)
    assert camp.controllers == ("A", "B") and camp.values["tower_del"].shape == (2, 1, 2)
    assert not camp.unstable.any() and np.isnan(camp.predicted_del).all()
    # the same indicators computed directly on the fake's signals after the 10 s transient, in SI
    t = 10.0 + np.arange(800) * 0.05
    for ci, gain in enumerate((1.0, 0.5)):
        for si, seed in enumerate((0, 2)):
            w = 1.0 + 0.1 * seed
            series = {"tower_base_my": 1e3 * (1e5 + gain * 2e4 * np.sin(1.1 * w * t) + 5e3 * np.sin(2.4 * t)),
                      "gen_speed": (7.56 + 0.2 * np.sin(1.3 * w * t)) * math.pi / 30,
                      "pitch": np.radians(15 + gain * np.sin(0.3 * w * t)), "power": 1e3 * (1.5e4 + 50 * np.sin(t)),
                      "blade_root_my": 1e3 * (3e4 + 8e3 * np.sin(0.8 * t + seed))}
            # the rate limit: PC_MaxRat of the shipped deck's DISCON.IN, 0.0349 rad/s (2 deg/s)
            want = indicators({k: a[None] for k, a in series.items()}, 0.05, 4.0, pitch_rate_limit=0.0349).as_dict()
            for k, v in want.items():
                assert_allclose(camp.values[k][ci, 0, si], v[0], rtol=1e-9, err_msg=f"{k} {ci} {seed}")
    assert camp.series["A"].outputs["tower_base_my"].shape == (1, 1, 800)
    n_calls = len(calls.read_text().split())
    assert n_calls == 4
    # resumed: nothing runs again, the same numbers
    again = run_openfast_campaign(ctrls, [19.0], [0, 2], **kw)
    assert len(calls.read_text().split()) == n_calls
    assert_allclose(again.values["tower_del"], camp.values["tower_del"], rtol=0)
    # ... and from a copy of the deck in another folder (a moved checkout, a rebuilt venv): the
    # runs are found by the deck's digest, not its path
    moved = tmp_path / "moved"
    shutil.copytree(iea15mw_monopile().fst.parent, moved)
    elsewhere = run_openfast_campaign(ctrls, [19.0], [0, 2], **{**kw, "deck": Deck(moved / iea15mw_monopile().fst.name,
                                                                                      version="5.0")})
    assert len(calls.read_text().split()) == n_calls
    assert_allclose(elsewhere.values["tower_del"], camp.values["tower_del"], rtol=0)
    # another controller under a stored name is refused
    with pytest.raises(ValueError, match="other settings or another controller under the name 'A'"):
        run_openfast_campaign({"A": ctrls["B"]}, [19.0], [0], **kw)



def test_the_exported_parameter_file_a_run_ran_is_kept_once_by_its_digest(tmp_path, fake):
    # what benchmarks/openfast_report.py compares a changed design against (ran_parameters): the
    # workbench's own parameter files are kept beside the runs, once per digest, and put back
    # when a resumed campaign finds the runs without them; another format (ROSCO's DISCON.IN) is not
    from specdesign.validate.openfast_campaign import ran_parameters

    inst, calls, lib = fake
    ctrls = {"QFT+ATD": _controller(tmp_path, lib, "q", "specdesign-discon 2\n# a design\ndt 0.01\n"),
             "ROSCO": _controller(tmp_path, lib, "r", "1.0\n")}
    kw = dict(deck=iea15mw_monopile(), duration=20.0, transient=5.0, record_dt=0.05, install=inst, processes=1,
              folder=tmp_path / "camp", initial_conditions=False)
    run_openfast_campaign(ctrls, [19.0], [0, 1], **kw)
    sha = named_digest(ctrls["QFT+ATD"].parameters)
    kept = tmp_path / "camp" / "QFT_ATD" / "parameters" / f"{sha}.IN"
    assert kept.read_bytes() == ctrls["QFT+ATD"].parameters.read_bytes()
    assert sorted((tmp_path / "camp").glob("*/parameters/*")) == [kept]  # once for both seeds, none for ROSCO
    runs = read_openfast_runs(tmp_path / "camp")
    assert {r.controller: ran_parameters(r) for r in runs} == {"QFT+ATD": kept, "ROSCO": None}
    kept.unlink()
    n_calls = len(calls.read_text().split())
    run_openfast_campaign(ctrls, [19.0], [0, 1], **kw)
    assert len(calls.read_text().split()) == n_calls and kept.is_file()

def test_a_resumed_campaign_counts_runs_of_the_same_design_exported_again(tmp_path, fake, model):
    # another machine's OpenFAST linearises with other round-off: Table 3's designs made again
    # moved by 2.4e-9 to 1.3e-7, so their files' digests changed and the store refused every run
    # (run.json differs). A file within SAME_DESIGN_RTOL of the kept one (responses, not bytes)
    # is the same design: its runs count, said by a warning, and the new file is not kept under
    # the runs' digest; a changed design is still refused, its distance said
    from specdesign.export import discon_parameters, write_parameters
    from specdesign.export.parameters import SAME_DESIGN_RTOL

    inst, calls, lib = fake
    p = discon_parameters(ct.tf([-2.0, -0.9, -0.1], [1.0, 1.2, 0.0]), model=model)

    def exported(tag, scale):
        path = write_parameters(dataclasses.replace(p, C=p.C * scale, D=p.D * scale), tmp_path / f"{tag}.IN")
        return Exported(lib, path)

    kw = dict(deck=iea15mw_monopile(), duration=20.0, transient=5.0, record_dt=0.05, install=inst, processes=1,
              folder=tmp_path / "camp", initial_conditions=False)
    first = run_openfast_campaign({"QFT+ATD": exported("a", 1.0)}, [19.0], [0, 1], **kw)
    n_calls = len(calls.read_text().split())
    moved = exported("b", 1 + 1e-7)  # responses 1e-7 apart (linear in C, D: tests/test_export.py)
    with pytest.warns(RuntimeWarning, match=r"earlier export of this design \(responses 1\.0e-07 relative apart"):
        again = run_openfast_campaign({"QFT+ATD": moved}, [19.0], [0, 1], **kw)
    assert len(calls.read_text().split()) == n_calls
    assert_allclose(again.values["tower_del"], first.values["tower_del"], rtol=0)
    kept = sorted(p_.name for p_ in (tmp_path / "camp" / "QFT_ATD" / "parameters").glob("*.IN"))
    assert kept == [f"{named_digest(tmp_path / 'a.IN')}.IN"]
    far = exported("c", 1 + 10 * SAME_DESIGN_RTOL)
    with pytest.raises(ValueError, match=r"run\.json differs; its controller's responses are 0\.0001 relative"):
        run_openfast_campaign({"QFT+ATD": far}, [19.0], [0, 1], **kw)


def test_kept_change_is_the_response_distance_or_inf(tmp_path, model):
    # the one comparison the campaign's resume and openfast_report.stale_designs share: responses
    # (C, D scaled by 1 + 1e-7 move every response by 1e-7: tests/test_export.py), inf when the
    # kept file is absent or not the workbench's format (ROSCO's own DISCON.IN)
    from specdesign.export import discon_parameters, write_parameters
    from specdesign.validate.openfast_campaign import kept_change

    p = discon_parameters(ct.tf([-2.0, -0.9, -0.1], [1.0, 1.2, 0.0]), model=model)
    a = write_parameters(p, tmp_path / "a.IN")
    b = write_parameters(dataclasses.replace(p, C=p.C * (1 + 1e-7), D=p.D * (1 + 1e-7)), tmp_path / "b.IN")
    assert kept_change(a, a) == 0.0
    assert kept_change(a, b) == pytest.approx(1e-7, rel=1e-3)
    assert kept_change(None, a) == float("inf")
    assert kept_change(tmp_path / "missing.IN", a) == float("inf")
    rosco_in = iea15mw_monopile().fst.with_name("IEA-15-240-RWT-Monopile_DISCON.IN")
    assert kept_change(rosco_in, a) == float("inf")


def test_a_controller_named_outside_ascii_runs_under_an_ascii_folder(tmp_path, fake):
    # OpenFAST opens its case files by name: "H∞+ATD" runs as Hinf_ATD, and is read back by its name
    inst, _, lib = fake
    camp = run_openfast_campaign({"H∞+ATD": _controller(tmp_path, lib, "h", "1.0")}, [19.0], [0],
                                 deck=iea15mw_monopile(), duration=20.0, transient=5.0, record_dt=0.05, install=inst,
                                 processes=1, folder=tmp_path / "camp", initial_conditions=False)
    assert camp.controllers == ("H∞+ATD",)
    assert (tmp_path / "camp" / "Hinf_ATD" / "19mps_seed0" / "run.json").is_file()
    assert [r.controller for r in read_openfast_runs(tmp_path / "camp")] == ["H∞+ATD"]


def test_a_parameter_file_counts_by_the_files_it_names_not_by_their_place(tmp_path, fake):
    # a DISCON.IN written with absolute file names (rosco.write_discon makes PerfFileName absolute,
    # as benchmarks/openfast_table3.py's ROSCO+TD file has it) is the same controller from another
    # checkout, so the repository's store is found there; a changed table is another controller
    inst, calls, lib = fake

    def controller(folder, table):
        folder.mkdir()
        (folder / "Cp_Ct_Cq.txt").write_text(table)
        return _controller(folder, lib, "a", f'1.0\n"{folder / "Cp_Ct_Cq.txt"}"  ! PerfFileName\n')

    kw = dict(deck=iea15mw_monopile(), duration=20.0, transient=5.0, record_dt=0.05, install=inst, processes=1,
              folder=tmp_path / "camp", initial_conditions=False)
    run_openfast_campaign({"A": controller(tmp_path / "one", "the table")}, [19.0], [0], **kw)
    n_calls = len(calls.read_text().split())
    run_openfast_campaign({"A": controller(tmp_path / "two", "the table")}, [19.0], [0], **kw)
    assert len(calls.read_text().split()) == n_calls  # found, not run again
    with pytest.raises(ValueError, match="other settings or another controller under the name 'A'"):
        run_openfast_campaign({"A": controller(tmp_path / "three", "another table")}, [19.0], [0], **kw)


def test_a_deck_counts_by_every_file_it_names_not_by_its_place(tmp_path, fake):
    # the .fst alone names its modules: a changed ElastoDyn (or airfoil) file under the same .fst
    # must be another deck, else a campaign silently reuses runs of the old turbine; a deck copied
    # to another folder (a clone) is the same deck, so its stored runs are found there
    inst, calls, lib = fake
    shipped = iea15mw_monopile()
    copies = []
    for name in ("one", "two"):
        shutil.copytree(shipped.fst.parent, tmp_path / name)
        copies.append(Deck(tmp_path / name / shipped.fst.name, shipped.version))
    assert copies[0].digest == copies[1].digest == shipped.digest
    ed = tmp_path / "two" / "IEA-15-240-RWT-Monopile_ElastoDyn_tower.dat"  # named by ElastoDyn, not by the .fst
    ed.write_text(ed.read_text().replace("1.0                    TwrFADmp(1)", "2.0                    TwrFADmp(1)", 1))
    assert "2.0                    TwrFADmp(1)" in ed.read_text()  # 2 % tower damping, not 1 %
    assert copies[1].fst.read_bytes() == shipped.fst.read_bytes() and copies[1].digest != shipped.digest
    # a file naming itself (or an ancestor) counts by its name: no endless recursion
    loop = tmp_path / "loop.dat"
    loop.write_text(f'"{loop}" this file\n"{shipped.fst}" a deck\n')
    assert len(named_digest(loop)) == 16

    ctrl = _controller(tmp_path, lib, "a", "1.0\n")
    kw = dict(duration=20.0, transient=5.0, record_dt=0.05, install=inst, processes=1, folder=tmp_path / "camp",
              initial_conditions=False)
    run_openfast_campaign({"A": ctrl}, [19.0], [0], deck=copies[0], **kw)
    with pytest.raises(ValueError, match="other settings"):
        run_openfast_campaign({"A": ctrl}, [19.0], [0], deck=copies[1], **kw)


def test_a_campaign_folder_is_read_as_far_as_it_got(tmp_path, fake, benchmark_script):
    # read_openfast_runs gives back what run_openfast_campaign stored, value for value and
    # spectrum for spectrum; a run whose result.npz is not written yet (a run in progress) is
    # not counted; a folder that is not there is named; the series of the kept seeds (the first
    # one here) come back as the campaign holds them, the other seeds' are absent
    inst, calls, lib = fake
    ctrls = {"A": _controller(tmp_path, lib, "a", "1.0"), "B": _controller(tmp_path, lib, "b", "0.5")}
    camp = run_openfast_campaign(ctrls, [19.0], [0, 2], deck=iea15mw_monopile(), duration=40.0, transient=10.0,
                                 record_dt=0.05, install=inst, processes=2, folder=tmp_path / "camp",
                                 initial_conditions=False, keep_series=1)
    runs = read_openfast_runs(tmp_path / "camp")
    assert [(r.controller, r.wind_speed, r.seed) for r in runs] == [("A", 19.0, 0), ("A", 19.0, 2), ("B", 19.0, 0),
                                                                      ("B", 19.0, 2)]
    for r in runs:
        ci, si = camp.controllers.index(r.controller), (0, 2).index(r.seed)
        for k, v in r.values.items():
            assert_allclose(v, camp.values[k][ci, 0, si], rtol=0, err_msg=k)
        assert r.meta["settings"]["duration"] == 40.0 and r.omega.shape == r.welch["tower_base_my"].shape
        if r.seed == 0:
            for k, a in r.series.items():
                assert_allclose(a, camp.series[r.controller].outputs[k][0, 0], rtol=0, err_msg=k)
            assert set(r.series) >= {"tower_base_my", "gen_speed", "pitch", "power"}
        else:
            assert r.series == {}
        # the pitch angle's own Welch spectrum is kept for every run, series kept or not (the
        # actuator's cost at 3P and above): that of the fake's pitch after the transient, in rad
        w, gain = 1.0 + 0.1 * r.seed, {"A": 1.0, "B": 0.5}[r.controller]
        pitch = np.radians(15 + gain * np.sin(0.3 * w * (10.0 + np.arange(800) * 0.05)))
        omega, want = welch_psd(pitch, 0.05)
        assert_allclose(r.omega, omega, rtol=0)
        assert_allclose(r.welch["pitch"], want, rtol=1e-9, atol=1e-12 * want.max())
        # and the tower-top acceleration's (the tower damper's input): the fake's 0.1 sin(t) m/s²
        _, want = welch_psd(0.1 * np.sin(10.0 + np.arange(800) * 0.05), 0.05)
        assert_allclose(r.welch["tower_top_acc"], want, rtol=1e-9, atol=1e-12 * want.max())
    # a run stored before the pitch spectrum was kept: openfast_report.py computes it from the
    # kept series with the run's own Welch settings, the same as stored; without series, none
    pitch_psd = benchmark_script("openfast_report").pitch_psd
    for r in runs:
        older = dataclasses.replace(r, welch={k: a for k, a in r.welch.items() if k != "pitch"})
        if r.seed == 0:
            assert_allclose(pitch_psd(older)[1], r.welch["pitch"], rtol=0, atol=0)
        else:
            assert pitch_psd(older) is None
    (tmp_path / "camp" / "B" / "19mps_seed2" / "result.npz").unlink()
    assert len(read_openfast_runs(tmp_path / "camp")) == 3
    with pytest.raises(FileNotFoundError, match="campaign's folder"):
        read_openfast_runs(tmp_path / "nowhere")


def test_failed_run_is_reported_and_the_rest_kept(tmp_path, fake):
    inst, calls, lib = fake
    ctrls = {"good": _controller(tmp_path, lib, "good", "1.0"), "bad": _controller(tmp_path, lib, "bad", "FAIL")}
    with pytest.warns(RuntimeWarning, match=r"(?s)2 of 4 OpenFAST runs failed.*seed 1.*Aborting OpenFAST"):
        camp = run_openfast_campaign(ctrls, [19.0], 2, deck=iea15mw_monopile(), duration=20.0, transient=5.0,
                                     install=inst, folder=tmp_path / "c", initial_conditions=False)
    assert camp.unstable.tolist() == [[False], [True]]
    assert np.isfinite(camp.values["tower_del"][0]).all() and np.isnan(camp.values["tower_del"][1]).all()
    assert "Invalid parameter file" in (tmp_path / "c" / "failures.txt").read_text()


def test_run_campaign_dispatches_to_openfast(tmp_path, fake):
    inst, calls, lib = fake
    camp = run_campaign({"A": _controller(tmp_path, lib, "a", "1.0")}, [19.0], [3], plant=iea15mw_monopile(),
                        duration=20.0, transient=5.0, store=tmp_path / "s",
                        openfast={"install": inst, "initial_conditions": False})
    assert camp.values["tower_del"].shape == (1, 1, 1) and np.isfinite(camp.values["tower_del"]).all()
    assert (tmp_path / "s" / "A" / "19mps_seed3" / "run.json").is_file()
    with pytest.raises(TypeError, match="export_discon"):
        run_campaign({"lti": object()}, [19.0], [3], plant=iea15mw_monopile(), openfast={"install": inst})


def test_pitch_sources_split_the_pitch_rate_by_measurement(benchmark_script, tmp_path):
    # openfast_report.pitch_sources: a run whose pitch is exactly C_β acting on the generator speed
    # (S_β = |C_β|² S_Ω, no acceleration) reads all of its pitch-rate variance "through the
    # generator speed" and none through the acceleration, band by band; the acceleration's part
    # is |C_atd/jω|² S_a; a run without the acceleration's spectrum (made before it was kept) is
    # skipped. Band integrals by hand (trapezoid of ω² S on the band's grid points); the table prints
    # 3 significant digits, hence rel 5e-3.
    from specdesign.validate.openfast_campaign import OpenFASTRun

    rep = benchmark_script("openfast_report")
    w = np.linspace(0.0, 31.4, 1025)
    cb, ca = ct.tf([-2.0, -0.5], [1.0, 0.8]), ct.tf([0.3, 0.0], [1.0, 2.0])
    s_om = 1e-4 / (1 + (w / 3.0) ** 2)
    gb = np.abs(np.squeeze(cb(1j * w))) ** 2
    welch = {"gen_speed": s_om, "pitch": gb * s_om, "tower_top_acc": np.zeros_like(w)}
    run = OpenFASTRun("QFT+ATD+3P", 19.0, 0, {}, w, welch, {}, tmp_path)
    design = type("D", (), {"pitch_controller": cb, "atd_controller": ca})()
    made = {"QFT+ATD+3P": {19.0: {"design": design}}}
    rows = [r.split(" | ") for r in rep.pitch_sources([run], made).splitlines()[2:]]
    assert len(rows) == len(rep.SOURCE_BANDS)
    for (lo, hi), row in zip(rep.SOURCE_BANDS, rows):
        m = (w >= lo) & (w < hi)
        want = rep.DEG**2 * np.trapezoid((w**2 * gb * s_om)[m], w[m])
        measured, speed, acc = (float(c.strip(" |")) for c in row[4:7])
        assert measured == pytest.approx(want, rel=5e-3) and speed == pytest.approx(want, rel=5e-3) and acc == 0.0
        # the generator speed's spectrum falls with ω: its peak in a band is the band's first grid point
        assert float(row[7].strip(" |")) == pytest.approx(w[m][0], abs=5e-3)
    s_a = np.full_like(w, 1e-3)
    run_a = dataclasses.replace(run, welch=dict(welch, tower_top_acc=s_a))
    row = rep.pitch_sources([run_a], made).splitlines()[-1].split(" | ")
    m = (w >= 5.0) & (w < 20.0)
    want = rep.DEG**2 * np.trapezoid((w**2 * np.abs(np.squeeze(ca(1j * w)) / (1j * w)) ** 2 * s_a)[m], w[m])
    assert float(row[6].strip(" |")) == pytest.approx(want, rel=5e-3)
    older = dataclasses.replace(run, welch={k: a for k, a in welch.items() if k != "tower_top_acc"})
    assert rep.pitch_sources([older], made).startswith("No run")
