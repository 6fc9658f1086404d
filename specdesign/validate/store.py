"""Resumable campaign results: one file per (wind speed, seed, controller) cell.

``run_campaign(..., store=path)`` writes every finished run here and, run again with the
same path, loads the cells already there and simulates only the missing ones, so an
interrupted campaign resumes where it stopped and a campaign grows by more seeds, wind
speeds or controllers without rerunning anything. The final
:class:`~specdesign.validate.Campaign` is assembled from the cells in both cases: bitwise
the same as an uninterrupted run.

Layout of ``path``::

    manifest.json        settings of the campaign and fingerprints of model and controllers
    index.csv            one row per stored cell: wind_speed, seed, controller, file,
                         unstable and the five indicators (pandas.read_csv reads it)
    cells/*.nc           one NetCDF-3 file per cell (xarray.open_dataset reads each one;
                         xarray.open_mfdataset(..., combine="nested", concat_dim="cell") all)

Why a directory of per-cell NetCDF files and not one Zarr or Parquet store: the cell is the
unit of resumption, and a file written to a temporary name and renamed (atomic on POSIX) is
either there whole or not at all, so a campaign killed at any instant leaves no half-written
cell and needs no lock or repair; cells are written by the one process that runs
:func:`~specdesign.validate.run_campaign` (workers of a cluster return results, they never
touch the store), so the store needs no shared file system. NetCDF-3 is written by
``scipy.io`` (already a dependency, no new package), stores float64 bit for bit (the
resumed campaign is bitwise the uninterrupted one) and is read by xarray, netCDF4 and every
NetCDF tool. The index is derived from the cells and rewritten (atomically) after every
finished task, so pandas gets the indicators of every cell in one table without opening
the cells.

A cell file holds the scalar indicators (``tower_del``, ... ; ``linear_*`` and
``volterra_*`` when the campaign computes them), ``predicted_del``, ``unstable``, the
per-seed Welch spectra ``welch_<output>(omega)``, the linear prediction
``predicted_psd_<output>(omega)`` of its (wind speed, controller), and with ``keep_series``
the records ``series_<output>(time)``; the scalar variables ``wind_speed`` and ``seed`` and
the global attribute ``controller`` name the cell, and the global attribute ``checksum`` (SHA-256
of the controller's name and every variable's name, shape and float64 bytes) seals it.

On resume every stored cell is verified before it is used: it must read, carry the
coordinates its file name promises (a file copied or renamed under another seed's name is
caught) and match its checksum. A cell that fails is said (one RuntimeWarning naming the
file and why) and recomputed, its file replaced. Opening a store writes nothing unless the
campaign adds to it (a new store, or new controllers in the manifest), so a finished store
in a read-only folder is read as it is; temporary files a killed writer left behind
(``.<name>.<pid>.tmp`` of a process no longer running) are removed when the store is next
opened for writing.
"""
from __future__ import annotations

import csv
import hashlib
import json
import os
import pickle
import re
import warnings
from pathlib import Path

import numpy as np

from .._files import atomic_write as _atomic_write
from .metrics import INDICATORS

__all__ = ["CampaignStore", "fingerprint"]

#: version of the layout above; a store of another version is refused (3: per-cell checksums)
FORMAT = 3
#: A temporary file of :func:`specdesign._files.atomic_write`: ``.<name>.<pid>.tmp``.
_TMP = re.compile(r"^\..+\.(\d+)\.tmp$")


class CellError(ValueError):
    """A stored cell that cannot be used (unreadable, another cell's data, a checksum mismatch)."""


def fingerprint(obj) -> str:
    """A stable digest of a model or controller: SHA-256 of its pickle.

    Parameters
    ----------
    obj : object
        A turbine model, a controller or any picklable object.

    Returns
    -------
    str
        64 hex digits; for an object pickle refuses (a lambda, a local class), its type's
        qualified name prefixed by "unpicklable:" (a weaker check: only the type is compared).

    Examples
    --------
    >>> fingerprint((1.0, "a")) == fingerprint((1.0, "a")), fingerprint((1.0, "a")) == fingerprint((2.0, "a"))
    (True, False)
    """
    try:
        return hashlib.sha256(pickle.dumps(obj, protocol=4)).hexdigest()
    except (pickle.PicklingError, TypeError, AttributeError):
        return "unpicklable:" + type(obj).__qualname__


