"""Campaigns in OpenFAST: controllers × wind speeds × seeds on a deck, TurbSim winds, OpenFAST
processes in parallel, one folder per run (resumable), the same :class:`Campaign` record as
on the reduced model.

:func:`specdesign.validate.run_campaign` dispatches here when given
``plant=specdesign.openfast.Deck(...)``.
"""
from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import math
import os
import sys
import tempfile
import warnings
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from tqdm.auto import tqdm

from ..controller.discon_file import read_discon
from ..export.forward import Forwarded, ForwardServer
from ..export.parameters import FORMAT_NAME, SAME_DESIGN_RTOL, read_parameters
from ..fatigue import TOWER_M
from ..openfast.deck import CAMPAIGN_CHANNELS, Case, Deck, OpenFASTRunError, named_digest, run_case, wave_seed_for, write_case
from ..openfast.install import OpenFASTInstall, check_deck_version, find_openfast
from ..openfast.series import OPENFAST_CHANNELS, series_from_openfast
from ..openfast.turbsim import TURBSIM_GRID, turbsim_field
from ..rosco.discon import rosco_library
from ..simulate import SimulationResult
from ..turbine import iea15mw
from ..wind import RECORD_LENGTH
from ._point import SPECTRA
from .campaign_record import Campaign
from .metrics import INDICATORS, indicators
from .stats import seeds_from, welch_psd
from .store import fingerprint

__all__ = ["run_openfast_campaign", "DisconController", "as_discon", "OPENFAST_SERIES", "OPENFAST_SPECTRA",
           "OpenFASTRun", "read_openfast_runs", "ran_parameters", "kept_change"]

#: OpenFAST channel → workbench series of an OpenFAST campaign (SI after reading).
OPENFAST_SERIES = {**OPENFAST_CHANNELS, "RootMyb1": "blade_root_my", "YawBrTAxp": "tower_top_acc"}
#: Outputs whose Welch spectra an OpenFAST run keeps: the campaign's, the pitch angle's own, for
#: the actuator's cost at 3P and above (issue 28: the reduced model has no 3P to show), and the
#: tower-top fore-aft acceleration's, the tower damper's input, to tell which measurement carries
#: the pitch's content above 3P (runs made before 2026-11-28 18:30 UTC lack it).
OPENFAST_SPECTRA = SPECTRA + ("pitch", "tower_top_acc")


@dataclass(frozen=True)
class DisconController:
    """A Bladed-interface controller as OpenFAST's ServoDyn runs it: a library and its parameter file.

    Parameters
    ----------
    library : pathlib.Path
        The compiled ``DISCON`` library.
    parameters : pathlib.Path
        The file it reads at initialisation (ServoDyn's ``DLL_InFile``).
    dt : float or None
        Its sample time (s), ServoDyn's ``DLL_DT`` (an exported design's ``dt``); None: the
        deck's (ROSCO is called every time step).
    """

    library: Path
    parameters: Path
    dt: float | None = None


@dataclass(frozen=True)
class OpenFASTRun:
    """One finished run of an OpenFAST campaign folder, as :func:`read_openfast_runs` reads it.

    Parameters
    ----------
    controller : str
        The controller's name in the campaign (its folder's name).
    wind_speed : float
        Mean hub-height wind speed, m/s.
    seed : int
        The campaign's seed (TurbSim's is ``specdesign.wind.seed_for(wind_speed, seed)``).
    values : dict
        Indicator → value in its unit (:data:`~specdesign.validate.metrics.INDICATORS`; DELs in
        N·m, SDs in rad or rad/s, power in W, pitch travel in rad/h, time at the rate limit as a
        fraction of the record, -); an indicator the run predates is absent, never filled in.
    omega : numpy.ndarray
        Frequencies of the Welch spectra, rad/s.
    welch : dict
        Output → one-sided Welch PSD of the recorded run on ``omega`` (unit²·s/rad).
    meta : dict
        The run's ``run.json``: settings, the controller files' digests, TurbSim's seeds.
    folder : pathlib.Path
        The run's folder (OpenFAST's log and summaries are kept there).
    series : dict
        Output → its recorded series after the transient (SI: rad/s, N·m, rad, W), sampled every
        ``meta["settings"]["record_dt"]`` s, for the seeds the campaign kept
        (``keep_series``); empty otherwise.
    """

    controller: str
    wind_speed: float
    seed: int
    values: dict
    omega: np.ndarray
    welch: dict
    meta: dict
    folder: Path
    series: dict = field(default_factory=dict)


