"""Resumable campaigns (run_campaign(store=...), specdesign.validate.store): an interrupted
campaign, rerun on its store, runs only the missing (wind speed, seed, controller) cells and
ends bitwise equal to the uninterrupted run (the oracle: the same campaign run in one go
without a store); the store is read by pandas and xarray and refuses another campaign."""
from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from specdesign import simulate as sm
from specdesign import turbine
from specdesign.validate import INDICATORS, run_campaign
from specdesign.validate import campaign as campaign_module
from specdesign.validate.store import CampaignStore

SPEEDS = [15.0, 19.0]
REAL_TASK = campaign_module.campaign_point
KW = dict(duration=30.0, transient=5.0, progress=False)


@pytest.fixture(scope="module")
def setup():
    model = turbine.iea15mw()
    ctrls = {"ROSCO": sm.rosco_scheduled(model), "PI19": turbine.rosco_baseline(model, 19.0)}
    return model, ctrls


def assert_bitwise_equal(a, b):
    """Every field of two Campaigns, arrays compared by their bytes (NaNs and signed zeros included)."""
    def same(x, y, path):
        if isinstance(x, dict):
            assert set(x) == set(y), path
            for k in x:
                same(x[k], y[k], f"{path}.{k}")
        elif dataclasses.is_dataclass(x):
            for f in dataclasses.fields(x):
                same(getattr(x, f.name), getattr(y, f.name), f"{path}.{f.name}")
        elif isinstance(x, np.ndarray):
            assert x.dtype == y.dtype and x.shape == y.shape, path
            assert np.ascontiguousarray(x).tobytes() == np.ascontiguousarray(y).tobytes(), path
        else:
            assert x == y, path

    same(a, b, "campaign")


class Interrupted(Exception):
    """A campaign stopped from outside (like a KeyboardInterrupt, without pytest's handling of one)."""


def recording(monkeypatch, fail_on=None):
    """Replace the task function by one that records (v, seeds, controllers) of every task and
    raises on the task whose (v, controllers) is ``fail_on`` (an interrupted campaign)."""
    calls, real = [], REAL_TASK

    def task(model, controllers, v, seeds, *args):
        if fail_on == (v, tuple(controllers)):
            raise Interrupted("campaign interrupted here")
        calls.append((v, tuple(seeds.tolist()), tuple(controllers)))
        return real(model, controllers, v, seeds, *args)

    monkeypatch.setattr(campaign_module, "campaign_point", task)
    return calls


def cells_of(calls):
    return {(v, s, n) for v, seeds, names in calls for s in seeds for n in names}


def test_interrupted_campaign_resumes_only_the_missing_cells_bitwise(setup, tmp_path, monkeypatch):
    model, ctrls = setup
    kw = dict(model=model, linear_twin=True, keep_series=2, **KW)
    ref = run_campaign(ctrls, SPEEDS, 3, **kw)  # uninterrupted, no store
    store = tmp_path / "camp"
    # interrupted while the second wind speed runs: the first one's 6 cells are stored
    recording(monkeypatch, fail_on=(19.0, ("ROSCO", "PI19")))
    with pytest.raises(Interrupted):
        run_campaign(ctrls, SPEEDS, 3, store=store, **kw)
    index = pd.read_csv(store / "index.csv")
    assert sorted(zip(index.wind_speed, index.seed, index.controller)) == sorted(
        (15.0, s, n) for s in range(3) for n in ctrls)
    # a cell lost as well (as if that run had never finished): the resumed run groups the
    # controllers by their missing seeds at each speed
    (store / "cells" / CampaignStore.cell_file(15.0, 1, "PI19")).unlink()
    calls = recording(monkeypatch)
    resumed = run_campaign(ctrls, SPEEDS, 3, store=store, **kw)
    assert sorted(calls) == [(15.0, (1,), ("PI19",)), (19.0, (0, 1, 2), ("ROSCO", "PI19"))]
    assert_bitwise_equal(resumed, ref)
    # everything stored: nothing runs, the same campaign again
    calls = recording(monkeypatch)
    again = run_campaign(ctrls, SPEEDS, 3, store=store, **kw)
    assert calls == []
    assert_bitwise_equal(again, ref)


def test_store_grows_by_seeds_and_controllers(setup, tmp_path, monkeypatch):
    model, ctrls = setup
    kw = dict(model=model, **KW)
    store = tmp_path / "grow"
    run_campaign({"ROSCO": ctrls["ROSCO"]}, [19.0], [4, 5], store=store, **kw)
    calls = recording(monkeypatch)
    grown = run_campaign(ctrls, [19.0], [4, 5, 6], store=store, **kw)
    # only the new seed of the stored controller and every seed of the new one ran
    assert cells_of(calls) == {(19.0, 6, "ROSCO")} | {(19.0, s, "PI19") for s in (4, 5, 6)}
    monkeypatch.undo()
    assert_bitwise_equal(grown, run_campaign(ctrls, [19.0], [4, 5, 6], **kw))


