"""The OpenFAST campaign's store kept in the repository (``benchmarks/results/openfast_table3``):
the runs the documented OpenFAST tables come from. Nothing here runs OpenFAST: the store is read
as ``benchmarks/openfast_report.py`` reads it."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from specdesign import validate
from specdesign.openfast import iea15mw_monopile
from specdesign.turbine import iea15mw

ROOT = Path(__file__).resolve().parents[1]
RUNS = ROOT / "benchmarks" / "results" / "openfast_table3" / "runs"


@pytest.fixture(scope="module")
def runs():
    found = validate.read_openfast_runs(RUNS)
    assert found, f"{RUNS} holds no finished run: the documented OpenFAST tables have nothing behind them"
    return found


def test_the_scripts_default_to_the_repository_store(benchmark_script):
    assert benchmark_script("openfast_table3").STORE / "runs" == RUNS



def test_every_exported_controller_a_run_ran_is_kept_by_its_digest(runs):
    # what the report compares a changed design against (stale_designs): the parameter file each
    # run of an exported controller ran, kept once per digest; a file whose digest is not its name
    # would be compared as something it is not
    from specdesign.export import read_parameters
    from specdesign.openfast.deck import named_digest
    from specdesign.validate.openfast_campaign import ran_parameters

    kept = sorted(RUNS.glob("*/parameters/*.IN"))
    assert kept, "no parameter file kept in the store"
    assert [f for f in kept if named_digest(f) != f.stem] == []
    exported = [r for r in runs if r.controller in ("QFT", "QFT+ATD", "H∞")]
    assert exported and [f"{r.controller} {r.wind_speed:g} seed {r.seed}" for r in exported if ran_parameters(r) is None] == []
    for f in kept:
        read_parameters(f)  # the workbench's format, readable

def test_the_stored_runs_were_made_on_the_shipped_deck(runs):
    # a deck changed after its runs would leave tables that no longer follow from the shipped files:
    # the campaign must run again (into an emptied store)
    # (its digest covers every file the .fst names, in turn: Deck.digest)
    deck = iea15mw_monopile()
    sha = deck.digest
    stale = sorted({f"{r.controller} {r.wind_speed:g} m/s seed {r.seed}" for r in runs
                    if r.meta["settings"]["deck_sha"] != sha})
    assert not stale, f"runs of another deck than {deck.fst}: {stale}"
    # Table 3's setting (the paper's): 600 s recorded after 60 s discarded, class B, m = 4
    settings = {(s["duration"], s["transient"], s["turbulence_class"], s["m"]) for s in (r.meta["settings"] for r in runs)}
    assert settings == {(600.0, 60.0, "B", 4.0)}


def test_every_change_the_store_gives_is_in_the_docs_as_printed(runs, benchmark_script):
    # docs/openfast.md's tables of paired changes are openfast_report.py's output spliced in: every row
    # the repository's store gives (per speed, controller and paired seeds, against ROSCO and against
    # ROSCO+TD) must stand there to the printed digit, or the docs were not regenerated from the store
    report = benchmark_script("openfast_report").report(RUNS, runs)
    rows = [line for line in report.splitlines() if re.match(r"\| \d+(\.\d+)? \| ", line)]
    assert rows
    docs = (ROOT / "docs" / "openfast.md").read_text()
    missing = [row for row in rows if row not in docs]
    assert not missing, "rows of `python benchmarks/openfast_report.py` not in docs/openfast.md:\n" + "\n".join(missing)
    # ... and each in its own table (the runs', the second baseline's, the bands'), in order:
    # the page is what `openfast_report.py --docs docs/openfast.md` leaves it
    assert benchmark_script("openfast_report").splice(docs, report)[0] == docs


def test_the_docs_splice_replaces_inserts_in_order_and_keeps_what_the_store_lacks(benchmark_script):
    # a row of the same (wind, controller) is replaced, a new one goes where wind then controller
    # order puts it, and a row the store does not give stays and is returned (said by --docs)
    splice = benchmark_script("openfast_report").splice
    head = "| wind (m/s) | controller | tower DEL (%) |\n|---|---|---|\n"
    page = "text\n\n" + head + "| 15 | QFT+ATD | -1.0 |\n| 21 | QFT+ATD | -3.0 |\n\nafter\n"
    printed = "Finished\n\n" + head + "| 15 | QFT+ATD | -2.0 |\n| 19 | ROSCO+TD | -8.2 |\n| 19 | QFT | +0.0 |\n"
    text, kept = splice(page, printed)
    assert text == ("text\n\n" + head + "| 15 | QFT+ATD | -2.0 |\n| 19 | QFT | +0.0 |\n| 19 | ROSCO+TD | -8.2 |\n"
                    "| 21 | QFT+ATD | -3.0 |\n\nafter\n")
    assert kept == ["| 21 | QFT+ATD | -3.0 |"]
    with pytest.raises(SystemExit, match="0 tables headed"):
        splice("no table here\n", printed)


def test_table3_as_far_as_the_runs_give_it_is_in_the_docs_as_printed(runs, benchmark_script):
    # Table 3's title (seeds per speed), OpenFAST rainflow and pitch-rate rows follow from the runs
    # alone (the other rows need the designs made again: `openfast_report.py --table3 --docs`);
    # a block whose speeds or seeds the store does not back was not regenerated from it
    rep = benchmark_script("openfast_report")
    docs = (ROOT / "docs" / "openfast.md").read_text().splitlines()
    titles = [i for i, line in enumerate(docs) if rep._TABLE3_TITLE.match(line)]
    assert titles, "docs/openfast.md has no Table 3 block"
    for i in titles:
        name = re.match(r"\*\*([^*]+)\*\*", docs[i]).group(1)
        stats = rep.table3_stats(runs, name, {r.wind_speed for r in runs if r.controller == name})
        want = rep.table3_store_rows(name, stats)
        assert docs[i] == want.pop("title")
        block = {row.split(" | ")[0][2:]: row for row in docs[i:rep._table_end(docs, i)] if row.startswith("| ")}
        assert block["tower DEL reduction"] == "| tower DEL reduction | " + " | ".join(f"{v:g}" for v in stats) + " | mean |"
        for label, cells in want.items():
            assert block[label] == f"| {label} | " + " | ".join(cells) + " |", f"{name}: {label}"


def test_the_table3_splice_replaces_a_designs_block_whole(benchmark_script):
    splice = benchmark_script("openfast_report").splice_table3
    title = "**QFT+ATD** (tower-base DEL reduction against ROSCO; seeds per speed: {})"
    block = title + "\n\n| tower DEL reduction | {} | mean |\n|---|---|---|\n| rainflow, OpenFAST | {} |  |\n"
    page = ("intro\n\n" + block.format("15 m/s: 3", "15", "20.0 %") + "\nbetween\n\n"
            + block.replace("QFT+ATD", "QFT").format("19 m/s: 1", "19", "0.0 %") + "\nafter\n")
    printed = block.format("15 m/s: 4, 17 m/s: 4", "15 | 17", "21.0 % | 22.0 %")
    assert splice(page, printed) == page.replace(block.format("15 m/s: 3", "15", "20.0 %"), printed)
    with pytest.raises(SystemExit, match="0 Table 3 blocks"):
        splice("intro\n", printed)


def test_runs_of_another_design_than_the_code_makes_are_named(benchmark_script, monkeypatch, tmp_path):
    # the report's linear side (damping table, predictions, Table 3's prediction row) designs
    # again; runs made with an earlier design code must be named, not silently paired with it,
    # unless the file they ran (kept in the store by the campaign) holds the same controller to
    # SAME_DESIGN_RTOL: a change of the design code's last digits is not another experiment
    import dataclasses

    import control as ct

    from specdesign.export import discon_parameters, write_parameters
    from specdesign.openfast.deck import named_digest

    report = benchmark_script("openfast_report")
    base = discon_parameters(ct.tf([-2.0, -0.9, -0.1], [1.0, 1.2, 0.0]), model=iea15mw())

    def params(scale):  # the controller's output scaled: its responses change by scale − 1
        return dataclasses.replace(base, C=base.C * scale, D=base.D * scale, integrator_gain=base.integrator_gain * scale)

    def fake_export(design, folder, name, reduced):
        folder.mkdir(parents=True)
        return type("Export", (), {"parameters": write_parameters(params(design), folder / "DISCON.IN")})()

    monkeypatch.setattr(report, "export_design", fake_export)
    store = tmp_path / "runs" / "QFT_ATD"

    class Run:
        def __init__(self, speed, ran_scale, kept=True):
            f = write_parameters(params(ran_scale), tmp_path / f"ran{speed:g}.IN")
            sha = named_digest(f)
            if kept:  # as the campaign keeps it: <controller>/parameters/<digest>.IN
                (store / "parameters").mkdir(parents=True, exist_ok=True)
                (store / "parameters" / f"{sha}.IN").write_bytes(f.read_bytes())
            self.controller, self.wind_speed, self.meta = "QFT+ATD", speed, {"parameters_sha": sha}
            self.folder = store / f"{speed:g}mps_seed0"

    rtol = report.SAME_DESIGN_RTOL
    made = {"QFT+ATD": {v: {"design": 1.0} for v in (19.0, 21.0, 23.0, 25.0)}}
    runs = [Run(19.0, 1.0),  # the same file
            Run(21.0, 1.0 + rtol / 10),  # an earlier export within the tolerance: counted
            Run(23.0, 1.0 + rtol * 10),  # beyond it: another design
            Run(25.0, 1.0 + rtol / 5, kept=False)]  # the file it ran is not in the store: cannot tell
    stale = report.stale_designs(runs, made)
    assert [(label, v) for label, v, _ in stale] == [("QFT+ATD", 23.0), ("QFT+ATD", 25.0)]
    assert stale[0][2] == {runs[2].meta["parameters_sha"]}


def test_the_comparison_page_carries_the_stores_rows_at_its_speeds(runs, benchmark_script):
    # docs/comparison.md's OpenFAST section is `openfast_report.py --speeds 17,19 --docs
    # docs/comparison.md`: every row the store gives at openfast_comparison.SPEEDS stands there,
    # each in its own table, and nothing else does
    speeds = benchmark_script("openfast_comparison").SPEEDS
    report = benchmark_script("openfast_report")
    printed = report.report(RUNS, [r for r in runs if r.wind_speed in speeds])
    docs = (ROOT / "docs" / "comparison.md").read_text()
    text, kept = report.splice(docs, printed)
    assert text == docs
    assert not kept, f"rows in docs/comparison.md that the store does not give: {kept}"


def test_the_forwarded_controllers_cost_per_step_is_tabulated_from_the_runs(benchmark_script):
    # issue 31 item 5 (CPU per control step): run.json's forwarded_calls (ForwardServer.call_statistics),
    # median over runs of the runs' medians and the largest 99th percentile, in ms; runs made
    # before the campaign recorded it (no forwarded_calls) are left out, and no table without any
    costs = benchmark_script("openfast_report").forwarded_costs

    class Run:
        def __init__(self, name, speed, cpu=None):
            st = None if cpu is None else {"calls": 33000, "cpu_median_s": cpu, "cpu_p99_s": 3 * cpu,
                                           "wall_median_s": 2 * cpu, "wall_p99_s": 5 * cpu}
            self.controller, self.wind_speed, self.meta = name, speed, {"forwarded_calls": st} if st else {}

    assert costs([Run("ROSCO", 19.0), Run("MPC", 19.0)]) == []
    lines = costs([Run("MPC", 19.0, 1e-3), Run("MPC", 19.0, 3e-3), Run("MPC", 19.0, 2e-3), Run("MPC", 19.0)])
    assert lines[-1] == "| MPC | 19 | 3 | 33000 | 2.00 | 9.00 | 4.00 | 15.00 |"


@pytest.mark.parametrize("said, minutes", [("45.155 seconds", 45.155 / 60), ("14.237 minutes", 14.237),
                                           ("1.5 hours", 90.0)])
def test_openfast_times_read_the_unit_openfast_prints(benchmark_script, tmp_path, said, minutes):
    # OpenFAST closes with "Total CPU Time: <x> <seconds|minutes|hours>" by the run's length
    # (a 40 s run says seconds, a 660 s one minutes): the report's times are minutes whatever it says
    (tmp_path / "case.log").write_text(f"  Total Real Time:       {said}\n  Total CPU Time:        {said}\n")
    run = type("Run", (), {"folder": tmp_path})()
    assert benchmark_script("openfast_report").openfast_times(run) == pytest.approx((minutes, minutes), rel=1e-12)