def read_openfast_runs(folder) -> list[OpenFASTRun]:
    """The finished runs in an OpenFAST campaign folder, without running anything.

    A campaign still running (or stopped) is read as far as it got: a run counts once its
    ``run.json`` and ``result.npz`` are both there (written last, so a run in progress is
    skipped). Use it to tabulate a long campaign before it ends.

    Parameters
    ----------
    folder : str or pathlib.Path
        The ``folder`` given to :func:`run_openfast_campaign` (``store`` of
        :func:`specdesign.validate.run_campaign` with an OpenFAST plant).

    Returns
    -------
    list of OpenFASTRun
        Sorted by controller, wind speed and seed.

    Raises
    ------
    FileNotFoundError
        ``folder`` is not a directory.
    ValueError
        A run's files do not read (naming the folder).
    """
    root = Path(folder)
    if not root.is_dir():
        raise FileNotFoundError(f"folder {root} is not a directory: pass the campaign's folder (its store)")
    runs = []
    for js in sorted(root.glob("*/*mps_seed*/run.json")):
        npz = js.with_name("result.npz")
        if not npz.is_file():
            continue
        try:
            meta = json.loads(js.read_text())
            data = _read_result(npz)
        except (OSError, ValueError) as e:
            raise ValueError(f"run folder {js.parent} does not read ({e}): delete it to run it again") from e
        values = {k[len("value_"):]: float(a) for k, a in data.items() if k.startswith("value_")}
        welch = {k[len("welch_"):]: a for k, a in data.items() if k.startswith("welch_")}
        series = {k[len("series_"):]: a for k, a in data.items() if k.startswith("series_")}
        runs.append(OpenFASTRun(str(meta["controller"]), float(meta["wind_speed"]), int(meta["seed"]), values,
                                data["omega"], welch, meta, js.parent, series))
    return sorted(runs, key=lambda r: (r.controller, r.wind_speed, r.seed))


def as_discon(controller) -> DisconController:
    """A campaign controller as a :class:`DisconController`.

    Parameters
    ----------
    controller : object
        One with ``library`` and ``parameters`` (an exported design,
        ``specdesign.export.export_discon``'s record), a ``specdesign.rosco.Discon``
        (``library`` and ``discon_in``), or a path to a ROSCO ``DISCON.IN`` (run with the
        ``rosco`` package's library).

    Returns
    -------
    DisconController
        The library and parameter file, both existing.

    Raises
    ------
    TypeError
        Anything else (e.g. an LTI controller: OpenFAST runs compiled controllers; export it
        with ``specdesign.export.export_discon`` first; a Python controller such as an MPC
        runs wrapped in ``specdesign.export.forwarded``).
    FileNotFoundError
        The library or parameter file does not exist.
    """
    if isinstance(controller, (str, Path)):
        lib, par = rosco_library(), Path(controller)
    elif hasattr(controller, "library") and hasattr(controller, "parameters"):
        lib, par = Path(controller.library), Path(controller.parameters)
    elif hasattr(controller, "library") and hasattr(controller, "discon_in"):
        lib, par = Path(controller.library), Path(controller.discon_in)
    else:
        raise TypeError(f"an OpenFAST campaign runs Bladed-interface controllers: an object with .library and "
                        f".parameters (specdesign.export.export_discon), a specdesign.rosco.Discon, a DISCON.IN "
                        f"path, or a Python controller wrapped in specdesign.export.forwarded; got "
                        f"{type(controller).__name__} (export an LTI design with export_discon, forward an MPC with "
                        "forwarded(controller, dt=...))")
    for key, p in (("library", lib), ("parameters", par)):
        if not p.is_file():
            raise FileNotFoundError(f"controller {key} {p} does not exist")
    dt = getattr(controller, "dt", None)
    return DisconController(lib.resolve(), par.resolve(), None if dt is None else float(dt))


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()[:16]