def test_store_is_read_by_pandas_and_xarray(setup, tmp_path):
    xr = pytest.importorskip("xarray")
    model, ctrls = setup
    store = tmp_path / "read"
    c = run_campaign(ctrls, SPEEDS, 2, model=model, store=store, **KW)
    # the index holds repr() of every float64: pandas' parser reads the same bits back
    index = pd.read_csv(store / "index.csv")
    assert len(index) == 2 * 2 * 2
    for row in index.itertuples():
        i, w, s = c.index(row.controller), SPEEDS.index(row.wind_speed), int(row.seed)
        for k in INDICATORS:
            assert getattr(row, k) == c.values[k][i, w, s]
        with xr.open_dataset(store / row.file) as ds:
            assert float(ds["tower_del"]) == c.values["tower_del"][i, w, s]
            assert ds.attrs["controller"] == row.controller
            assert float(ds["wind_speed"]) == row.wind_speed and int(ds["seed"]) == row.seed
            assert np.array_equal(ds["omega"].values, c.omega)
            assert np.array_equal(ds["predicted_psd_tower_base_my"].values, c.predicted_psd["tower_base_my"][i, w],
                                  equal_nan=True)
    # all cells at once, one "cell" dimension: the per-seed Welch spectra average to the campaign's
    files = sorted(store.glob("cells/*.nc"))
    with xr.open_mfdataset(files, combine="nested", concat_dim="cell") as ds:
        assert ds.sizes["cell"] == 8
        pick = [k for k, f in enumerate(files) if f.name in set(index.file[(index.controller == "PI19")
                                                                         & (index.wind_speed == 19.0)].str[6:])]
        avg = ds["welch_gen_speed"].isel(cell=pick).values.mean(axis=0)
    np.testing.assert_allclose(avg, c.welch["gen_speed"][c.index("PI19"), 1], rtol=1e-13)


def test_store_refuses_another_campaign(setup, tmp_path):
    model, ctrls = setup
    store = tmp_path / "refuse"
    run_campaign({"PI19": ctrls["PI19"]}, [19.0], [0], model=model, store=store, **KW)
    with pytest.raises(ValueError, match="settings"):
        run_campaign({"PI19": ctrls["PI19"]}, [19.0], [0], model=model, store=store, m=10.0, **KW)
    with pytest.raises(ValueError, match="'PI19' differs"):
        run_campaign({"PI19": turbine.rosco_baseline(model, 17.0)}, [19.0], [0], model=model, store=store, **KW)
    other = dataclasses.replace(model, rated_rotor_speed=model.rated_rotor_speed * 1.01)
    with pytest.raises(ValueError, match="model"):
        run_campaign({"PI19": ctrls["PI19"]}, [19.0], [0], model=other, store=store, **KW)
    (tmp_path / "a_file").write_text("")
    with pytest.raises(ValueError, match="is a file"):
        run_campaign({"PI19": ctrls["PI19"]}, [19.0], [0], model=model, store=tmp_path / "a_file", **KW)


def test_store_reruns_runs_whose_records_are_now_kept(setup, tmp_path, monkeypatch):
    # keep_series=1 keeps the first seed's records; the same store with the seeds reordered
    # must rerun the new first seed (stored without records), not show NaN records
    model, ctrls = setup
    kw = dict(model=model, keep_series=1, **KW)
    store = tmp_path / "reorder"
    run_campaign({"PI19": ctrls["PI19"]}, [19.0], [4, 5], store=store, **kw)
    calls = recording(monkeypatch)
    reordered = run_campaign({"PI19": ctrls["PI19"]}, [19.0], [5, 4], store=store, **kw)
    assert cells_of(calls) == {(19.0, 5, "PI19")}
    monkeypatch.undo()
    assert_bitwise_equal(reordered, run_campaign({"PI19": ctrls["PI19"]}, [19.0], [5, 4], **kw))
    assert np.all(np.isfinite(reordered.series["PI19"].outputs["tower_base_my"]))


def test_a_models_fingerprint_does_not_depend_on_its_history():
    # the store recognises a model by its pickle: trims, compiled tables and linearisations
    # computed on one instance must not make it another model; a changed field must
    from dataclasses import replace

    from specdesign.turbine import iea15mw
    from specdesign.validate.store import fingerprint

    used = iea15mw()
    fresh = fingerprint(iea15mw())
    used.trim(19.0)
    used.linearize(21.0)
    assert fingerprint(used) == fresh
    assert fingerprint(replace(used, air_density=1.2)) != fresh
