"""Campaigns: controllers × wind speeds × paired seeds, simulated and post-processed into
indicators, Welch spectra, linear and Volterra predictions, with the up-front checks that
refuse a bad step before the first simulation."""
from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import queue
import sys
from collections.abc import Iterable, Mapping

import numba
import numpy as np
from tqdm.auto import tqdm

from .. import turbine
from .._blas import on_one_blas_thread
from .._checks import positive_scalar
from ..controller.noise import SensorNoise
from ..controller.torque import TorqueLaw
from ..export.forward import Forwarded
from ..fatigue import TOWER_M
from ..simulate import SimulationResult, check_step, turbine_plant
from ..simulate.checks import checked_loop
from ..wind import RECORD_LENGTH
from ._loop import has_linear_form
from .campaign_record import Campaign
from ._point import SPECTRA, campaign_point
from .metrics import INDICATORS
from .openfast_campaign import run_openfast_campaign
from .stats import seeds_from
from .store import CampaignStore, fingerprint

__all__ = ["run_campaign", "concat_campaigns", "check_plant_step", "check_campaign_step"]


def check_plant_step(model, wind_speeds, dt: float) -> None:
    """Refuse an integration step the plant's RK4 cannot resolve, before any simulation.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The plant (:func:`specdesign.simulate.turbine_plant` accepts it).
    wind_speeds : array_like
        Wind speeds of the campaign (m/s).
    dt : float
        Integration step (s).

    Raises
    ------
    ValueError
        ``dt`` is too large for the fastest mode of the linearised plant at some wind speed
        (the message gives the largest step it allows).
    """
    check_step(turbine_plant(model), np.asarray(wind_speeds, float), dt)


def check_campaign_step(model, controllers: Mapping, wind_speeds, dt: float) -> None:
    """Refuse, before the first simulation, a step too large for the plant or for a controller.

    :func:`specdesign.simulate.simulate` would refuse such a step at that wind speed only after
    the earlier speeds had run. A controller whose loop is unstable at a speed is not checked
    there (the campaign reports it as unstable); callables are not checked.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The plant.
    controllers : mapping
        Name → controller.
    wind_speeds : array_like
        Wind speeds of the campaign (m/s).
    dt : float
        Integration and controller step (s).

    Raises
    ------
    ValueError
        ``dt`` is not positive, too large for the plant (:func:`check_plant_step`), or one at
        which a controller's sampled loop is unstable (naming the controller).
    """
    dt = positive_scalar(dt, "dt")
    plant = turbine_plant(model)
    if plant.linearize is None:
        return
    check_step(plant, wind_speeds, dt)
    for name, c in controllers.items():
        if not has_linear_form(c):
            continue
        for v in wind_speeds:
            try:  # an unstable loop is not checked here: the campaign reports it
                checked_loop(plant, c, float(v), dt)
            except ValueError as err:
                raise ValueError(f"campaign controller {name!r}: {err}") from None