def run_openfast_campaign(controllers: Mapping, wind_speeds, seeds, *, deck: Deck, duration: float = RECORD_LENGTH,
                          transient: float = 60.0, dt: float | None = None, record_dt: float = 0.05, m: float = TOWER_M,
                          folder=None, processes: int | None = None, progress: bool | None = None,
                          turbulence_class: str = "B", grid_points: int = TURBSIM_GRID["points"],
                          grid_size: float = TURBSIM_GRID["size"], hydro: bool = True, keep_series: bool | int = False,
                          nperseg: int | None = None, install: OpenFASTInstall | None = None,
                          cpu_limit: float | None = None, timeout: float | None = None, nice: int = 0,
                          initial_conditions: bool = True) -> Campaign:
    """Run every controller at every wind speed and seed in OpenFAST with TurbSim winds.

    Every run is a folder ``<folder>/<controller>/<speed>mps_seed<seed>/`` holding the case
    OpenFAST ran and ``result.npz`` (indicators, Welch spectra, the kept series) with
    ``run.json`` (what it ran: settings, controller files' digests, TurbSim seeds). Run again
    with the same folder, the finished runs are read back and only the missing ones run: an
    interrupted campaign resumes. A folder holding a run of other settings or another
    controller under the same name is refused. A failed run (OpenFAST error, timeout,
    TurbSim failure) is reported with its case, seed and the tail of OpenFAST's message, in
    a warning and in ``<folder>/failures.txt``; its values are NaN, its (controller, speed)
    is flagged ``unstable``, and the other runs are kept.

    Parameters
    ----------
    controllers : dict
        Name → Bladed-interface controller (:func:`as_discon`: an exported design's record, a
        ``specdesign.rosco.Discon``, or a ROSCO ``DISCON.IN`` path), or a Python controller
        wrapped in :func:`specdesign.export.forwarded` (an MPC): each of its runs gets its own
        :class:`~specdesign.export.ForwardServer` (a socket and a copy of the controller, in a
        thread of this process) beside its OpenFAST process, and the forwarding library as
        ServoDyn's controller. A failure of the Python side is reported as a failed run, with
        the end of the Python traceback.
    wind_speeds : array_like
        Mean hub-height wind speeds (m/s).
    seeds : int or sequence of int
        :func:`~specdesign.validate.seeds_from`; TurbSim's seed is
        ``specdesign.wind.seed_for(speed, seed)``, the same field for every controller.
    deck : Deck
        The OpenFAST deck (e.g. ``specdesign.openfast.iea15mw_monopile()``).
    duration : float, default 600.0
        Recorded time per run (s).
    transient : float, default 60.0
        Time simulated first and discarded (s).
    dt : float, optional
        OpenFAST's time step (s); default the deck's.
    record_dt : float, default 0.05
        Output spacing (s), a multiple of the time step.
    m : float, default 4.0
        Wöhler exponent of the tower-base DEL (the blade-root DEL uses m = 10).
    folder : str or os.PathLike, optional
        The campaign folder (resumable); default a temporary folder deleted at the end.
    processes : int, optional
        OpenFAST (and TurbSim) processes at a time; default the number of CPUs.
    progress : bool, optional
        A tqdm bar over the runs; None → only when stderr is a terminal.
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC NTM class of the TurbSim winds.
    grid_points, grid_size : int, float
        TurbSim grid (:data:`specdesign.openfast.turbsim.TURBSIM_GRID`).
    hydro : bool, default True
        SeaState and HydroDyn on (as the deck has them).
    keep_series : bool or int, default False
        Keep the recorded series of the first k seeds (True: all) in ``Campaign.series``.
    nperseg : int, optional
        Welch segment length (:func:`~specdesign.validate.welch_psd`).
    install : OpenFASTInstall, optional
        The executables; default :func:`specdesign.openfast.find_openfast`.
    cpu_limit, timeout : float, optional
        CPU-time and wall-clock limits per OpenFAST run (s); defaults those of
        :func:`specdesign.openfast.run_case` (10 s of CPU per simulated second + 120 s; no
        wall-clock limit).
    nice : int, default 0
        Niceness added to the OpenFAST processes.
    initial_conditions : bool, default True
        Start each run at the reduced IEA 15 MW model's trim (pitch, rotor speed) when the
        deck is an IEA-15-240-RWT deck: a shorter start-up transient.

    Returns
    -------
    Campaign
        Indicators (C, W, S), seed-averaged Welch spectra; ``predicted_del`` and
        ``predicted_psd`` are NaN (compiled controllers have no linear form here: take the
        prediction from the design).

    Raises
    ------
    TypeError
        ``controllers`` is not a non-empty dict, or holds a controller OpenFAST cannot run.
    ValueError
        Bad seeds, durations or steps, a deck of another OpenFAST version than the
        executable's, a folder holding another campaign's runs.
    """
    if not isinstance(controllers, dict) or not controllers:
        raise TypeError("controllers must be a non-empty dict {name: controller}")
    if not isinstance(deck, Deck):
        raise TypeError(f"deck must be a specdesign.openfast.Deck, got {type(deck).__name__}")
    discon = {str(n): c if isinstance(c, Forwarded) else as_discon(c) for n, c in controllers.items()}
    vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    seeds = seeds_from(seeds)
    for key, val in (("duration", duration), ("record_dt", record_dt)):
        if not val > 0:
            raise ValueError(f"{key}={val!r} must be positive (s)")
    if not transient >= 0:
        raise ValueError(f"transient={transient!r} must be ≥ 0 (s)")
    install = install or find_openfast()
    check_deck_version(install, deck.version, deck.fst)
    n_keep = len(seeds) if keep_series is True else int(keep_series)
    settings = {"deck": str(deck.fst), "deck_sha": deck.digest, "duration": float(duration),
                "transient": float(transient), "dt": dt, "record_dt": float(record_dt), "m": float(m),
                "turbulence_class": turbulence_class, "grid_points": int(grid_points), "grid_size": float(grid_size),
                "hydro": bool(hydro), "openfast": install.version, "initial_conditions": bool(initial_conditions),
                "nperseg": None if nperseg is None else int(nperseg), "waves": "wave_seed_for(speed, seed)"}
    trim = _trim(deck) if initial_conditions else None
    rate_limit = _rate_limit(deck)
    tmp = None
    if folder is None:
        tmp = tempfile.TemporaryDirectory(prefix="specdesign_openfast_")
        folder = tmp.name
    root = Path(folder).expanduser().resolve()
    root.mkdir(parents=True, exist_ok=True)
    runs = [(n, float(v), int(s)) for v in vs for s in seeds for n in discon]
    results, todo = {}, []
    for run in runs:
        meta = _meta(run, discon[run[0]], settings)
        done = _load(root, run, meta, discon[run[0]])
        if done is not None:
            results[run] = done
        else:
            todo.append((run, meta))
    show = sys.stderr.isatty() if progress is None else bool(progress)

    bar = tqdm(total=len(runs), initial=len(results), desc="OpenFAST", unit="run", disable=not show)
    failures = {}
    kept = set(seeds[:n_keep].tolist())

    def one(run, meta):
        name, v, s = run
        wind = turbsim_field(v, s, length=transient + duration, grid_points=grid_points, grid_size=grid_size,
                             turbulence_class=turbulence_class, install=install)
        c = discon[name]
        init = trim(v) if trim is not None else (None, None)

        def openfast(library, parameters):
            case = write_case(deck, _run_folder(root, run), tmax=transient + duration, wind_speed=v,
                              wind_file=wind.path, seed=s, library=library, parameters=parameters, controller_dt=c.dt,
                              dt=dt, dt_out=record_dt, channels=CAMPAIGN_CHANNELS, initial_pitch=init[0],
                              initial_rotor_speed=init[1], hydro=hydro, wave_seed=wave_seed_for(v, s) if hydro else None,
                              name=f"{_slug(name)}_{v:g}mps_seed{s}")
            return case, run_case(case, install, cpu_limit=cpu_limit, timeout=timeout, nice=nice)

        if isinstance(c, Forwarded):  # its own server (socket, controller copy) beside this OpenFAST process
            folder = _run_folder(root, run)
            folder.mkdir(parents=True, exist_ok=True)
            with ForwardServer(c) as server:
                try:
                    case, out = openfast(c.library, server.write(folder / _FORWARD_FILE))
                finally:  # the Python traceback says more than OpenFAST's "DISCON failed"
                    server.raise_error(f"{name} at {v:g} m/s, seed {s}: ")
                # the controller's cost per control step, recorded beside the run (not compared)
                meta = dict(meta, forwarded_calls=server.call_statistics())
            return _post(case, out, settings, meta, keep=s in kept, wind=wind, rate_limit=rate_limit)
        case, out = openfast(c.library, c.parameters)
        res = _post(case, out, settings, meta, keep=s in kept, wind=wind, rate_limit=rate_limit)
        _archive(root, name, Path(c.parameters), meta["parameters_sha"])
        return res

    try:
        with cf.ThreadPoolExecutor(processes or _cpus()) as pool:  # threads wait on OpenFAST processes
            futs = {pool.submit(one, run, meta): run for run, meta in todo}
            try:
                for f in cf.as_completed(futs):
                    run = futs[f]
                    try:
                        results[run] = f.result()
                    except (OpenFASTRunError, RuntimeError, ValueError, OSError) as e:
                        failures[run] = str(e)
                    bar.update(1)
            except BaseException:
                for f in futs:
                    f.cancel()
                raise
    finally:
        bar.close()
    if failures:
        text = "\n\n".join(f"{n} at {v:g} m/s, seed {s}: {msg}" for (n, v, s), msg in failures.items())
        (root / "failures.txt").write_text(text + "\n")
        warnings.warn(f"{len(failures)} of {len(runs)} OpenFAST runs failed (values NaN, flagged unstable; "
                      f"{root / 'failures.txt'}):\n{text}", RuntimeWarning, stacklevel=2)
    camp = _assemble(results, tuple(discon), vs, seeds, settings, n_keep)
    if tmp is not None:
        tmp.cleanup()
    return camp