class CampaignStore:
    """The cells of one campaign in a directory (layout: module docstring).

    Parameters
    ----------
    path : str or os.PathLike
        The store's directory (created if missing).
    settings : dict
        The campaign's settings (JSON-serialisable: duration, steps, m, ...); a store made
        with other settings is refused.
    model : str
        :func:`~specdesign.validate.store.fingerprint` of the turbine model.
    controllers : dict
        Controller name → :func:`~specdesign.validate.store.fingerprint`. Names new to the store are added; a name
        stored with another fingerprint is refused.

    Raises
    ------
    ValueError
        ``path`` exists and is not a directory, or holds a campaign of another format,
        settings, model or controller definition (the message names what differs; use
        another path to keep both).
    """

    def __init__(self, path, settings: dict, model: str, controllers: dict):
        self.path = Path(path)
        if self.path.exists() and not self.path.is_dir():
            raise ValueError(f"store={str(path)!r} is a file; give a directory (it is created if missing)")
        if not (self.path / "cells").is_dir():
            (self.path / "cells").mkdir(parents=True, exist_ok=True)
        _remove_stale_tmp(self.path)
        manifest = {"format": FORMAT, "settings": settings, "model": model, "controllers": dict(controllers)}
        mpath = self.path / "manifest.json"
        old = None
        if mpath.exists():
            try:
                old = json.loads(mpath.read_text())
                if not isinstance(old, dict) or not isinstance(old.get("controllers"), dict):
                    raise ValueError("not a JSON object with 'controllers'")
            except (ValueError, UnicodeDecodeError) as e:
                raise ValueError(f"{mpath}: not a readable campaign manifest ({e}); it may have been truncated: "
                                 "remove the store's folder to start afresh, or give another store path") from None
            for key in ("format", "settings", "model"):
                if old.get(key) != manifest[key]:
                    raise ValueError(f"store {str(path)!r} holds a campaign with another {key} ({old.get(key)!r}, now "
                                     f"{manifest[key]!r}): resume it with the same {key}, or give another store path")
            for name, fp in controllers.items():
                if old["controllers"].get(name, fp) != fp:
                    raise ValueError(f"store {str(path)!r}: controller {name!r} differs from the one stored under that "
                                     "name; rename it or give another store path")
            manifest["controllers"] = {**old["controllers"], **controllers}
        if manifest != old:  # never rewritten on a read: a finished store in a read-only folder opens
            _atomic_write(mpath, lambda p: p.write_text(json.dumps(manifest, indent=1, sort_keys=True)))
        self._rows = {}

    @staticmethod
    def cell_file(v: float, seed: int, controller: str) -> str:
        """File name of a cell (under ``cells/``).

        Parameters
        ----------
        v : float
            Wind speed (m/s).
        seed : int
            Seed.
        controller : str
            Controller name (any string: it enters the name as a digest).

        Returns
        -------
        str
            ``v<v>_s<seed>_c<12 hex digits>.nc``.
        """
        tag = hashlib.sha256(controller.encode()).hexdigest()[:12]
        return f"v{float(v)!r}_s{int(seed)}_c{tag}.nc"

    def load(self, cells) -> dict:
        """The stored cells among ``cells``.

        Parameters
        ----------
        cells : iterable of (float, int, str)
            (wind speed in m/s, seed, controller name) of the cells wanted.

        Returns
        -------
        dict
            (v, seed, controller) → cell record (the form :meth:`~specdesign.validate.store.CampaignStore.write` takes) for every
            wanted cell that is stored and verified; missing ones are absent, and so are
            those that fail verification (the caller recomputes them).

        Warns
        -----
        RuntimeWarning
            For each stored cell that fails verification (truncated or unreadable, another
            cell's coordinates, a checksum mismatch): the file and the reason.
        """
        out = {}
        for cell in cells:
            f = self.path / "cells" / self.cell_file(*cell)
            if f.exists():
                try:
                    out[cell] = _read_cell(f, cell)
                except CellError as e:
                    warnings.warn(f"campaign store: {f}: {e}; the cell is recomputed", RuntimeWarning, stacklevel=2)
                    continue
                self._rows[cell] = _index_row(cell, f.name, out[cell])
        return out

    def write(self, records: dict) -> None:
        """Store finished cells (each file atomically) and rewrite the index.

        Parameters
        ----------
        records : dict
            (v, seed, controller) → cell record: ``values``, ``linear``, ``volterra``
            (indicator → float), ``welch``, ``ppsd`` (output → (nω,) array), ``pred``
            (float), ``unstable`` (bool), ``omega`` ((nω,) rad/s) and ``series`` (None, or
            output → (n,) array with ``time``, ``dt``, ``sim_dt``).
        """
        for cell, rec in records.items():
            name = self.cell_file(*cell)
            _atomic_write(self.path / "cells" / name, lambda p, c=cell, r=rec: _write_cell(p, c, r))
            self._rows[cell] = _index_row(cell, name, rec)
        rows = [self._rows[c] for c in sorted(self._rows)]

        def write_index(p):
            with open(p, "w", newline="") as fh:
                w = csv.writer(fh)
                w.writerow(["wind_speed", "seed", "controller", "file", "unstable", *INDICATORS])
                # repr: the shortest string that reads back as the same float64
                w.writerows([[repr(x) if isinstance(x, float) else x for x in r] for r in rows])

        _atomic_write(self.path / "index.csv", write_index)


def _index_row(cell, name, rec):
    v, seed, controller = cell
    return [float(v), int(seed), controller, f"cells/{name}", int(rec["unstable"]),
            *(float(rec["values"][k]) for k in INDICATORS)]