@on_one_blas_thread  # the tasks' own limit (campaign_point) nests in it: two local threads never undo it
def run_campaign(controllers: Mapping, wind_speeds, seeds, *, model=None, duration: float = RECORD_LENGTH, dt: float = 0.02,
                 record_dt: float = 0.1, transient: float = 60.0, m: float = TOWER_M, predict: bool = True,
                 turbulence_class: str = "B", keep_series: bool | int = False, linear_twin: bool = False,
                 volterra: int = 0, executor=None, progress: bool | None = None,
                 nperseg: int | None = None, store=None, torque_control="auto", plant=None,
                 openfast: Mapping | None = None, noise: SensorNoise | None = None) -> Campaign:
    """Run every controller at every wind speed on the same seeds and post-process.

    Parameters
    ----------
    controllers : dict
        Name → controller (LTI, Controller, ScheduledController or callable; see
        :mod:`specdesign.simulate`). A Python controller wrapped for OpenFAST
        (:func:`specdesign.export.forwarded`) runs as the controller it wraps on the reduced
        model, so one dict serves both plants (the wrapper's torque law and rate limit are the
        forwarding library's: the reduced model's callable contract holds the trim torque).
    wind_speeds : array_like
        Mean wind speeds (m/s).
    seeds : int or sequence of int
        Distinct integers, or an integer n for the seeds 0..n−1 (:func:`seeds_from`, as in
        campaign files); every controller sees the same wind series per (wind speed, seed)
        (:func:`specdesign.simulate.seed_for`).
    model : TurbineModel, optional
        Default ``turbine.iea15mw()``.
    duration : float, default 600.0
        Recorded time per run (s).
    dt : float, default 0.02
        Integration and controller step (s).
    record_dt : float, default 0.1
        Output spacing (s), a multiple of ``dt``.
    transient : float, default 60.0
        Time simulated first and discarded (s).
    m : float, default 4.0
        Wöhler exponent of the DEL.
    predict : bool, default True
        Compute the linear predictions (|T|²S_W, Dirlik DEL) for LTI-like controllers.
    turbulence_class : {"A", "B", "C"}, default "B"
        IEC NTM class of the wind.
    keep_series : bool or int, default False
        Keep time series in ``Campaign.series``: True for every seed, an int k for the first k
        seeds (enough for Fig. 9), False for none (memory: C·W·k·n·8 bytes per output).
    linear_twin : bool, default False
        Also run every LTI-like controller through the linearised model on the same wind
        (twice the simulation time): ``Campaign.linear_values``; :func:`~specdesign.validate.acceptance`
        then splits the deviation into the spectral method's part (linear-model rainflow −
        prediction) and the plant nonlinearity's part (nonlinear − linear-model rainflow).
    volterra : {0, 1, 2, 3}, default 0
        0 (none), or the order of the Volterra series (:func:`~specdesign.validate.volterra_response`)
        evaluated for every LTI-like controller on the same wind and window, FFT-fast:
        ``Campaign.volterra_values``, which :func:`~specdesign.validate.acceptance` compares
        with rainflow too.
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Wind speeds are submitted as separate tasks (every controller and seed of a speed
        in one task: one wind synthesis, the seeds batched) to anything with
        ``submit(fn, *args)`` returning futures: a ``concurrent.futures`` executor,
        ``client.get_executor()`` or the dask ``Client`` itself (docs/campaigns.md shows a
        multi-machine cluster); the results are bitwise those of a local run, collected as
        they finish. Default: run locally, the compiled simulator using every core, two wind
        speeds at a time in threads when every controller has a linear form (one speed's
        Python post-processing runs while the other is simulated; the same results).
        For a local process pool use a "spawn" context,
        ``ProcessPoolExecutor(mp_context=multiprocessing.get_context("spawn"))``: numba's
        OpenMP threads make fork() unsafe.
    progress : bool, optional
        Show a tqdm bar over the runs (one per wind speed, seed and controller), advanced as
        tasks finish, locally or on the cluster; None → only when stderr is a terminal.
    nperseg : int, optional
        Welch segment length (:func:`~specdesign.validate.welch_psd`).
    store : str or os.PathLike, optional
        A directory keeping every finished run, one file per (wind speed, seed,
        controller) (:mod:`specdesign.validate.store`: NetCDF cells that xarray reads, an
        index that pandas reads). Run again with the same directory, the campaign loads the
        runs already there and simulates only the missing ones: an interrupted campaign
        resumes, and one given more seeds, speeds or controllers runs only those. The
        result is bitwise that of an uninterrupted run. A store holding other settings,
        another model or another controller under the same name is refused; a stored cell
        that fails verification (unreadable, another cell's coordinates, its checksum) is
        recomputed with a RuntimeWarning naming its file. With an OpenFAST ``plant``: the
        campaign folder (a folder per run, resumable).
    torque_control : {"auto", "rosco", None} or specdesign.rosco.TorqueLaw, default "auto"
        Generator torque of the simulations (:func:`specdesign.simulate.simulate`): "auto"
        runs the model's torque law below rated and holds the trim torque above; "rosco"
        runs the law at every wind speed (near rated, where gusts cross into region 2.5, as
        ROSCO does: docs/validation.md "Below rated"). Callable controllers command the
        torque themselves: they run with "auto" (or None when None is asked). The linear
        twin and the predictions use the linearisation (the law closed below rated).
    plant : specdesign.openfast.Deck, optional
        Run the campaign in OpenFAST on this deck instead of the reduced ``model``
        (:func:`specdesign.validate.openfast_campaign.run_openfast_campaign`: TurbSim winds per
        speed and seed, compiled Bladed-interface controllers, OpenFAST processes in
        parallel). ``duration``, ``transient``, ``record_dt``, ``m``, ``turbulence_class``,
        ``keep_series``, ``nperseg``, ``progress`` and ``store`` keep their meaning; ``dt``
        is the deck's; the predictions are NaN.
    openfast : dict, optional
        With ``plant``: further options of ``run_openfast_campaign`` (``processes``,
        ``grid_points``, ``hydro``, ``cpu_limit``, ``timeout``, ``nice``, ``install``, ``dt``).
    noise : specdesign.controller.noise.SensorNoise, optional
        The sensors every controller reads through (``simulate(..., noise=...)``): the same
        noise for every controller on the same (wind speed, seed), the comparison stays paired;
        the linear twin reads it too. None (default): the plant's outputs themselves. Not with
        an OpenFAST ``plant`` (its controllers read ServoDyn's signals).

    Returns
    -------
    Campaign
        Indicators, spectra and predictions of every controller, wind speed and seed.

    Raises
    ------
    TypeError
        ``controllers`` is not a non-empty dict, or ``volterra`` asks for a model without
        ``aero_expansion``.
    ValueError
        Invalid seeds, ``volterra`` or ``torque_control``, a step too large (:func:`check_campaign_step`) or a
        store of another campaign, before the first simulation; errors of
        :func:`specdesign.simulate.simulate`.
    """
    if not isinstance(controllers, dict) or not controllers:
        raise TypeError("controllers must be a non-empty dict {name: controller}")
    if noise is not None and not isinstance(noise, SensorNoise):
        raise TypeError(f"noise must be a specdesign.controller.noise.SensorNoise or None, got {type(noise).__name__}")
    if plant is not None:
        if linear_twin or volterra or executor is not None or noise is not None:
            raise ValueError("linear_twin, volterra, executor and noise are options of the reduced model's campaign, not "
                             "of an OpenFAST plant (its processes: openfast={'processes': n})")
        return run_openfast_campaign(controllers, wind_speeds, seeds, deck=plant, duration=duration, transient=transient,
                                     record_dt=record_dt, m=m, turbulence_class=turbulence_class,
                                     keep_series=keep_series, nperseg=nperseg, progress=progress, folder=store,
                                     **dict(openfast or {}))
    # a controller wrapped for the forwarding library runs as itself here (store fingerprints included)
    controllers = {n: c.controller if isinstance(c, Forwarded) else c for n, c in controllers.items()}
    model, vs, seeds, names, n_keep, settings = _checked_campaign(
        controllers, wind_speeds, seeds, model, duration, dt, record_dt, transient, m, predict, turbulence_class,
        keep_series, linear_twin, volterra, nperseg, torque_control, noise)
    wanted = [(float(v), int(s), n) for v in vs for s in seeds for n in names]
    records, st = {}, None
    if store is not None:
        st = CampaignStore(store, settings, fingerprint(model), {n: fingerprint(c) for n, c in controllers.items()})
        records = st.load(wanted)
    kept = set(seeds[:n_keep].tolist())
    # a stored run among the first keep_series seeds but stored without its records (the
    # seeds were reordered) runs again, rather than showing NaN records
    records = {c: r for c, r in records.items() if not (c[1] in kept and r["series"] is None and not r["unstable"])}
    tasks = _tasks(vs, seeds, names, records)
    show = (sys.stderr.isatty()) if progress is None else bool(progress)
    bar = tqdm(total=sum(t[1].size * len(t[2]) for t in tasks), desc="validation", unit="run", disable=not show)

    def args(task):
        v, todo, group = task
        # the kept seeds are a prefix of the task's seeds (both in campaign order)
        return (model, {n: controllers[n] for n in group}, v, todo, duration, dt, record_dt, transient, m, predict,
                turbulence_class, sum(s in kept for s in todo.tolist()), nperseg, bool(linear_twin), int(volterra),
                torque_control, noise)

    def finish(task, point):
        new = _cells(task, point)
        records.update(new)
        if st is not None:
            st.write(new)
        bar.update(len(new))

    def collect(pool, todo):
        futs = {pool.submit(campaign_point, *args(t)): t for t in todo}
        try:
            for f in _as_completed(list(futs)):
                finish(futs[f], f.result())
        finally:  # on an error or an interrupt, do not leave the rest running on the cluster
            for f in futs:
                # only the unfinished: cancelling a finished dask future releases its key
                # on the scheduler, which would cancel an identical task submitted next
                if not f.done():
                    f.cancel()

    try:
        if executor is None:
            todo = list(tasks)
            if todo:  # the first task here: it starts numba's threading layer, which _overlap checks
                t = todo.pop(0)
                finish(t, campaign_point(*args(t)))
            if len(todo) > 1 and _overlap(controllers):
                with cf.ThreadPoolExecutor(2) as pool:
                    collect(pool, todo)
            else:
                for t in todo:
                    finish(t, campaign_point(*args(t)))
        else:
            collect(executor, todo=tasks)
    finally:
        bar.close()
    return _assemble(records, names, vs, seeds, settings)