#: The forwarding library's parameter file in a forwarded controller's run folder.
_FORWARD_FILE = "DISCON_forward.IN"


def _cpus() -> int:
    return os.cpu_count() or 1


def _trim(deck: Deck):
    """(pitch rad, rotor speed rad/s) at a wind speed from the reduced IEA 15 MW model, for an
    IEA-15-240-RWT deck; None for another deck (its own initial conditions are kept)."""
    if not deck.name.startswith("IEA-15-240-RWT"):
        return None

    model = iea15mw()

    def at(v):
        op = model.trim(v)
        return float(op.pitch), float(op.rotor_speed)

    return at


def _rate_limit(deck: Deck) -> float | None:
    """The turbine's pitch-rate limit (rad/s): ``PC_MaxRat`` of the deck's own DISCON.IN (ROSCO's
    file beside the ``.fst``, ``<name>_DISCON.IN``), the limit its controller applies; None
    without that file (the time at the limit is then NaN)."""
    path = deck.fst.with_name(deck.name + "_DISCON.IN")
    if not path.is_file():
        return None
    entry = read_discon(path)[0].get("PC_MaxRat")
    return None if entry is None else float(entry.values[0])


def _kept_file(root: Path, name: str, sha: str) -> Path:
    """Where the campaign keeps the parameter file of digest ``sha`` that ``name``'s runs ran."""
    return root / _slug(name) / "parameters" / f"{sha}.IN"