def _remove_stale_tmp(path: Path) -> None:
    """Remove the temporary files of writers no longer running (a killed campaign's); a live
    process's are left alone, and a folder that cannot be written is left as it is."""
    for folder in (path, path / "cells"):
        try:
            names = [p for p in folder.iterdir() if _TMP.match(p.name)]
        except OSError:
            continue
        for p in names:
            pid = int(_TMP.match(p.name).group(1))
            try:
                os.kill(pid, 0)  # signal 0: does the process exist (no signal is sent)
                continue  # still running: its file
            except ProcessLookupError:
                pass
            except (PermissionError, OverflowError):  # another user's live process, or no such pid
                continue
            try:
                p.unlink()
            except OSError:
                pass


def _checksum(controller: str, var: dict) -> str:
    """SHA-256 of a cell: the controller's name and every variable's name, shape and float64 bytes."""
    h = hashlib.sha256(str(controller).encode())
    for k in sorted(var):
        a = np.ascontiguousarray(var[k], dtype="<f8")
        h.update(f"\0{k}\0{a.shape}\0".encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _write_cell(path, cell, rec):
    from scipy.io import netcdf_file

    v, seed, controller = cell
    # (type, dimension, value) of every variable, in file order; the checksum is over these
    var = {"wind_speed": ("d", (), float(v)), "seed": ("i", (), int(seed)), "omega": ("d", ("omega",), rec["omega"])}
    scalars = {"predicted_del": rec["pred"]}
    for group, prefix in (("values", ""), ("linear", "linear_"), ("volterra", "volterra_")):
        scalars.update({prefix + k: x for k, x in rec[group].items()})
    var.update({k: ("d", (), float(x)) for k, x in scalars.items()})
    var["unstable"] = ("b", (), int(rec["unstable"]))
    for k in rec["welch"]:
        var[f"welch_{k}"] = ("d", ("omega",), rec["welch"][k])
        var[f"predicted_psd_{k}"] = ("d", ("omega",), rec["ppsd"][k])
    s = rec["series"]
    if s is not None:
        var["series_dt"] = ("d", (), float(s["dt"]))
        var["series_sim_dt"] = ("d", (), float(s["sim_dt"]))
        var["series_time"] = ("d", ("time",), s["time"])
        var.update({f"series_{k}": ("d", ("time",), x) for k, x in s["outputs"].items()})
    with netcdf_file(path, "w", version=2) as f:
        # numbers as variables, not attributes: scipy writes a float attribute as float32
        f.controller = str(controller)
        f.checksum = _checksum(controller, {k: np.asarray(x, dtype=float) for k, (_, _, x) in var.items()})
        f.createDimension("omega", rec["omega"].size)
        if s is not None:
            f.createDimension("time", s["time"].size)
        for k, (typ, dims, x) in var.items():
            f.createVariable(k, typ, dims)[...] = x


def _read_cell(path, cell=None):
    """The record of a cell file, verified: it reads, carries ``cell``'s coordinates (when
    given) and its checksum; CellError otherwise."""
    from scipy.io import netcdf_file

    try:
        with netcdf_file(path, "r", mmap=False) as f:
            var = {k: np.array(x.data, dtype=float) for k, x in f.variables.items()}
            controller = f.controller.decode() if isinstance(f.controller, bytes) else str(f.controller)
            stored = getattr(f, "checksum", b"")
    except Exception as e:  # a truncated file fails in scipy's reader with whatever it met: ValueError, OSError, ...
        raise CellError(f"unreadable ({type(e).__name__}: {e})") from None
    stored = stored.decode() if isinstance(stored, bytes) else str(stored)
    if cell is not None:
        v, seed, name = cell
        here = (float(var.get("wind_speed", np.nan)), float(var.get("seed", np.nan)), controller)
        if here != (float(v), float(seed), name):
            raise CellError(f"holds the cell (wind speed {here[0]!r} m/s, seed {here[1]:g}, controller {here[2]!r}), not "
                            f"the one its name stands for ({float(v)!r} m/s, seed {int(seed)}, {name!r})")
    if stored != _checksum(controller, var):
        raise CellError("its data do not match its checksum (changed after it was written)" if stored else
                        "it has no checksum")
    for k in ("omega", "predicted_del", "unstable"):
        if k not in var:
            raise CellError(f"lacks the variable {k!r}")
    rec = {"values": {}, "linear": {}, "volterra": {}, "welch": {}, "ppsd": {}, "omega": var["omega"],
           "pred": float(var["predicted_del"]), "unstable": bool(var["unstable"]), "series": None}
    for k, x in var.items():
        for prefix, group in (("linear_", "linear"), ("volterra_", "volterra"), ("", "values")):
            if k.startswith(prefix) and k[len(prefix):] in INDICATORS:
                rec[group][k[len(prefix):]] = float(x)
                break
        if k.startswith("welch_"):
            rec["welch"][k[6:]] = x
        elif k.startswith("predicted_psd_"):
            rec["ppsd"][k[14:]] = x
    if "series_time" in var:
        rec["series"] = {"time": var["series_time"], "dt": float(var["series_dt"]), "sim_dt": float(var["series_sim_dt"]),
                         "outputs": {k[7:]: x for k, x in var.items()
                                     if k.startswith("series_") and k not in ("series_time", "series_dt", "series_sim_dt")}}
    return rec