def _checked_campaign(controllers, wind_speeds, seeds, model, duration, dt, record_dt, transient, m, predict,
                      turbulence_class, keep_series, linear_twin, volterra, nperseg, torque_control, noise):
    """:func:`run_campaign`'s door on the reduced model: the model, speeds, seeds, names, number
    of kept series and the store's settings, every option checked before any simulation."""
    if model is None:
        model = turbine.iea15mw()
    vs = np.atleast_1d(np.asarray(wind_speeds, dtype=float))
    seeds = seeds_from(seeds)
    if volterra not in (0, 1, 2, 3) or isinstance(volterra, bool):
        raise ValueError(f"volterra={volterra!r} must be 0 (none) or an order 1, 2 or 3")
    if volterra and not hasattr(model, "aero_expansion"):
        raise TypeError(f"volterra={volterra} needs a turbine.TurbineModel, got {type(model).__name__}")
    check_campaign_step(model, controllers, vs, dt)
    names = tuple(controllers)
    n_keep = len(seeds) if keep_series is True else int(keep_series)
    settings = {"duration": float(duration), "dt": float(dt), "record_dt": float(record_dt),
                "transient": float(transient), "m": float(m), "predict": bool(predict),
                # True (every seed) stays True: a store grown by more seeds keeps theirs too
                "turbulence_class": turbulence_class, "keep_series": True if keep_series is True else n_keep,
                "linear_twin": bool(linear_twin),
                "volterra": int(volterra), "nperseg": None if nperseg is None else int(nperseg),
                "torque_control": _torque_setting(torque_control)}
    if noise is not None:  # only then: a store made before the noise model still matches a noise-free campaign
        settings["noise"] = dataclasses.asdict(noise)
    if torque_control == "rosco" and turbine_plant(model).torque_law is None:
        raise ValueError("torque_control='rosco' needs a model with a torque law (a TurbineModel with torque_control, "
                         "e.g. iea15mw()); pass a specdesign.rosco.TorqueLaw or torque_control='auto'")
    return model, vs, seeds, names, n_keep, settings