def _archive(root: Path, name: str, parameters: Path, sha: str) -> None:
    # a parameter file of the workbench's format, kept once per controller and digest beside its
    # runs: what ran stays readable after the design code changes (ran_parameters); after the run
    # is saved, so that a file that cannot be kept costs a warning, not the run
    out = _kept_file(root, name, sha)
    if out.exists():
        return
    try:
        text = parameters.read_bytes()
        if text.split(maxsplit=1)[:1] != [FORMAT_NAME.encode()]:
            return
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_bytes(text)
    except OSError as e:
        warnings.warn(f"{name}: the parameter file {parameters} was not kept in {out.parent} ({e}); "
                      "the report cannot compare a changed design with it", RuntimeWarning, stacklevel=2)


def ran_parameters(run: OpenFASTRun) -> Path | None:
    """The parameter file ``run`` ran, as the campaign kept it beside its runs, or None.

    Kept for controllers exported by :func:`specdesign.export.export_discon` (the workbench's
    format, read by :func:`specdesign.export.read_parameters`), by the digest in the run's
    ``run.json``; ROSCO's own files and forwarded Python controllers are not kept.

    Parameters
    ----------
    run : OpenFASTRun
        A run of :func:`read_openfast_runs`.

    Returns
    -------
    pathlib.Path or None
        ``<controller>/parameters/<digest>.IN`` in the store, if it is there.
    """
    f = Path(run.folder).parent / "parameters" / f"{run.meta.get('parameters_sha')}.IN"
    return f if f.is_file() else None


