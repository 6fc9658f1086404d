"""Campaign-store doors (issue "Nothing silently wrong, part two"): every stored cell is
verified on resume (readable, its own coordinates, its checksum) and recomputed when it fails,
a store is never rewritten on a read (a finished store in a read-only folder opens), a
truncated manifest is an error naming its path, and temporary files are cleaned, a killed
writer's on the next open. The oracle of every recomputation: the same campaign run in one go
without a store, compared byte for byte."""
from __future__ import annotations

import dataclasses
import json
import subprocess
import warnings

import numpy as np
import pytest

from specdesign import turbine
from specdesign.validate import run_campaign
from specdesign.validate import store as store_module
from specdesign.validate.store import CampaignStore, CellError, _read_cell

KW = dict(duration=20.0, transient=5.0, progress=False, predict=False)


@pytest.fixture(scope="module")
def setup():
    model = turbine.iea15mw()
    ctrls = {"PI19": turbine.rosco_baseline(model, 19.0)}
    plain = run_campaign(ctrls, [19.0], [0, 1], model=model, **KW)
    return model, ctrls, plain


def _bitwise(a, b):
    for f in dataclasses.fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert x.tobytes() == y.tobytes(), f.name
        elif isinstance(x, dict):
            assert set(x) == set(y), f.name
            for k in x:
                if isinstance(x[k], np.ndarray):
                    assert x[k].tobytes() == y[k].tobytes(), (f.name, k)


@pytest.fixture
def stored(setup, tmp_path):
    model, ctrls, _ = setup
    path = tmp_path / "store"
    run_campaign(ctrls, [19.0], [0, 1], model=model, store=path, **KW)
    return path


def _cell(path, seed):
    return path / "cells" / CampaignStore.cell_file(19.0, seed, "PI19")


def _resume(setup, path, match):
    model, ctrls, plain = setup
    with pytest.warns(RuntimeWarning, match=match):
        again = run_campaign(ctrls, [19.0], [0, 1], model=model, store=path, **KW)
    _bitwise(again, plain)  # recomputed: the uninterrupted campaign's numbers
    return again


def test_a_cell_under_another_seeds_name_is_caught_and_recomputed(setup, stored):
    _cell(stored, 1).write_bytes(_cell(stored, 0).read_bytes())  # seed 0's data as seed 1's file
    _resume(setup, stored, r"s1_c.*\.nc: holds the cell \(wind speed 19.0 m/s, seed 0, controller 'PI19'\), not the one "
                           r"its name stands for \(19.0 m/s, seed 1, 'PI19'\); the cell is recomputed")
    assert _read_cell(_cell(stored, 1), (19.0, 1, "PI19"))  # its file replaced by the right one


@pytest.mark.parametrize("keep", [0, 100, 0.5, 0.99])
def test_a_truncated_cell_is_recomputed_naming_the_file(setup, stored, keep):
    f = _cell(stored, 0)
    data = f.read_bytes()
    f.write_bytes(data[:int(keep if keep >= 1 else keep * len(data))])
    _resume(setup, stored, r"s0_c.*\.nc: (unreadable|.*checksum).*; the cell is recomputed")


def test_a_changed_value_fails_its_checksum(setup, stored):
    from scipy.io import netcdf_file

    f = _cell(stored, 0)
    with netcdf_file(f, "r", mmap=False) as nc:
        omega = np.array(nc.variables["omega"].data, dtype=">f8").tobytes()  # NetCDF-3 stores big-endian
    data = bytearray(f.read_bytes())
    i = data.find(omega)
    assert i > 0
    data[i + 8 * 10 + 7] ^= 0x01  # the last mantissa bit of omega[10]: a file of the same size, still readable
    f.write_bytes(bytes(data))
    _resume(setup, stored, r"do not match its checksum \(changed after it was written\); the cell is recomputed")


def test_a_truncated_manifest_names_its_path(setup, stored):
    model, ctrls, _ = setup
    m = stored / "manifest.json"
    m.write_text(m.read_text()[:40])
    with pytest.raises(ValueError, match=rf"{m}: not a readable campaign manifest .*truncated"):
        run_campaign(ctrls, [19.0], [0, 1], model=model, store=stored, **KW)


def test_a_finished_store_is_never_written_on_read(setup, stored, monkeypatch):
    model, ctrls, plain = setup
    before = {p: p.stat().st_mtime_ns for p in stored.rglob("*")}

    def refuse(*a, **k):  # a read-only folder (chmod alone does not stop root, who runs CI here)
        raise PermissionError("read-only store")

    monkeypatch.setattr(store_module, "_atomic_write", refuse)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # every cell verifies
        again = run_campaign(ctrls, [19.0], [0, 1], model=model, store=stored, **KW)
    _bitwise(again, plain)
    assert {p: p.stat().st_mtime_ns for p in stored.rglob("*")} == before


def test_no_temporary_file_is_left_and_a_killed_writers_are_removed(setup, stored):
    model, ctrls, _ = setup
    assert not [p for p in stored.rglob("*") if p.name.endswith(".tmp")]
    dead = subprocess.Popen(["true"])
    dead.wait()  # a process that has ended: its pid names no running writer
    stale = [stored / f".index.csv.{dead.pid}.tmp", stored / "cells" / f".v19.0_s0_cx.nc.{dead.pid}.tmp"]
    live = stored / "cells" / f".v19.0_s1_cx.nc.{__import__('os').getpid()}.tmp"  # this process: a live writer
    for p in (*stale, live):
        p.write_bytes(b"half a cell")
    run_campaign(ctrls, [19.0], [0, 1], model=model, store=stored, **KW)
    assert not any(p.exists() for p in stale) and live.exists()


def test_read_cell_refuses_what_it_cannot_verify(stored):
    with pytest.raises(CellError, match="not the one its name stands for"):
        _read_cell(_cell(stored, 0), (19.0, 1, "PI19"))
    with pytest.raises(CellError, match="not the one its name stands for"):
        _read_cell(_cell(stored, 0), (19.0, 0, "another"))
    assert json.loads((stored / "manifest.json").read_text())["format"] == store_module.FORMAT