def _tasks(vs, seeds, names, records) -> list:
    """The runs still to make: (speed, seeds, controllers) per wind speed."""
    tasks = []
    for v in vs:
        # controllers missing the same seeds at this speed share one task (one wind synthesis,
        # seeds batched); a fresh campaign has one task per wind speed
        groups = {}
        for n in names:
            todo = tuple(int(s) for s in seeds if (float(v), int(s), n) not in records)
            if todo:
                groups.setdefault(todo, []).append(n)
        for todo, group in groups.items():
            tasks.append((float(v), np.asarray(todo, dtype=np.int64), tuple(group)))
    return tasks


def _overlap(controllers) -> bool:
    """Whether a local campaign runs two wind speeds at a time, in threads: the compiled
    simulator releases the GIL and uses every core, so one speed's Python work (checks, wind,
    rainflow, Welch) runs while the other's simulation does, and the results do not depend on
    the order. Only for controllers with a linear form (a callable may keep state between the
    steps of a run: two runs at once would share it) and under a numba threading layer that
    takes calls from two threads at once (OpenMP, TBB; not the workqueue)."""
    try:
        layer = numba.threading_layer()
    except ValueError:  # no parallel kernel has run in this process
        return False
    return layer in ("omp", "tbb") and all(has_linear_form(c) for c in controllers.values())