def kept_change(kept, parameters) -> float:
    """How far the controller of a kept parameter file is from that of ``parameters``: the largest
    relative change of a response (:meth:`~specdesign.export.DisconParameters.response_change`).

    Parameters
    ----------
    kept : str, pathlib.Path or None
        The file a run ran (:func:`ran_parameters`), None when the store did not keep it.
    parameters : str or pathlib.Path
        A parameter file of :func:`specdesign.export.export_discon` (the controller about to run).

    Returns
    -------
    float
        The change, ``inf`` when ``kept`` is None, missing or not the workbench's format (ROSCO's
        own file), or when a field other than the controller differs; compare it with
        :data:`~specdesign.export.parameters.SAME_DESIGN_RTOL`.
    """
    if kept is None:
        return math.inf
    try:
        return read_parameters(kept).response_change(read_parameters(parameters))
    except (OSError, ValueError):
        return math.inf


def _slug(name: str) -> str:
    """``name`` as an ASCII file name: "H∞+ATD" → "Hinf_ATD" (OpenFAST's Fortran opens the case's files by name)."""
    name = name.replace("∞", "inf")
    return "".join(ch if (ch.isascii() and ch.isalnum()) or ch in "-_." else "_" for ch in name)


def _run_folder(root: Path, run) -> Path:
    name, v, s = run
    return root / _slug(name) / f"{v:g}mps_seed{s}"


def _meta(run, c: DisconController | Forwarded, settings) -> dict:
    name, v, s = run
    if isinstance(c, Forwarded):
        # the controller's pickle and the library's parameters (the socket, which changes per run, aside)
        text = c.text("socket").encode() + fingerprint(c.controller).encode()
        lib = c.library
        return {"controller": name, "wind_speed": v, "seed": s, "controller_dt": c.dt,
                "library_sha": _sha(lib), "parameters_sha": hashlib.sha256(text).hexdigest()[:16],
                "library": str(lib), "parameters": f"forwarded Python controller {c.name!r}",
                "settings": settings}
    return {"controller": name, "wind_speed": v, "seed": s, "controller_dt": c.dt, "library_sha": _sha(c.library),
            "parameters_sha": named_digest(c.parameters), "library": str(c.library), "parameters": str(c.parameters),
            "settings": settings}


#: Recorded in run.json for the reader, not compared: where the deck, library and parameter file
#: lay (their digests are compared), so a checkout moved or a venv rebuilt finds its runs.
_LOCATIONS = ("deck",)


def _same(a: dict, b: dict) -> bool:
    keys = ("controller", "wind_speed", "seed", "controller_dt", "library_sha", "parameters_sha")

    def settings(m):
        return {k: v for k, v in (m.get("settings") or {}).items() if k not in _LOCATIONS}
    return all(a.get(k) == b.get(k) for k in keys) and settings(a) == settings(b)


def _controller_change(root: Path, run, old: dict, meta: dict, controller) -> float:
    """How far the exported controller a stored run ran is from ``controller`` (relative,
    :meth:`~specdesign.export.DisconParameters.response_change`), when that is all that differs
    between ``old`` and ``meta`` and the file it ran is kept; else inf."""
    if isinstance(controller, Forwarded) or not _same(old, dict(meta, parameters_sha=old.get("parameters_sha"))):
        return math.inf
    return kept_change(_kept_file(root, run[0], old.get("parameters_sha")), controller.parameters)


def _load(root: Path, run, meta, controller):
    """A finished run's results, or None; a run of other settings there is refused. A run of
    an exported controller within :data:`~specdesign.export.parameters.SAME_DESIGN_RTOL` of
    ``controller`` (the same design exported again, its last digits moved: another machine's
    linearisation) counts as its run, said by a warning. The parameter file of a run found with
    the same digest is kept if it was not (:func:`_archive`)."""
    f = _run_folder(root, run)
    js, npz = f / "run.json", f / "result.npz"
    if not (js.is_file() and npz.is_file()):
        return None
    old = json.loads(js.read_text())
    if not _same(old, meta):
        change = _controller_change(root, run, old, meta, controller)
        if not change <= SAME_DESIGN_RTOL:
            apart = f"; its controller's responses are {change:.2g} relative from this one's" if np.isfinite(change) else ""
            raise ValueError(f"{f} holds a run of other settings or another controller under the name {run[0]!r} "
                             f"(run.json differs{apart}): use another folder, or delete that run to redo it")
        warnings.warn(f"{f}: ran an earlier export of this design (responses {change:.1e} relative apart, within "
                      f"{SAME_DESIGN_RTOL:g}): counted as its run", RuntimeWarning, stacklevel=3)
    elif not isinstance(controller, Forwarded):  # the file that ran, kept if it was not
        _archive(root, run[0], Path(controller.parameters), meta["parameters_sha"])
    return _read_result(npz)


