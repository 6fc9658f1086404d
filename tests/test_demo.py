"""The main job: ``python -m specdesign demo`` at reduced size, and its hand-off to ``validate``."""
import csv

import numpy as np
import pytest

from specdesign import spec
from specdesign.demo import run_demo
from specdesign.turbine import iea15mw
from specdesign.cli import run_config


def _row(path, label):
    with open(path) as f:
        for r in csv.reader(f):
            if r[0] == label:
                return [float(x) for x in r[1:] if x]
    raise AssertionError(f"{label} not in {path}")


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    summary = run_demo(out=out, fast=True, n_seeds=3, duration=150.0)
    return out, summary


def test_demo_writes_every_artefact(demo):
    out, _ = demo
    for name in ("summary.md", "table2.md", "table2.csv", "table3.md", "table3.csv", "controller_qft.json",
                 "validate.toml", "1_sensitivity.png", "2_specification.png", "3_nichols.png", "3_bode.png",
                 "4_spectra.png", "4_time_series.png"):
        assert (out / name).is_file() and (out / name).stat().st_size > 0, name


def test_demo_numbers_agree_with_independent_calls(demo):
    out, s = demo
    # the promise is the one-call specification of spec.shape_to_target, recomputed here
    base = spec.baseline_analysis(iea15mw(), 19.0)
    assert s["promised_del_pct"] == pytest.approx(spec.shape_to_target(base, 15.0).promise.exact_del, rel=1e-9)
    assert s["baseline_del_MNm"] == pytest.approx(base.del_1hz / 1e6, rel=1e-12)
    # the tables on disk hold the numbers of the summary
    assert _row(out / "table3.csv", "Linear prediction")[0] == pytest.approx(s["predicted_del_pct"], rel=1e-12)
    assert _row(out / "table3.csv", "Rainflow evaluation")[0] == pytest.approx(s["rainflow_del_pct"], rel=1e-12)
    assert 20.0 <= s["predicted_del_pct"] <= 35.0
    assert s["rainflow_del_pct"] > 10.0


def test_validate_config_written_by_the_demo_reproduces_its_validation(demo):
    """The CLI path (TOML + controller JSON) gives the demo's numbers on the same seeds."""
    out, s = demo
    camp = run_config(out / "validate.toml", out=out / "validation")
    table3 = out / "validation" / "table3.csv"
    assert _row(table3, "Linear prediction")[0] == pytest.approx(s["predicted_del_pct"], abs=1e-6)
    assert _row(table3, "Rainflow evaluation")[0] == pytest.approx(s["rainflow_del_pct"], abs=1e-6)
    assert _row(table3, "Volterra prediction (order 3, rainflow, same seeds)")[0] == pytest.approx(
        s["volterra_del_pct"], abs=1e-6)
    assert np.array_equal(camp.seeds, np.arange(3)) and camp.volterra_order == 3