def _torque_setting(torque_control):
    """``torque_control`` as a JSON-serialisable store setting (a law by its fingerprint), checked up front."""
    if isinstance(torque_control, TorqueLaw):
        return "law:" + fingerprint(torque_control)
    if torque_control is None or (isinstance(torque_control, str) and torque_control in ("auto", "rosco")):
        return torque_control
    raise ValueError(f"torque_control={torque_control!r} must be 'auto', 'rosco', None or a specdesign.rosco.TorqueLaw")


def _as_completed(futures):
    """Futures in the order they finish: concurrent.futures ones, or any with ``add_done_callback``
    (a dask.distributed Client's own futures)."""
    if all(isinstance(f, cf.Future) for f in futures):
        yield from cf.as_completed(futures)
        return
    done = queue.SimpleQueue()
    for f in futures:
        f.add_done_callback(done.put)
    for _ in futures:
        yield done.get()


def _cells(task, point) -> dict:
    """Split the result of one task (a wind speed, some controllers, some seeds) into cells."""
    v, todo, group = task
    out = {}
    for i, name in enumerate(group):
        r = point["series"].get(name)
        for j, s in enumerate(todo.tolist()):
            series = None
            if r is not None and j < r.seeds.size:
                series = {"time": r.time, "dt": r.dt, "sim_dt": r.sim_dt,
                          "outputs": {k: a[0, j] for k, a in r.outputs.items()}}
            out[(v, s, name)] = {
                "values": {k: point["values"][k][i][j] for k in INDICATORS},
                "linear": {k: point["linear"][k][i][j] for k in point["linear"]},
                "volterra": {k: point["volterra"][k][i][j] for k in point["volterra"]},
                "welch": {k: point["welch"][k][i][j] for k in SPECTRA},
                "ppsd": {k: point["ppsd"][k][i] for k in SPECTRA},
                "pred": point["pred"][i], "unstable": point["unstable"][i], "omega": point["omega"], "series": series}
    return out


def _assemble(records, names, vs, seeds, settings) -> Campaign:
    """The :class:`Campaign` of the cells (v, seed, controller), whichever run or store they came from."""
    cell = [[[records[(float(v), int(s), n)] for s in seeds] for v in vs] for n in names]
    first = [[row[0] for row in by_v] for by_v in cell]  # per-(controller, speed) entries: any seed has them

    def per_seed(group, keys):
        # a cell stored before an indicator existed (the actuator's) reads NaN for it
        return {k: np.array([[[c[group].get(k, np.nan) for c in row] for row in by_v] for by_v in cell]) for k in keys}

    def spectra(key, mean):
        if mean:  # the seed average as np.mean of the (S, nω) block a batch of seeds gives
            return {k: np.array([[np.stack([c[key][k] for c in row]).mean(axis=0) for row in by_v] for by_v in cell])
                    for k in SPECTRA}
        return {k: np.array([[f[key][k] for f in by_v] for by_v in first]) for k in SPECTRA}

    series = {}
    n_keep = len(seeds) if settings["keep_series"] is True else settings["keep_series"]
    if n_keep:
        for ci, name in enumerate(names):
            kept = [[c["series"] for c in row[:n_keep]] for row in cell[ci]]
            ok = next((r for row in kept for r in row if r is not None), None)
            if ok is None:  # unstable or diverged at every speed (warned): no series to keep
                continue
            # where it was unstable or diverged (warned), NaN series: the other speeds are kept
            outs = {k: np.stack([np.stack([(r["outputs"][k] if r is not None else np.full_like(a, np.nan)) for r in row])
                                 for row in kept]) for k, a in ok["outputs"].items()}
            series[name] = SimulationResult(time=ok["time"], wind_speeds=vs, seeds=seeds[:n_keep], outputs=outs,
                                            dt=ok["dt"], sim_dt=ok["sim_dt"], controller=name)
    return Campaign(
        controllers=names, wind_speeds=vs, seeds=seeds, duration=settings["duration"], dt=settings["record_dt"],
        m=settings["m"], values=per_seed("values", INDICATORS),
        predicted_del=np.array([[f["pred"] for f in by_v] for by_v in first]),
        omega=cell[0][0][0]["omega"], welch=spectra("welch", True), predicted_psd=spectra("ppsd", False),
        series=series, linear_values=per_seed("linear", INDICATORS) if settings["linear_twin"] else {},
        volterra_values=per_seed("volterra", INDICATORS) if settings["volterra"] else {},
        volterra_order=settings["volterra"],
        unstable=np.array([[bool(f["unstable"]) for f in by_v] for by_v in first]),
    )


