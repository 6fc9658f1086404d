"""``python -m specdesign demo``: the complete 19 m/s design loop, end to end.

1. sensitivity: ΔD%(ω) of the ROSCO loop (tower damping off) for the tower-base moment;
2. specification: the feasible specification pair that promises the target DEL reduction,
   certified over the neighbouring operating points (``method="target"``, the default), or
   notches on T_{MyT,w} promising a damage reduction (``method="notch"``);
3. controller: the QFT design that meets that specification at every plant case (a reduced
   certificate, pitch only), or the fixed-structure pitch controller + active tower damping;
4. validation: paired-seed nonlinear simulations, rainflow DEL vs the linear prediction.

Writes ``summary.md``, the tables (Markdown and CSV) and the figures into ``out``.

``python -m specdesign demo --lifetime`` (:func:`run_lifetime_demo`): ROSCO vs the designed
(specification-driven, gain-scheduled) QFT controller from cut-in to cut-out over a Weibull wind
climate, and the lifetime tower-base DEL change with its standard error.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import control as ct
import numpy as np

from loopshaping.freqresp import is_zero

from . import feasibility, validate
from ._checks import del_target, positive_scalar, real_scalar
from .plots.fatigue import plot_sensitivity
from .plots.qft import plot_design_bode, plot_design_nichols
from .plots.validation import plot_lifetime_damage, save_validation_figures
from .rosco import rosco_baseline, rosco_scheduled
from .simulate import scheduled
from .feasibility.target import TARGET_REDUCTION
from .spec import KEEP_BELOW, SPEC_REDUCTION
from .turbine import iea15mw

__all__ = ["run_demo", "run_lifetime_demo", "LIFETIME_DESIGN_SPEEDS", "check_demo_options", "check_lifetime_options",
           "DemoOptions"]

#: Wind speeds (m/s) of the QFT designs the lifetime demo schedules (the seed paper's range).
LIFETIME_DESIGN_SPEEDS = (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)
#: Shortest recorded time per run, s: 10 output samples at the campaigns' record_dt of 0.1 s
#: (the campaign file's own minimum).
MIN_DURATION = 1.0
#: Longest recorded time per run, s: one day (the campaign file's own maximum).
MAX_DURATION = 86400.0


@dataclass(frozen=True)
class DemoOptions:
    """The demos' options, checked (:func:`check_demo_options`, :func:`check_lifetime_options`).

    Parameters
    ----------
    wind_speed : float or None
        Operating point of the design demo, m/s (None for the lifetime demo).
    target_reduction : float
        Tower-base DEL reduction, %.
    n_seeds : int
        Paired seeds (per wind bin for the lifetime demo).
    duration : float
        Recorded time per run, s.
    design_speeds : tuple of float
        Wind speeds of the lifetime demo's designs, m/s (``()`` for the design demo).
    """

    wind_speed: float | None
    target_reduction: float
    n_seeds: int
    duration: float
    design_speeds: tuple = ()


def _seeds_and_duration(n_seeds, duration, default_seeds, default_duration):
    """(seeds, duration s) checked: ≥ 2 paired seeds (a standard error needs two) and a duration in
    [:data:`MIN_DURATION`, :data:`MAX_DURATION`] s; None takes the default (0 is no default)."""
    n = default_seeds if n_seeds is None else n_seeds
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)):
        raise TypeError(f"n_seeds={n_seeds!r} must be a whole number of paired seeds (≥ 2)")
    if n < 2:
        raise ValueError(f"n_seeds={n_seeds!r}: the paired change's standard error needs at least 2 paired seeds")
    d = default_duration if duration is None else positive_scalar(duration, "duration")
    if not MIN_DURATION <= d <= MAX_DURATION:
        raise ValueError(f"duration={duration!r} s must lie in {MIN_DURATION:g}-{MAX_DURATION:g} s (10 output samples "
                         "at 0.1 s to one day per run)")
    return int(n), float(d)


def check_demo_options(wind_speed=19.0, target_reduction=TARGET_REDUCTION, n_seeds=None, duration=None, *, fast=False,
                       spec_reduction=SPEC_REDUCTION, model=None) -> DemoOptions:
    """The design demo's options (:func:`run_demo`), checked before any work.

    Parameters
    ----------
    wind_speed : float
        Operating point, m/s: one where a pitch controller can be designed
        (:func:`specdesign.qft.check_design_speed`).
    target_reduction : float
        Tower-base DEL reduction, % (0-100).
    n_seeds : int, optional
        Paired seeds (≥ 2); default 50, 8 with ``fast``.
    duration : float, optional
        Recorded time per run, s (1-86400); default 600, 300 with ``fast``.
    fast : bool
        The reduced defaults.
    spec_reduction : float
        Damage reduction of the notch specification, % (0-100).
    model : specdesign.turbine.TurbineModel, optional
        The turbine (default :func:`specdesign.turbine.iea15mw`).

    Returns
    -------
    DemoOptions
        The options with their defaults filled in.

    Raises
    ------
    TypeError
        For a bool or a string where a number is meant.
    ValueError
        Naming the option and its range.
    """
    from .qft import check_design_speed

    v = check_design_speed(iea15mw() if model is None else model, real_scalar(wind_speed, "wind_speed"))
    t = del_target(target_reduction)
    del_target(spec_reduction, "spec_reduction")
    n, d = _seeds_and_duration(n_seeds, duration, 8 if fast else 50, 300.0 if fast else 600.0)
    return DemoOptions(v, t, n, d)


def check_lifetime_options(n_seeds=None, duration=None, design_speeds=LIFETIME_DESIGN_SPEEDS, bin_width=2.0, *,
                           fast=False, target_reduction=TARGET_REDUCTION, cut_in=3.0, cut_out=25.0, k=None, scale=None,
                           model=None) -> DemoOptions:
    """The lifetime demo's options (:func:`run_lifetime_demo`), checked before any design.

    Parameters
    ----------
    n_seeds : int, optional
        Paired seeds per bin (≥ 2); default 6, 3 with ``fast``.
    duration : float, optional
        Recorded time per run, s (1-86400); default 600, 300 with ``fast``.
    design_speeds : sequence of float
        Wind speeds of the designs, m/s: distinct, each where a pitch controller can be
        designed (:func:`specdesign.qft.check_design_speed`).
    bin_width, cut_in, cut_out, k, scale
        The climate, as :func:`specdesign.validate.weibull_bins` takes them.
    fast : bool
        The reduced defaults.
    target_reduction : float
        Tower-base DEL reduction of every design, % (0-100).
    model : specdesign.turbine.TurbineModel, optional
        The turbine (default :func:`specdesign.turbine.iea15mw`).

    Returns
    -------
    DemoOptions
        The options with their defaults filled in (``wind_speed`` None).

    Raises
    ------
    TypeError
        For a bool or a string where a number is meant.
    ValueError
        Naming the option and its range.
    """
    from .qft import check_design_speed

    n, d = _seeds_and_duration(n_seeds, duration, 3 if fast else 6, 300.0 if fast else 600.0)
    t = del_target(target_reduction)
    validate.weibull_bins(validate.WEIBULL_K if k is None else k, scale=validate.WEIBULL_A if scale is None else scale,
                          cut_in=cut_in, cut_out=cut_out, bin_width=bin_width)
    if isinstance(design_speeds, (str, bytes)) or np.ndim(design_speeds) != 1 or len(design_speeds) == 0:
        raise ValueError(f"design_speeds={design_speeds!r} must be a non-empty sequence of wind speeds in m/s")
    m = iea15mw() if model is None else model
    speeds = []
    for i, x in enumerate(design_speeds):
        try:
            speeds.append(check_design_speed(m, real_scalar(x, "wind_speed")))
        except (TypeError, ValueError) as e:  # check_design_speed names wind_speed: say which design speed
            raise type(e)(f"design_speeds[{i}]: {e}") from None
    speeds = tuple(speeds)
    if len(set(speeds)) != len(speeds):
        raise ValueError(f"design_speeds={design_speeds!r} repeats a wind speed; give each once")
    return DemoOptions(None, t, n, d, speeds)


def _say(msg):
    print(msg, flush=True)


def run_demo(out: str | os.PathLike = "specdesign_output", *, fast: bool = False, wind_speed: float = 19.0,
             spec_reduction: float = SPEC_REDUCTION, target_reduction: float = TARGET_REDUCTION, n_seeds: int | None = None,
             duration: float | None = None, method: str = "target") -> dict:
    """Run the design loop at one wind speed and write its tables and figures into ``out``.

    Writes ``summary.md``, ``table2.md/.csv``, ``table3.md/.csv``, the designed controllers
    (``controller_qft.json``), a campaign file that reruns the validation (``validate.toml``)
    and the figures ``1_sensitivity.png`` … ``3_bode.png`` of the design steps, then the
    validation's ``fig8_<v>mps.png`` (spectra), ``fig9_<v>mps.png`` (time series) and
    ``fig10.png`` (DEL reductions with the promise), as ``specdesign validate`` names them
    (:func:`specdesign.plots.validation.save_validation_figures`). Figures are drawn on
    :class:`matplotlib.figure.Figure`: no pyplot, no backend needed.

    Parameters
    ----------
    out : str or os.PathLike, default "specdesign_output"
        Output folder (created).
    fast : bool, default False
        Reduced validation: 8 seeds of 300 s instead of 50 of 600 s.
    wind_speed : float, default 19.0
        Operating point (m/s).
    spec_reduction : float, default 15.0
        Damage reduction the notch specification promises (%; ``method="notch"`` only).
    target_reduction : float, default 25.0
        Tower-base DEL reduction (%): the specification's promise (``"target"``) or the QFT
        design's DEL target (``"notch"``).
    n_seeds : int, optional
        Paired seeds of the validation (≥ 2; overrides ``fast``).
    duration : float, optional
        Recorded time per run (s, 1-86400; overrides ``fast``).
    method : {"target", "notch"}, default "target"
        ``"target"``: specification-driven (:func:`specdesign.feasibility.specification_for_target`,
        then ``design_qft(spec=qft.spec_from_certified(...))``); ``"notch"``: the notch specification and the
        fixed-structure QFT design with a DEL target.

    Returns
    -------
    dict
        The headline numbers (DELs in MN·m, reductions in %, deviations in pp, run time in s).

    Raises
    ------
    TypeError, ValueError
        For an option out of range (:func:`check_demo_options`), before any work.
    """
    from matplotlib.figure import (
        Figure,  # figures only written to files: no pyplot, no backend
    )

    from . import qft, spec
    from .plots.spec import plot_specification

    if method not in ("target", "notch"):
        raise ValueError(f"method={method!r} must be 'target' (specification-driven) or 'notch'")
    model = iea15mw()
    opts = check_demo_options(wind_speed, target_reduction, n_seeds, duration, fast=fast,
                              spec_reduction=spec_reduction, model=model)
    v, target_reduction, n_seeds, duration = opts.wind_speed, opts.target_reduction, opts.n_seeds, opts.duration
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()

    _say(f"[1/4] damage sensitivity of the ROSCO loop at {v:g} m/s (tower-base moment, Dirlik, m = 4)")
    base = spec.baseline_analysis(model, v)
    peak = base.omega[np.argmax(np.where(base.omega > 0.6, base.sensitivity, -np.inf))]
    _say(f"      baseline DEL {base.del_1hz / 1e6:.2f} MN·m; ΔD% peak above 0.6 rad/s at {peak:.3f} rad/s (tower mode)")
    fig = Figure(figsize=(7, 3.5))
    ax = fig.subplots()
    plot_sensitivity(base.omega, base.sensitivity, ax=ax)
    ax.set_title(f"Damage sensitivity ΔD%(ω), tower-base moment, ROSCO, {v:g} m/s")
    fig.tight_layout()
    fig.savefig(out / "1_sensitivity.png", dpi=120)

    if method == "target":
        _say(f"[2/4] specification promising {target_reduction:g} % less tower-base DEL, certified over "
             f"{v - 1:g}-{v + 1:g} m/s")
        target = feasibility.specification_for_target(model, v, target_reduction)
        spec_text = (f"the target specification: W_Ω = ROSCO's speed map + {target.speed_relax_db:.2f} dB, W_MyT = "
                     f"a certified design's tower map + {target.slack_db:.2f} dB (of which {target.robustness_db:.2f} "
                     "dB for the neighbouring operating points)")
        _say("      " + spec_text)
        tower, p = target.tower, target.promise
    else:
        _say(f"[2/4] specification promising {spec_reduction:g} % less damage (notches above 0.6 rad/s)")
        shaped = spec.shape_to_target(base, spec_reduction, keep_below=KEEP_BELOW)
        for n in shaped.notches:
            _say(f"      notch {n.omega_n:.3f} rad/s, {n.depth_db:.2f} dB, width {n.width:.3f}")
        spec_text = f"{len(shaped.notches)} notch(es)"
        tower, p = shaped.specification, shaped.promise
    _say(f"      promise: damage −{p.exact_damage:.2f} % (Eq. 10: −{p.predicted_damage:.2f} %), DEL −{p.exact_del:.2f} %")
    fig = Figure(figsize=(7, 3.5))
    ax = fig.subplots()
    plot_specification(base, tower, ax=ax)
    ax.set_title(f"Tower-load specification W_MyT at {v:g} m/s")
    fig.tight_layout()
    fig.savefig(out / "2_specification.png", dpi=120)

    if method == "target":
        _say("[3/4] QFT design meeting that specification at every plant case (the certificate, reduced; pitch only)")
        design = qft.design_qft(model, v, spec=qft.spec_from_certified(target))
    else:
        _say(f"[3/4] QFT design: pitch controller + active tower damping, target −{target_reduction:g} % DEL")
        design = qft.design_qft(model, v, spec=qft.spec_notch(target_reduction), spec_reduction=spec_reduction)
    _say("      " + design.summary())
    # the controllers as the transfer functions written to controller_qft.json, so that
    # `specdesign validate` simulates exactly what the demo simulated
    pitch = ct.tf(design.pitch_controller)
    atd = None if is_zero(design.atd_controller) else ct.tf(design.atd_controller)
    _say(f"      C_β(s) = {_tf_text(pitch)}")
    if atd is not None:
        _say(f"      C_ATD(s) = {_tf_text(atd)}")
    n_loops = 1 if atd is None else 2  # a pitch-only design has no ATD chart to draw
    fig = Figure(figsize=(7 * n_loops, 5.5))
    plot_design_nichols(design, axes=fig.subplots(1, n_loops, squeeze=False)[0])
    fig.savefig(out / "3_nichols.png", dpi=120)
    fig = Figure(figsize=(9, 7.5))
    plot_design_bode(design, model, axes=fig.subplots(2, 1, sharex=True))
    fig.savefig(out / "3_bode.png", dpi=120)

    _say(f"[4/4] validation: {n_seeds} paired seeds × {duration:g} s, nonlinear model, rainflow DEL")
    controllers = {
        "ROSCO": rosco_baseline(model, v),
        "QFT": scheduled(model, {v: pitch}, atd=None if atd is None else {v: atd}, name="QFT"),
    }
    camp = validate.run_campaign(controllers, [v], np.arange(n_seeds), model=model, duration=duration, keep_series=True,
                                 linear_twin=True, volterra=3)
    t2 = validate.table2(camp, "QFT", "ROSCO")
    t3 = validate.table3(camp, "QFT", "ROSCO", promised={v: p.exact_del})
    acc = validate.acceptance(camp, "QFT", "ROSCO")
    for name, table in (("table2", t2), ("table3", t3)):
        (out / f"{name}.md").write_text(table.to_markdown())
        table.to_csv(out / f"{name}.csv")
    _say(t3.to_markdown())
    # the figures `specdesign validate` writes, by the same function and under the same names:
    # a validation rerun into this folder replaces them instead of adding copies
    figures = save_validation_figures(camp, out, acc, promised={v: p.exact_del})

    # the designed controllers and a campaign file, so `python -m specdesign validate` can rerun
    # or extend the validation (more seeds, other wind speeds) without redesigning
    (out / "controller_qft.json").write_text(json.dumps(
        {"pitch": _tf_dict(pitch)} | ({} if atd is None else {"atd": _tf_dict(atd)}), indent=1))
    (out / "validate.toml").write_text(
        f"# python -m specdesign validate {out / 'validate.toml'}  (schema: docs/validation.md)\n"
        f'turbine = "iea15mw"\nwind_speeds = [{v:g}]\nseeds = {list(range(n_seeds))}\nduration = {duration:g}\n'
        'linear_twin = true\nvolterra = 3\n'
        'baseline = "ROSCO"\ndesigned = "QFT"\noutput = "validation"\n\n'
        f'[controllers.ROSCO]\nkind = "rosco"\nwind_speeds = [{v:g}]\n\n[controllers.QFT]\nfile = "controller_qft.json"\n\n'
        f'[promised]\n"{v:g}" = {p.exact_del:.4f}\n')

    elapsed = time.perf_counter() - t_start
    summary = {
        "wind_speed": v,
        "baseline_del_MNm": base.del_1hz / 1e6,
        "promised_damage_pct": p.exact_damage,
        "promised_del_pct": p.exact_del,
        "predicted_del_pct": float(acc.predicted[0]),
        "rainflow_del_pct": float(acc.rainflow[0]),
        "deviation_pp": float(acc.deviation[0]),
        "deviation_se_pp": float(acc.se[0]),
        "spectral_part_pp": float(acc.spectral_deviation[0]),
        "nonlinear_part_pp": float(acc.nonlinear_deviation[0]),
        "nonlinear_part_se_pp": float(acc.se_nonlinear[0]),
        "volterra_del_pct": float(acc.volterra[0]),
        "volterra_deviation_pp": float(acc.volterra_deviation[0]),
        "volterra_deviation_se_pp": float(acc.se_volterra[0]),
        "n_seeds": int(n_seeds),
        "seconds": elapsed,
    }
    lines = [
        f"# specdesign demo: {v:g} m/s design loop",
        "",
        f"- baseline (ROSCO, tower damping off) tower-base DEL, 1 Hz, m = 4: {summary['baseline_del_MNm']:.2f} MN·m",
        f"- specification: {spec_text}, promises −{p.exact_damage:.2f} % damage "
        f"(Eq. 10: −{p.predicted_damage:.2f} %), −{p.exact_del:.2f} % DEL",
        f"- QFT controller: {design.summary()}",
        f"- validation over {n_seeds} paired seeds of {duration:g} s: linear prediction −{summary['predicted_del_pct']:.2f} % DEL, "
        f"rainflow −{summary['rainflow_del_pct']:.2f} % ± {summary['deviation_se_pp']:.2f} (SE), deviation "
        f"{summary['deviation_pp']:+.2f} pp = spectral method {summary['spectral_part_pp']:+.2f} pp (rainflow on the "
        f"linearised model, same seeds) + plant nonlinearity {summary['nonlinear_part_pp']:+.2f} ± "
        f"{summary['nonlinear_part_se_pp']:.2f} pp (docs/nonlinearity.md)",
        f"- third-order Volterra prediction (the linear loop plus the aerodynamic nonlinearity, frequency domain, same "
        f"seeds): −{summary['volterra_del_pct']:.2f} % DEL, rainflow − Volterra {summary['volterra_deviation_pp']:+.2f} ± "
        f"{summary['volterra_deviation_se_pp']:.2f} pp",
        "",
        t2.to_markdown(),
        t3.to_markdown(),
        ("Figures: 1_sensitivity.png, 2_specification.png, 3_nichols.png, 3_bode.png, "
         + ", ".join(f.name for f in figures) + " (Welch spectra vs the linear prediction, time series, DEL reductions)"),
        "",
        "Controllers: controller_qft.json; rerun or extend the validation with "
        "`python -m specdesign validate validate.toml` (edit seeds or wind speeds there).",
        "",
        f"Run time: {elapsed:.0f} s.",
    ]
    (out / "summary.md").write_text("\n".join(lines) + "\n")
    _say(f"done in {elapsed:.0f} s: {out.resolve()}/summary.md")
    return summary


def run_lifetime_demo(out: str | os.PathLike = "specdesign_output", *, fast: bool = False, n_seeds: int | None = None,
                      duration: float | None = None, design_speeds=LIFETIME_DESIGN_SPEEDS, bin_width: float = 2.0,
                      cut_in: float = 3.0, cut_out: float = 25.0, k: float | None = None,
                      scale: float | None = None, target_reduction: float = TARGET_REDUCTION) -> dict:
    """Lifetime comparison, ROSCO vs the designed controller, from cut-in to cut-out.

    The designed controller: the specification-driven QFT designs of
    :func:`specdesign.qft.design_schedule` at ``design_speeds``, scheduled on the trim pitch
    (:func:`specdesign.simulate.scheduled`); below the lowest design speed the schedule holds
    that design, and below rated its command sits at fine pitch as ROSCO's does (the torque law
    runs the turbine there). The baseline: ROSCO's gain-scheduled PI
    (:func:`specdesign.rosco.rosco_scheduled`, tower damping off). Both run ROSCO's torque law in
    every run (``torque_control="rosco"``, the transitions through rated included), on the same
    seeds at every bin centre of the Weibull climate (:func:`specdesign.validate.weibull_bins`);
    :func:`specdesign.validate.lifetime` combines the bins, the rainflow DELs and the linear
    predictions alike. Writes ``lifetime.md`` (the
    lifetime summary and Table 2 with its Lifetime column), ``table2_lifetime.md/.csv``,
    ``lifetime_runs.csv`` (every run's tower-base DEL and its bin's linear prediction) and ``lifetime_damage.png`` (damage per
    bin).

    Parameters
    ----------
    out : str or os.PathLike, default "specdesign_output"
        Output folder (created).
    fast : bool, default False
        3 seeds of 300 s per bin instead of 6 of 600 s.
    n_seeds : int, optional
        Paired seeds per bin (overrides ``fast``).
    duration : float, optional
        Recorded time per run (s; overrides ``fast``).
    design_speeds : sequence of float, default LIFETIME_DESIGN_SPEEDS
        Wind speeds of the QFT designs (m/s, within the model's design range).
    bin_width : float, default 2.0
        Bin width (m/s; IEC 61400-1 DLC 1.2: 2 m/s); must divide cut_out − cut_in.
    cut_in, cut_out : float, default 3.0, 25.0
        Cut-in and cut-out wind speeds (m/s).
    k : float, optional
        Weibull shape; default the seed paper's 2.2 (:data:`specdesign.validate.WEIBULL_K`).
    scale : float, optional
        Weibull scale A (m/s); default the seed paper's 11.29 (:data:`specdesign.validate.WEIBULL_A`).
    target_reduction : float, default 25.0
        Tower-base DEL reduction every design's specification promises, %.

    Returns
    -------
    dict
        ``change_pct`` and ``change_se_pp`` (the designed controller's lifetime tower-base DEL
        change vs ROSCO, % and its SE), ``predicted_change_pct`` (the same from the linear
        predictions, Dirlik on |T|²S_W per bin, %), ``del_life_MNm`` (controller → lifetime DEL, MN·m),
        ``wind_speeds`` (bin centres, m/s), ``probabilities``, ``n_seeds``, ``duration``,
        ``seconds``.

    Raises
    ------
    TypeError
        For a bool or a string where a number is meant.
    ValueError
        Any option out of range (:func:`check_lifetime_options`: bad climate parameters, fewer
        than 2 seeds, a duration outside 1-86400 s, a design speed outside the design range),
        all checked before the first design; or errors of the design and the campaign.
    """
    from matplotlib.figure import Figure

    from . import qft

    out = Path(out)
    model = iea15mw()
    # every option, the design speeds included, before the first design
    opts = check_lifetime_options(n_seeds, duration, design_speeds, bin_width, fast=fast,
                                  target_reduction=target_reduction, cut_in=cut_in, cut_out=cut_out, k=k, scale=scale,
                                  model=model)
    n_seeds, duration, speeds = opts.n_seeds, opts.duration, opts.design_speeds
    climate = validate.weibull_bins(validate.WEIBULL_K if k is None else k,
                                    scale=validate.WEIBULL_A if scale is None else scale, cut_in=cut_in,
                                    cut_out=cut_out, bin_width=bin_width)
    out.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    _say(f"[1/3] QFT designs meeting the specification for {opts.target_reduction:g} % less tower-base DEL at "
         f"{_list(speeds)} m/s")
    # the lowest design, held below rated, is made to keep fine pitch there (design_schedule's held_below_rated)
    designs = qft.design_schedule(model, speeds, opts.target_reduction)
    pitch = {v: ct.tf(d.pitch_controller) for v, d in zip(speeds, designs)}
    atd = {v: ct.tf(d.atd_controller) for v, d in zip(speeds, designs)}
    controllers = {"ROSCO": rosco_scheduled(model),
                   "QFT": scheduled(model, pitch, atd=None if all(is_zero(a) for a in atd.values()) else atd,
                                    name="QFT")}
    vs = climate.centres
    _say(f"[2/3] {vs.size} wind bins {vs[0]:g}-{vs[-1]:g} m/s × {n_seeds} paired seeds × {duration:g} s × 2 "
         "controllers, ROSCO's torque law in every run")
    camp = validate.run_campaign(controllers, vs, n_seeds, model=model, duration=duration, torque_control="rosco")
    _say(f"[3/3] lifetime DEL over {climate.description}")
    life = validate.lifetime(camp, climate, baseline="ROSCO")
    t2 = validate.table2(camp, "QFT", "ROSCO", climate=climate)
    t2.to_csv(out / "table2_lifetime.csv")
    (out / "table2_lifetime.md").write_text(t2.to_markdown())
    with open(out / "lifetime_runs.csv", "w") as f:
        f.write("controller,wind_speed_m_s,seed,tower_del_Nm,predicted_tower_del_Nm\n")
        for i, name in enumerate(camp.controllers):
            for w, v in enumerate(vs):
                for j, seed in enumerate(camp.seeds):
                    f.write(f"{name},{v:g},{seed},{float(camp.values['tower_del'][i, w, j])!r},"
                            f"{float(camp.predicted_del[i, w])!r}\n")
    fig = Figure(figsize=(9, 4.5))
    plot_lifetime_damage(life, ax=fig.subplots())
    fig.tight_layout()
    fig.savefig(out / "lifetime_damage.png", dpi=120)
    i = life.controllers.index("QFT")
    change, se = float(life.change[i, 0]), float(life.change_se[i, 0])
    predicted = float(life.predicted_change[i, 0])
    headline = (f"Lifetime tower-base DEL change, QFT vs ROSCO: {change:+.2f} % ± {se:.2f} % (SE, {life.method} "
                f"over {n_seeds} paired seeds per bin); linear prediction {predicted:+.2f} %")
    _say(life.summary())
    _say(headline)
    elapsed = time.perf_counter() - t_start
    (out / "lifetime.md").write_text("\n".join([
        "# specdesign demo --lifetime: ROSCO vs the scheduled QFT designs, cut-in to cut-out", "",
        f"- designed controller: specification-driven QFT designs at {_list(speeds)} m/s, scheduled on the trim pitch "
        f"(held below {speeds[0]:g} m/s; at fine pitch below rated)",
        f"- {vs.size} bins × {n_seeds} paired seeds × {duration:g} s, ROSCO's torque law in every run", "",
        "```", life.summary(), "```", "", f"**{headline}**", "", t2.to_markdown(),
        "Figure: lifetime_damage.png (damage per wind bin). Per-run DELs: lifetime_runs.csv.", "",
        f"Run time: {elapsed:.0f} s."]) + "\n")
    _say(f"done in {elapsed:.0f} s: {out.resolve()}/lifetime.md")
    return {"change_pct": change, "change_se_pp": se, "predicted_change_pct": predicted,
            "del_life_MNm": {n: float(life.del_life[c, 0]) / 1e6 for c, n in enumerate(life.controllers)},
            "wind_speeds": vs.tolist(), "probabilities": life.probabilities.tolist(), "n_seeds": int(n_seeds),
            "duration": float(duration), "seconds": elapsed}


def _list(values):
    return ", ".join(f"{v:g}" for v in values)


def _tf_dict(tf):
    return {"num": np.asarray(tf.num[0][0], float).tolist(), "den": np.asarray(tf.den[0][0], float).tolist()}


def _tf_text(tf):
    num, den = (np.trim_zeros(np.asarray(c[0][0], float), "f") for c in (tf.num, tf.den))
    return f"({np.array2string(num, precision=4)}) / ({np.array2string(den, precision=4)})"