def _read_result(npz: Path) -> dict:
    """A run's ``result.npz`` as a dict of arrays (read whole: the file is closed after)."""
    with np.load(npz) as z:
        return {k: z[k] for k in z.files}


def _post(case: Case, out, settings, meta, keep: bool, wind, rate_limit: float | None = None) -> dict:
    """Indicators, Welch spectra and (kept) series of one OpenFAST run, saved in its folder
    (``rate_limit``: the pitch-rate limit, rad/s, for the time at it)."""
    t0 = settings["transient"]
    n = int(round(settings["duration"] / settings["record_dt"]))
    series, dt = series_from_openfast(out, OPENFAST_SERIES)
    i0 = int(np.searchsorted(out.time, t0 - 1e-9))
    if out.time.size - i0 < n:
        raise OpenFASTRunError(case, f"wrote {out.time[-1]:g} s, fewer than transient + duration "
                                     f"({t0 + settings['duration']:g} s)", "")
    rec = {k: a[0, i0:i0 + n] for k, a in series.items()}
    ind = indicators({k: a[None] for k, a in rec.items()}, dt, settings["m"], pitch_rate_limit=rate_limit).as_dict()
    res = {f"value_{k}": np.asarray(ind[k][0], float) for k in INDICATORS}
    for k in OPENFAST_SPECTRA:
        omega, p = welch_psd(rec[k], dt, settings["nperseg"])
        res[f"welch_{k}"] = p
    res["omega"] = omega
    res["dt"] = np.asarray(dt)
    if keep:
        for k, a in rec.items():
            res[f"series_{k}"] = a
    np.savez(case.folder / "result.npz", **res)
    meta = dict(meta, turbsim=wind.settings, wind_file=str(wind.path))
    (case.folder / "run.json").write_text(json.dumps(meta, indent=1) + "\n")
    # the case's big files go: the outputs are in result.npz, the inputs are rewritten on demand
    case.outb.unlink(missing_ok=True)
    return res


def _assemble(results, names, vs, seeds, settings, n_keep) -> Campaign:
    C, W, S = len(names), vs.size, seeds.size
    some = next(iter(results.values()), None)
    omega = some["omega"] if some is not None else np.zeros(1)
    values = {k: np.full((C, W, S), np.nan) for k in INDICATORS}
    welch = {k: np.full((C, W, omega.size), np.nan) for k in SPECTRA}
    unstable = np.zeros((C, W), bool)
    dt = float(some["dt"]) if some is not None else settings["record_dt"]
    n = int(round(settings["duration"] / settings["record_dt"]))
    keep = {}
    for ci, name in enumerate(names):
        for wi, v in enumerate(vs):
            acc = {k: [] for k in SPECTRA}
            for si, s in enumerate(seeds):
                r = results.get((name, float(v), int(s)))
                if r is None:
                    unstable[ci, wi] = True
                    continue
                for k in INDICATORS:  # a run post-processed before an indicator existed reads NaN for it
                    values[k][ci, wi, si] = float(r.get(f"value_{k}", np.nan))
                for k in SPECTRA:
                    acc[k].append(r[f"welch_{k}"])
                if si < n_keep:
                    for k in OPENFAST_SERIES.values():
                        keep.setdefault(name, {}).setdefault(k, np.full((W, n_keep, n), np.nan))[wi, si] = \
                            r.get(f"series_{k}", np.nan)
            for k in SPECTRA:
                if acc[k]:
                    welch[k][ci, wi] = np.mean(acc[k], axis=0)
    series = {}
    if n_keep and keep:

        for name, outs in keep.items():
            series[name] = SimulationResult(time=np.arange(n) * dt, wind_speeds=vs, seeds=seeds[:n_keep],
                                            outputs=outs, dt=dt, sim_dt=settings["dt"] or dt, controller=name)
    return Campaign(controllers=names, wind_speeds=vs, seeds=seeds, duration=settings["duration"], dt=dt,
                    m=settings["m"], values=values, predicted_del=np.full((C, W), np.nan), omega=omega, welch=welch,
                    predicted_psd={k: np.full((C, W, omega.size), np.nan) for k in SPECTRA}, series=series,
                    unstable=unstable)
