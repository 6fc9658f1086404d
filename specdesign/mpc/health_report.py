"""The trade-off of the health-aware MPC: energy against blade and tower fatigue as its weights vary.

:func:`health_tradeoff` simulates :class:`specdesign.mpc.health.HealthMPC` for a sweep of the
health weight ψ (blade-moment excursions) and of Boutrous, Nejjari and Puig's accumulated-stress weight ψ_acc, on
the same wind (speeds × seeds, :func:`specdesign.simulate.simulate`), and returns one
:class:`TradeoffPoint` per controller; :func:`plot_tradeoff` draws the curve. Aggregation over
the runs: mean power over every run; DELs pooled by fatigue, DEL = (mean_runs DEL_r^m)^{1/m}
(equal weight per wind speed and seed: no wind climate), blade-root flapwise m = 10, tower-base
fore-aft m = 4, 1 Hz; damage ratios (DEL/DEL_ref)^m against the first point of the sweep.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..fatigue import BLADE_M, TOWER_M, del_rainflow
from ..rosco import rosco_scheduled
from ..simulate import simulate
from .health import HealthMPC

__all__ = ["TradeoffPoint", "health_tradeoff", "plot_tradeoff"]



@dataclass(frozen=True)
class TradeoffPoint:
    """One controller of the trade-off sweep (aggregated over wind speeds and seeds).

    Parameters
    ----------
    label : str
        Controller label.
    health_weight, stress_weight : float
        ψ and ψ_acc of :class:`~specdesign.mpc.health.HealthMPC` (NaN for a non-MPC baseline).
    mean_power : float
        Mean electrical power (W).
    blade_del, tower_del : float
        Fatigue-pooled 1 Hz DELs of the blade-root flapwise (m = 10) and tower-base fore-aft
        (m = 4) moments (N·m).
    speed_sd, max_speed : float
        Mean over runs of the generator-speed standard deviation, and its largest value (rad/s).
    pitch_rate_sd : float
        Mean over runs of the standard deviation of the pitch rate (rad/s).
    cpu_per_step : float
        Mean CPU time of one controller sample per run (s); NaN for a compiled controller.
    """

    label: str
    health_weight: float
    stress_weight: float
    mean_power: float
    blade_del: float
    tower_del: float
    speed_sd: float
    max_speed: float
    pitch_rate_sd: float
    cpu_per_step: float


def _pooled_del(x, m, duration):
    dels = np.array([del_rainflow(s, m, duration) for s in x.reshape(-1, x.shape[-1])])
    return float(np.mean(dels**m) ** (1.0 / m))


def _point(label, hw, sw, r, cpu):
    dur = r.duration
    om = r["gen_speed"]
    rate = np.diff(r["pitch"], axis=-1) / r.dt
    return TradeoffPoint(label, float(hw), float(sw), float(r["power"].mean()),
                         _pooled_del(r["blade_root_my"], BLADE_M, dur), _pooled_del(r["tower_base_my"], TOWER_M, dur),
                         float(om.std(axis=-1).mean()), float(om.max()), float(rate.std(axis=-1).mean()), float(cpu))


def health_tradeoff(model, wind_speeds, seeds, *, health_weights=(0.0, 3.0, 10.0, 30.0, 100.0),
                    stress_weights=(10.0, 30.0, 100.0), duration: float = 300.0, transient: float = 60.0,
                    baseline: bool = True, **mpc_options) -> tuple[TradeoffPoint, ...]:
    """Simulate the sweep of the health-aware MPC's weights on common wind.

    Parameters
    ----------
    model : TurbineModel
        The turbine.
    wind_speeds : array_like
        Mean wind speeds (m/s).
    seeds : sequence of int
        Wind seeds (the same for every controller).
    health_weights : sequence of float, optional
        ψ values (ψ_acc = 0); the first is the reference of the damage ratios.
    stress_weights : sequence of float, optional
        ψ_acc values (ψ = 0): Boutrous et al.'s derating term.
    duration, transient : float, optional
        Recorded and discarded time per run (s).
    baseline : bool, optional
        Also run ROSCO (:func:`specdesign.rosco.rosco_scheduled`) first, labelled "ROSCO".
    **mpc_options
        Further keyword arguments of :class:`~specdesign.mpc.health.HealthMPC`.

    Returns
    -------
    tuple of TradeoffPoint
        ROSCO (if asked), then the ψ sweep, then the ψ_acc sweep.
    """
    out = []
    run = dict(seeds=list(seeds), duration=duration, transient=transient)
    if baseline:
        r = simulate(model, rosco_scheduled(model), wind_speeds, **run)
        out.append(_point("ROSCO", np.nan, np.nan, r, np.nan))
    sweep = [(f"ψ = {w:g}", w, 0.0) for w in health_weights] + [(f"ψ_acc = {w:g}", 0.0, w) for w in stress_weights]
    for label, hw, sw in sweep:
        mpc = HealthMPC(model, health_weight=hw, stress_weight=sw, name=label, **mpc_options)
        r = simulate(model, mpc, wind_speeds, **run)
        out.append(_point(label, hw, sw, r, np.mean(mpc.solve_times)))
    return tuple(out)


def plot_tradeoff(points, *, reference: str | None = None):
    """Energy change against blade and tower damage ratios, one curve per swept weight.

    Parameters
    ----------
    points : sequence of TradeoffPoint
        :func:`health_tradeoff`'s result.
    reference : str, optional
        Label of the reference point (default the first MPC point, ψ = first health weight).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels: blade-root damage ratio (m = 10) and tower-base damage ratio (m = 4)
        against the mean-power change (%), both against the reference.

    Raises
    ------
    ValueError
        If ``reference`` is not among the labels, or there are no MPC points.
    """
    from matplotlib.figure import Figure

    mpc = [p for p in points if np.isfinite(p.health_weight)]
    if not mpc:
        raise ValueError("points holds no health-MPC point (health_tradeoff's result is expected)")
    ref = mpc[0] if reference is None else next((p for p in points if p.label == reference), None)
    if ref is None:
        raise ValueError(f"reference={reference!r} is not among the labels {[p.label for p in points]}")
    fig = Figure(figsize=(9, 3.8), layout="constrained")
    axes = fig.subplots(1, 2)
    series = (("health weight ψ (excursions)", [p for p in mpc if p.stress_weight == 0], "o-"),
              ("Boutrous et al.'s ψ_acc (accumulated moment)", [p for p in mpc if p.stress_weight > 0 or p is ref], "s--"))
    for ax, attr, m, title in ((axes[0], "blade_del", BLADE_M, "blade-root flapwise"),
                               (axes[1], "tower_del", TOWER_M, "tower-base fore-aft")):
        for name, pts, style in series:
            pts = sorted(pts, key=lambda p: (p.stress_weight, p.health_weight))
            e = [100 * (p.mean_power / ref.mean_power - 1) for p in pts]
            d = [(getattr(p, attr) / getattr(ref, attr)) ** m for p in pts]
            ax.plot(e, d, style, label=name)
            for p, xe, yd in zip(pts, e, d):
                ax.annotate(p.label.split("= ")[-1], (xe, yd), fontsize=7, xytext=(3, 3), textcoords="offset points")
        for p in points:
            if not np.isfinite(p.health_weight):
                ax.plot(100 * (p.mean_power / ref.mean_power - 1), (getattr(p, attr) / getattr(ref, attr)) ** m, "k^",
                        label=p.label)
        ax.set_yscale("log")
        ax.set_xlabel(f"mean power change vs {ref.label} (%)")
        ax.set_ylabel(f"damage / damage at {ref.label} (m = {m:g})")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=7)
    return fig