def concat_campaigns(campaigns: Iterable[Campaign]) -> Campaign:
    """One :class:`Campaign` from campaigns over different wind speeds.

    E.g. one campaign per operating point, each with that point's designed controllers under
    the same names. Wind speeds are stacked in the given order.

    Parameters
    ----------
    campaigns : iterable of Campaign
        Campaigns sharing controller names, seeds, duration, sampling, m, Welch grid, linear
        twin, Volterra order and kept series, over distinct wind speeds.

    Returns
    -------
    Campaign
        The campaigns side by side along the wind-speed axis.

    Raises
    ------
    TypeError
        An empty sequence or an item that is not a Campaign.
    ValueError
        Campaigns run with different settings, or a repeated wind speed.
    """
    camps = list(campaigns)
    if not camps or not all(isinstance(c, Campaign) for c in camps):
        raise TypeError("campaigns must be a non-empty sequence of validate.Campaign")
    c0 = camps[0]
    for k, c in enumerate(camps[1:], 1):
        same = (c.controllers == c0.controllers and np.array_equal(c.seeds, c0.seeds) and c.duration == c0.duration
                and c.dt == c0.dt and c.m == c0.m and np.array_equal(c.omega, c0.omega)
                and bool(c.linear_values) == bool(c0.linear_values) and bool(c.series) == bool(c0.series)
                and c.volterra_order == c0.volterra_order)
        if not same:
            raise ValueError(f"campaigns[{k}] differs from campaigns[0] in controllers, seeds, duration, dt, m, Welch "
                             "grid, linear twin, Volterra order or kept series: run them with the same settings")
    vs = np.concatenate([c.wind_speeds for c in camps])
    if len(set(vs.tolist())) != vs.size:
        raise ValueError(f"campaigns repeat a wind speed ({vs.tolist()} m/s)")

    def cat(dicts, axis=1):
        return {k: np.concatenate([d[k] for d in dicts], axis=axis) for k in dicts[0]} if dicts[0] else {}

    series = {}
    for name in c0.series:
        rs = [c.series[name] for c in camps]
        series[name] = dataclasses.replace(rs[0], wind_speeds=np.concatenate([r.wind_speeds for r in rs]),
                                           outputs=cat([r.outputs for r in rs], axis=0))
    return dataclasses.replace(
        c0, wind_speeds=vs, values=cat([c.values for c in camps]),
        predicted_del=np.concatenate([c.predicted_del for c in camps], axis=1),
        welch=cat([c.welch for c in camps]), predicted_psd=cat([c.predicted_psd for c in camps]), series=series,
        linear_values=cat([c.linear_values for c in camps]), volterra_values=cat([c.volterra_values for c in camps]),
        unstable=np.concatenate([c.unstable for c in camps], axis=1))
