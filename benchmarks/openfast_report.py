"""What an OpenFAST campaign folder holds so far: Table 3's rainflow row, the actuator's cost and
where in frequency the tower-base moment changed, from the finished runs only (nothing is run).

Reads ``benchmarks/openfast_table3.py``'s folder (or any ``run_campaign(..., plant=Deck)``
store) with :func:`specdesign.validate.read_openfast_runs` and prints, per wind speed and
controller against the baseline on the seeds both have finished:

- the tower-base DEL change (1 Hz, m = 4; seeds pooled by damage, jackknife SE over the
  paired seeds), generator-speed SD, blade-root DEL and mean-power changes;
- the actuator's cost, absolute: pitch-rate SD (deg/s), pitch travel (deg/h) and the time at
  the pitch-rate limit (% of the record), where the runs carry them (runs stored before an
  indicator existed lack it and are left out of its mean, never filled in);
- the variance of the tower-base moment in frequency bands (from the runs' Welch spectra),
  each as the ratio designed/baseline: the wind-driven band the specification shapes, the
  band of the first tower fore-aft mode (~1.1 rad/s on the IEA 15 MW monopile), 3P, above.

With ``--damping`` it also makes the designs again on OpenFAST's linearisations (as
``openfast_table3.py --plant openfast``: cached, ~5 min per speed for reading the
linearisation) and prints the damping ratio of the closed loop's poles near the tower mode,
for the baseline (ROSCO's PI on the linearisation) and the design: the excitation the linear
prediction has (rotor-effective wind) barely reaches the mode; waves and the rotational
sampling of the turbulence in OpenFAST do, and their response scales with 1/ζ.

With ``--table3`` it prints Table 3 per design beside the paper's (its rows at 15-25 m/s):
the specification each design meets, the linear prediction on OpenFAST's linearisation with
both loops closed, the OpenFAST rainflow reduction over the paired seeds (± SE), the deviation,
the reduced model's rainflow for the same controllers on the same seed numbers (the workbench's
simulator, its own rotor-effective wind: a few seconds per run) and the pitch-rate SDs.

With ``--docs docs/openfast.md`` the (wind, controller) tables are written into the page: each
row of the page's table of the same header is replaced by the store's, new ones inserted; rows
the store does not give are kept and listed (Table 3 is printed, not written).

    python benchmarks/openfast_report.py      # the repository's store, benchmarks/results/openfast_table3/runs
    python benchmarks/openfast_report.py --docs docs/openfast.md
    python benchmarks/openfast_report.py --damping --table3 --figures docs/figures
"""
from __future__ import annotations

import argparse
import math
import re
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

import control as ct
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)
import numpy as np  # noqa: E402

from specdesign import closedloop, spec, turbine, validate, wind  # noqa: E402
from specdesign.export.parameters import SAME_DESIGN_RTOL  # noqa: E402
from specdesign.openfast import iea15mw_monopile  # noqa: E402
from specdesign.openfast.deck import named_digest  # noqa: E402
from specdesign.validate.openfast_campaign import kept_change, ran_parameters  # noqa: E402

sys.path.insert(0, str(Path(__file__).parent))  # the campaign's script beside this one
# its store, model and design step: the controllers it ran
from openfast_table3 import STORE, STRUCTURES, designs, export_design, openfast_model, predicted_del  # noqa: E402

#: Bands of the tower-base moment's variance, rad/s: (label, low, high).
BANDS = (("wind 0.05-0.6", 0.05, 0.6), ("0.6-0.85", 0.6, 0.85), ("tower mode 0.85-1.5", 0.85, 1.5),
         ("1.5-2.2", 1.5, 2.2), ("3P 2.2-2.6", 2.2, 2.6), ("> 2.6", 2.6, np.inf))
#: Poles of the closed loop counted as the tower mode's (rad/s): around the IEA 15 MW monopile's
#: first fore-aft mode (1.07-1.1 rad/s in OpenFAST's linearisations and runs).
TOWER_MODE_BAND = (0.85, 1.4)
#: From here up (rad/s: the 3P band's lower edge) the pitch rate's variance is counted as spent
#: at 3P and above, where no design of the workbench aims to act.
PITCH_RATE_SPLIT = 2.2
DEG = 180.0 / math.pi
#: The baseline's name in the damping table and Fig. 8 (its linear loop is ROSCO's PI placed on
#: OpenFAST's rotor model; in the runs, ROSCO's compiled DISCON).
BASELINE = "ROSCO"
#: ROSCO with its tower damper (``openfast_table3.py --rosco-td``): the second baseline of issue 31.
SECOND_BASELINE = "ROSCO+TD"
_COLOURS = {"ROSCO": "tab:blue", "ROSCO+TD": "tab:purple", "QFT": "tab:red", "QFT+ATD": "tab:green",
            "QFT+ATD+3P": "tab:olive"}


def openfast_times(run) -> tuple[float, float]:
    """OpenFAST's own ``Total CPU Time`` and ``Total Real Time`` of a run (minutes) from the log
    kept in its folder; NaN where the log does not say."""
    out = [float("nan"), float("nan")]
    for log in run.folder.glob("*.log"):
        for line in log.read_text(errors="replace").splitlines():
            for i, key in enumerate(("Total CPU Time:", "Total Real Time:")):
                if key in line:
                    # OpenFAST says seconds, minutes or hours, whichever reads best
                    value, unit = line.split(key)[1].split()[:2]
                    out[i] = float(value) * _MINUTES_PER[unit.rstrip("s")]
    return out[0], out[1]


#: OpenFAST's time units in its closing lines, in minutes.
_MINUTES_PER = {"second": 1 / 60, "minute": 1.0, "hour": 60.0, "day": 1440.0}


def forwarded_costs(runs) -> list[str]:
    """Lines on the forwarded Python controllers' cost per control step (run.json's
    ``forwarded_calls``, recorded by the campaign since 2026-11-28; runs before have none):
    per controller and speed, the median over runs of each run's median and its largest 99th
    percentile, CPU of the server's thread and wall, ms."""
    cells = defaultdict(list)
    for r in runs:
        st = r.meta.get("forwarded_calls")
        if st and "cpu_median_s" in st:
            cells[r.controller, r.wind_speed].append(st)
    if not cells:
        return []
    lines = ["", ("Forwarded Python controllers, cost per control step (ms; median over runs of each run's "
                  "median, largest 99th percentile):"), "",
             "| controller | wind (m/s) | runs | calls per run | CPU median | CPU p99 | wall median | wall p99 |",
             "|---|---|---|---|---|---|---|---|"]
    for (name, v), sts in sorted(cells.items()):
        ms = {k: 1e3 * np.array([st[k] for st in sts])
              for k in ("cpu_median_s", "cpu_p99_s", "wall_median_s", "wall_p99_s")}
        lines.append(f"| {name} | {v:g} | {len(sts)} | {int(np.median([st['calls'] for st in sts]))} "
                     f"| {np.median(ms['cpu_median_s']):.2f} | {ms['cpu_p99_s'].max():.2f} "
                     f"| {np.median(ms['wall_median_s']):.2f} | {ms['wall_p99_s'].max():.2f} |")
    return lines


def wind_psd(model, v, omega):
    """S_W of the linear predictions (rotor-effective wind, class B, weighted by the 600 s
    record's window as :func:`specdesign.validate.linear_prediction` weights it), (m/s)²·s/rad."""
    return wind.rotor_effective_spectrum(omega, v, model.rotor_radius, turbulence_class="B") * wind.record_window(omega)


def band_variance(omega, psd, lo, hi) -> float:
    """∫ PSD dω over lo ≤ ω < hi (rad/s), trapezoidal on the Welch grid."""
    m = (omega >= lo) & (omega < hi)
    return float(np.trapezoid(psd[m], omega[m])) if m.sum() > 1 else float("nan")


def pitch_psd(run):
    """(ω rad/s, the pitch angle's Welch PSD rad²·s/rad) of an OpenFAST run: stored by the
    campaign since 2026-11-28 (``OPENFAST_SPECTRA``); for an earlier run, from its kept series with
    the campaign's own Welch settings; None when it has neither (never filled in)."""
    if "pitch" in run.welch:
        return run.omega, run.welch["pitch"]
    if "pitch" in run.series:
        st = run.meta["settings"]
        return validate.welch_psd(run.series["pitch"], st["record_dt"], st["nperseg"])
    return None


def _cell_stats(runs, base, name, v, m):
    b = {r.seed: r for r in runs if r.controller == base and r.wind_speed == v}
    d = {r.seed: r for r in runs if r.controller == name and r.wind_speed == v}
    seeds = sorted(set(b) & set(d))
    if not seeds:
        return None
    out = {"seeds": seeds}
    for ind in ("tower_del", "gen_speed_sd", "blade_del", "mean_power"):
        ch = validate.paired_change([d[s].values[ind] for s in seeds], [b[s].values[ind] for s in seeds], ind, m=m)
        out[ind] = (float(ch.change[0]), float(ch.se[0]))
    for ind, f in (("pitch_rate_sd", DEG), ("pitch_travel", DEG), ("rate_limit_time", 100.0)):
        for who, runs_ in (("base", b), ("design", d)):
            x = [runs_[s].values[ind] * f for s in seeds if ind in runs_[s].values]
            out[ind, who] = (float(np.mean(x)), len(x)) if x else (float("nan"), 0)
    for label, lo, hi in BANDS:
        vb = np.mean([band_variance(b[s].omega, b[s].welch["tower_base_my"], lo, hi) for s in seeds])
        vd = np.mean([band_variance(d[s].omega, d[s].welch["tower_base_my"], lo, hi) for s in seeds])
        out["band", label] = (vb, vd)
    # the pitch's own spectrum, on the seeds both runs have it for (the actuator's cost by band)
    pitch = {s: (pitch_psd(b[s]), pitch_psd(d[s])) for s in seeds}
    out["pitch seeds"] = [s for s, (pb, pd) in pitch.items() if pb is not None and pd is not None]
    for label, lo, hi in BANDS:
        out["pitch", label] = tuple(np.mean([band_variance(*pitch[s][i], lo, hi) * DEG**2 for s in out["pitch seeds"]])
                                    if out["pitch seeds"] else float("nan") for i in (0, 1))
    # the pitch rate's variance is ∫ ω²·S dω: its share at 3P and above, where the tower gains nothing
    out["rate share"] = tuple(np.mean([band_variance(w, w**2 * p, PITCH_RATE_SPLIT, np.inf) / band_variance(w, w**2 * p, 0.0, np.inf)
                                       for w, p in (pitch[s][i] for s in out["pitch seeds"])])
                              if out["pitch seeds"] else float("nan") for i in (0, 1))
    return out


def _ratio(r) -> str:
    """A variance ratio to 3 significant digits without an exponent (×0.273, ×4.38, ×2409)."""
    return f"{r:.0f}" if r >= 100 else f"{r:.3g}"


def _pm(st, key, n, digits=1) -> str:
    """A paired change ± its SE (the SE only from two seeds up), to ``digits`` decimals."""
    return f"{st[key][0]:+.{digits}f} ± {st[key][1]:.{digits}f}" if n > 1 else f"{st[key][0]:+.{digits}f}"


def _change_table(runs, baseline, m, skip=()) -> tuple[list, list]:
    """Every controller's paired changes against ``baseline`` per speed (markdown lines) and
    the cells' statistics (for the band table)."""
    names = sorted({r.controller for r in runs} - {baseline} - set(skip))
    speeds = sorted({r.wind_speed for r in runs})
    lines, bands = [], []
    head = ("| wind (m/s) | controller | paired seeds | tower DEL (%) | gen-speed SD (%) | blade DEL (%) | mean power (%) "
            f"| pitch-rate SD (deg/s): {baseline} / design | pitch travel (deg/h): {baseline} / design "
            "| at the rate limit (%): design |")
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for v in speeds:
        for name in names:
            st = _cell_stats(runs, baseline, name, v, m)
            if st is None:
                continue
            n = len(st["seeds"])
            trav = [f"{x:.0f}" if k else "not recorded" for x, k in (st["pitch_travel", "base"], st["pitch_travel", "design"])]
            lines.append(f"| {v:g} | {name} | {n} ({', '.join(map(str, st['seeds']))}) | {_pm(st, 'tower_del', n)} "
                         f"| {_pm(st, 'gen_speed_sd', n)} | {_pm(st, 'blade_del', n)} | {_pm(st, 'mean_power', n, 2)} "
                         f"| {st['pitch_rate_sd', 'base'][0]:.3f} / {st['pitch_rate_sd', 'design'][0]:.3f} "
                         f"| {trav[0]} / {trav[1]} "
                         f"| {st['rate_limit_time', 'design'][0]:.2f} |")
            bands.append((v, name, st))
    return lines, bands


def report(folder, runs, baseline="ROSCO", m=4.0) -> str:
    """The runs, actuator and band tables of ``runs`` (``validate.read_openfast_runs(folder)``,
    read once by the caller: the design steps use them too)."""
    if not runs:
        raise SystemExit(f"{folder}: no finished run yet")
    count = defaultdict(int)
    for r in runs:
        count[r.controller, r.wind_speed] += 1
    lines = [f"Finished runs in {folder}: " + ", ".join(f"{c} {v:g} m/s × {n}" for (c, v), n in sorted(count.items())), ""]
    table, bands = _change_table(runs, baseline, m)
    lines += table
    if SECOND_BASELINE in {r.controller for r in runs} and baseline != SECOND_BASELINE:
        # issue 31: every design against ROSCO with its tower damper too, on the same seeds
        lines += ["", f"Against the second baseline, {SECOND_BASELINE} (ROSCO's compiled DISCON, TD_Mode = 1):", ""]
        lines += _change_table(runs, SECOND_BASELINE, m, skip={baseline})[0]
    times = np.array([openfast_times(r) for r in runs])
    ok = ~np.isnan(times).any(axis=1)
    if ok.any():
        length = runs[0].meta["settings"]["duration"] + runs[0].meta["settings"]["transient"]
        lines += ["", f"OpenFAST's own times per {length:g} s run ({ok.sum()} runs): CPU {times[ok, 0].min():.1f}-"
                      f"{times[ok, 0].max():.1f} min (median {np.median(times[ok, 0]):.1f}; "
                      f"{60 * np.median(times[ok, 0]) / length:.2f} s of CPU per simulated second), wall "
                      f"{times[ok, 1].min():.1f}-{times[ok, 1].max():.1f} min (the load of the machine)"]
    lines += forwarded_costs(runs)
    lines += ["", "Tower-base moment variance by band, mean over the paired seeds (MN²·m²); design / baseline:", ""]
    head = "| wind (m/s) | controller | " + " | ".join(f"{b[0]} rad/s" for b in BANDS) + " |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for v, name, st in bands:
        cells = []
        for label, _, _ in BANDS:
            vb, vd = st["band", label]
            cells.append(f"{vb / 1e12:.3g} → {vd / 1e12:.3g} (×{vd / vb:.2f})")
        lines.append(f"| {v:g} | {name} | " + " | ".join(cells) + " |")
    pitched = [(v, name, st) for v, name, st in bands if st["pitch seeds"]]
    if pitched:
        # issue 28: where in frequency the actuator works, 3P and above included (the pitch
        # spectrum is kept by the campaign since 2026-11-28, before only with seed 0's series)
        lines += ["", (f"Pitch angle variance by band, mean over the seeds both runs recorded its spectrum for "
                       f"(deg²); {baseline} → design:"), ""]
        head = ("| wind (m/s) | controller | seeds | " + " | ".join(f"{b[0]} rad/s" for b in BANDS)
                + f" | pitch-rate variance at ≥ {PITCH_RATE_SPLIT:g} rad/s (%): {baseline} / design |")
        lines += [head, "|" + "---|" * (head.count("|") - 1)]
        for v, name, st in pitched:
            cells = [f"{st['pitch', label][0]:.3g} → {st['pitch', label][1]:.3g} "
                     f"(×{_ratio(st['pitch', label][1] / st['pitch', label][0])})" for label, _, _ in BANDS]
            cells.append(f"{100 * st['rate share'][0]:.0f} / {100 * st['rate share'][1]:.0f}")
            lines.append(f"| {v:g} | {name} | {', '.join(map(str, st['pitch seeds']))} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def campaign_designs(runs, target=25.0):
    """OpenFAST's linearisations and the designs the campaign ran (as ``openfast_table3.py``
    makes them: ``QFT`` the certified chain, ``QFT+ATD`` the paper's structure), each only at
    the speeds where it ran (a certified pitch-only design may be refused at a speed the
    campaign never ran it at): (model, {label: {speed: {"design", "promise"}}})."""
    speeds = sorted({r.wind_speed for r in runs})
    names = {r.controller for r in runs}
    model = openfast_model(iea15mw_monopile(), speeds, processes=1)
    made = {label: designs(model, sorted({r.wind_speed for r in runs if r.controller == label}), target, structure)
            for structure, (label, _) in STRUCTURES.items() if label in names}
    for label, speed, digests in stale_designs(runs, made):
        print(f"WARNING: the {label} runs at {speed:g} m/s ran a parameter file of digest {', '.join(sorted(digests))}; "
              f"this code's design exports another: the damping table, the linear predictions and Table 3's "
              f"prediction rows are this code's design, the rainflow rows the runs' (rerun the campaign)", file=sys.stderr)
    return model, made


def stale_designs(runs, made, same_rtol=SAME_DESIGN_RTOL) -> list:
    """(label, speed, the runs' parameter digests) where the designs ``made`` (:func:`campaign_designs`),
    exported as the campaigns export them (``openfast_table3.export_design``), give another parameter
    file than the runs of that controller and speed ran, and the file those runs ran (as the store
    keeps it, ``validate.openfast_campaign.ran_parameters``) is missing or holds a controller whose
    responses differ from this code's by more than ``same_rtol`` (relative): runs of an earlier design.
    Runs of a file within it are said on stderr with the change."""
    reduced, out = turbine.iea15mw(), []
    with tempfile.TemporaryDirectory() as tmp:
        for label, by_speed in made.items():
            for v, entry in by_speed.items():
                mine = [r for r in runs if r.controller == label and r.wind_speed == v]
                ran = {r.meta["parameters_sha"] for r in mine}
                export = export_design(entry["design"], Path(tmp) / f"{label}{v:g}", f"{label} {v:g} m/s", reduced)
                if not ran or named_digest(export.parameters) in ran:
                    continue
                kept = {r.meta["parameters_sha"]: ran_parameters(r) for r in mine}
                change = max(kept_change(f, export.parameters) for f in kept.values())
                if change > same_rtol:
                    out.append((label, v, ran))
                else:
                    print(f"note: the {label} runs at {v:g} m/s ran an earlier export of this code's design "
                          f"(responses {change:.1e} relative apart, within {same_rtol:g}): counted as its runs", file=sys.stderr)
    return out


def linear_side(runs, model, made, figures=None, reduced=None) -> tuple[str, dict]:
    """Closed-loop damping near the tower mode of the baseline and of each design
    (:func:`campaign_designs`) on OpenFAST's linearisation at each speed, both loops closed
    (:func:`specdesign.closedloop.closed_loop`), and the linear prediction of the tower DEL
    change (%, ``openfast_table3.predicted_del``); with ``figures`` (a folder) the paper's
    Fig. 8 from OpenFAST per speed (the runs' seed-mean Welch spectra, solid, against |T|²S_W
    on the same linearisation, dashed) and Fig. 10 (with ``reduced``, :func:`reduced_model_changes`,
    the reduced model's rainflow beside OpenFAST's). Returns the table and the predictions
    {(controller, speed): %}."""

    speeds = sorted({v for m in made.values() for v in m})
    label, lo, hi = BANDS[2]
    lines = ["| wind (m/s) | controller | closed-loop poles in "
             f"{TOWER_MODE_BAND[0]}-{TOWER_MODE_BAND[1]} rad/s: \\|p\\| (rad/s), ζ | least ζ "
             f"| tower mode ζ (closedloop.tower_damping) | linear \\|T\\|²S_W in the {label} rad/s band (MN²·m²) "
             "| predicted tower DEL (%) |", "|---|---|---|---|---|---|---|"]
    preds = {}
    w = np.geomspace(lo, hi, 400)
    for v in speeds:
        plant = model.linearize(v)
        sw = wind_psd(model, v, w)
        loops = [(BASELINE, spec.baseline_controller(model, v), None, None)]
        loops += [(name, ct.tf(m[v]["design"].pitch_controller), m[v]["design"].atd_controller, m[v]["design"])
                  for name, m in made.items() if v in m]
        predicted = {}
        base_del = predicted_del(model, v)
        for name, c, atd, design in loops:
            cl = closedloop.closed_loop(plant, c, atd, warn=False)
            change = 100 * (predicted_del(model, v, design) / base_del - 1)
            preds[name, v] = change
            p = cl.poles()
            p = p[(p.imag > 0) & (np.abs(p) >= TOWER_MODE_BAND[0]) & (np.abs(p) <= TOWER_MODE_BAND[1])]
            z = -p.real / np.abs(p)
            t = cl["tower_base_my", "wind"](1j * w)
            var = float(np.trapezoid(np.abs(t) ** 2 * sw, w))
            lines.append(f"| {v:g} | {name} | " + ", ".join(f"{abs(a):.3f}, {b:.3f}" for a, b in zip(p, z))
                         + f" | {z.min() if z.size else float('nan'):.3f} | {closedloop.tower_damping(plant, cl)[1]:.3f} "
                         f"| {var / 1e12:.3g} | {change:+.1f} |")
            predicted[name] = cl
        if figures is not None:
            _fig8(runs, v, model, predicted, Path(figures))
    if figures is not None:
        _fig10(runs, preds, Path(figures), reduced=reduced)
    return "\n".join(lines), preds


#: The paper's Table 3 (seed 004, Table 3: fatigue reduction, %, at 15-25 m/s; its "estimation
#: deviation" is |linear prediction − rainflow|): row → values per wind speed, then the mean it
#: prints (None where it prints none).
PAPER_TABLE3 = {
    "specification": ((37.37, 10.10, 11.78, 20.55, 35.97, 30.35), None),
    "linear prediction": ((24.81, 24.15, 28.60, 27.93, 35.12, 30.36), None),
    "rainflow": ((25.91, 22.24, 27.75, 27.28, 34.71, 28.84), None),
    "deviation": ((1.1, 1.91, 0.85, 0.65, 0.41, 1.52), 1.07),
}
PAPER_SPEEDS = (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)


def reduced_model_changes(made, runs, baseline=BASELINE, m=4.0) -> dict:
    """The designs and ROSCO's LTI form (:func:`specdesign.rosco.rosco_scheduled`) on the
    workbench's reduced IEA 15 MW model (:func:`specdesign.validate.run_campaign`, its own
    rotor-effective wind from the same seed numbers as the OpenFAST runs, 600 s after 60 s,
    the model's torque law below rated and the trim torque above, as the exported library):
    {(controller, speed): (change %, SE pp, seeds)} of the tower DEL."""
    from specdesign.rosco import rosco_scheduled
    from specdesign.simulate import ScheduledController
    from specdesign.turbine import iea15mw

    reduced = iea15mw()
    out = {}
    for name, by_v in made.items():
        for v, entry in by_v.items():
            st = _cell_stats(runs, baseline, name, v, m)
            if st is None:
                continue
            d = entry["design"]
            camp = validate.run_campaign(
                {baseline: rosco_scheduled(reduced), name: ScheduledController.fixed(d.pitch_controller, d.atd_controller)},
                [v], st["seeds"], model=reduced, predict=False, progress=False)
            ch = validate.paired_change(camp.values["tower_del"][1], camp.values["tower_del"][0], "tower_del", m=m)
            out[name, v] = (float(ch.change[0]), float(ch.se[0]), st["seeds"])
    return out


def table3(runs, made, preds, reduced=None, baseline=BASELINE, m=4.0) -> str:
    """Table 3 from OpenFAST per design, beside the paper's: the specification the design meets
    (``openfast_table3.designs``' promise), the linear prediction on OpenFAST's linearisation
    (``preds``), the OpenFAST rainflow reduction over the paired seeds (± jackknife SE from two
    seeds up), the deviation (rainflow − prediction, pp; its SE is the rainflow's, the
    prediction being exact), the reduced model's rainflow on the same seed numbers
    (:func:`reduced_model_changes`, when given) and the actuator's cost (pitch-rate SD, pitch
    travel, time at the rate limit); reductions are positive, as the paper prints them."""
    blocks = []
    for name, by_v in made.items():
        stats = table3_stats(runs, name, by_v, baseline, m)
        speeds = list(stats)
        if not speeds:
            continue
        store = table3_store_rows(name, stats, baseline)
        cols = " | ".join(f"{v:g}" for v in speeds)
        lines = [store.pop("title"), "",
                 f"| tower DEL reduction | {cols} | mean |", "|---|" + "---|" * (len(speeds) + 1)]
        rain = {v: -stats[v]["tower_del"][0] for v in speeds}
        pred = {v: -preds[name, v] for v in speeds}
        dev = {v: pred[v] - rain[v] for v in speeds}
        row = {"specification (this workbench)": [f"{by_v[v]['promise']:.1f} %" for v in speeds] + [""],
               "linear prediction (OpenFAST's linearisation)": [f"{pred[v]:.1f} %" for v in speeds] + [""],
               "rainflow, OpenFAST": store["rainflow, OpenFAST"],
               "deviation, prediction − rainflow": [f"{dev[v]:+.1f}{_tower_se(stats[v])} pp" for v in speeds]
               + [f"{np.mean(list(dev.values())):+.1f} pp (\\|·\\| {np.mean(np.abs(list(dev.values()))):.1f})"]}
        if reduced is not None:
            row["rainflow, reduced model (same seed numbers)"] = [
                (f"{-reduced[name, v][0]:.1f}" + (f" ± {reduced[name, v][1]:.1f}" if len(reduced[name, v][2]) > 1 else "")
                 + " %") if (name, v) in reduced else "" for v in speeds] + [""]
        row.update(store)  # the actuator's cost, after the fatigue rows
        for key, (vals, mean) in PAPER_TABLE3.items():
            paper = dict(zip(PAPER_SPEEDS, vals))
            unit = " %" if key != "deviation" else " pp"
            row[f"the paper: {key}"] = [f"{paper[v]:.2f}{unit}" if v in paper else "" for v in speeds] + [
                "" if mean is None else f"{mean:.2f}{unit}"]
        lines += [f"| {k} | " + " | ".join(cells) + " |" for k, cells in row.items()]
        blocks.append("\n".join(lines))
    return "\n\n".join(blocks)


def table3_stats(runs, name, speeds, baseline=BASELINE, m=4.0) -> dict:
    """:func:`_cell_stats` of design ``name`` per speed of ``speeds``, in order, where it and
    ``baseline`` have paired runs: the speeds of its Table 3 block."""
    stats = {v: _cell_stats(runs, baseline, name, v, m) for v in sorted(speeds)}
    return {v: st for v, st in stats.items() if st is not None}


def _tower_se(st) -> str:
    """" ± SE" of the tower DEL change, from two paired seeds up."""
    return f" ± {st['tower_del'][1]:.1f}" if len(st["seeds"]) > 1 else ""


def table3_store_rows(name, stats, baseline=BASELINE) -> dict:
    """The parts of design ``name``'s Table 3 block that the runs alone give (no design made
    again): its title line, the OpenFAST rainflow row and the actuator's cost (pitch-rate SD,
    pitch travel, time at the rate limit) as lists of cells (the mean column last). ``stats`` as
    :func:`table3_stats` gives them."""
    def travel(st, who):
        x, k = st["pitch_travel", who]
        return f"{x:.0f}" if k else "not recorded"
    return {"title": f"**{name}** (tower-base DEL reduction against {baseline}; seeds per speed: "
            + ", ".join(f"{v:g} m/s: {len(st['seeds'])}" for v, st in stats.items()) + ")",
            "rainflow, OpenFAST": [f"{-st['tower_del'][0]:.1f}{_tower_se(st)} %" for st in stats.values()] + [""],
            f"pitch-rate SD (deg/s): {baseline} / design": [
                f"{st['pitch_rate_sd', 'base'][0]:.3f} / {st['pitch_rate_sd', 'design'][0]:.3f}"
                for st in stats.values()] + [""],
            f"pitch travel (deg/h): {baseline} / design": [
                f"{travel(st, 'base')} / {travel(st, 'design')}" for st in stats.values()] + [""],
            "at the rate limit (%): design": [f"{st['rate_limit_time', 'design'][0]:.2f}" for st in stats.values()] + [""]}


def splice_table3(docs: str, printed: str) -> str:
    """``docs`` with each Table 3 block of ``printed`` (:func:`table3`: its bold title line, a
    blank line, its table) in place of the block of the same design and baseline."""
    lines, printed = docs.splitlines(), printed.splitlines()
    for start in (i for i, line in enumerate(printed) if _TABLE3_TITLE.match(line)):
        key = _TABLE3_TITLE.match(printed[start]).group(1)
        block = printed[start:_table_end(printed, start)]
        where = [i for i, line in enumerate(lines) if (t := _TABLE3_TITLE.match(line)) and t.group(1) == key]
        if len(where) != 1:
            raise SystemExit(f"--docs: {len(where)} Table 3 blocks titled {key!r} there, 1 expected")
        lines[where[0]:_table_end(lines, where[0])] = block
    return "\n".join(lines) + ("\n" if docs.endswith("\n") else "")


_TABLE3_TITLE = re.compile(r"(\*\*[^*]+\*\* \(tower-base DEL reduction against [^;]+);")


def _table_end(lines, title) -> int:
    """The index after the table that follows the title line ``title`` (blank lines between)."""
    i = title + 1
    while i < len(lines) and not lines[i].startswith("|"):
        i += 1
    while i < len(lines) and lines[i].startswith("|"):
        i += 1
    return i


def _fig8(runs, v, model, loops, folder):
    """The paper's Fig. 8 from OpenFAST at ``v``: generator speed (rpm²·s/rad) and tower-base
    moment (MN²·m²·s/rad) PSDs, runs (solid) vs linear prediction (dashed)."""
    folder.mkdir(parents=True, exist_ok=True)
    rpm = 30.0 / math.pi
    # each controller's mean over the seeds it has finished (the paired comparison is the tables')
    here = [r for r in runs if r.wind_speed == v and r.controller in loops]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
    for (out, unit, k), ax in zip((("gen_speed", "rpm²·s/rad", rpm ** 2), ("tower_base_my", "MN²·m²·s/rad", 1e-12)),
                                  axes):
        shown = []
        for name, cl in loops.items():
            mine = [r for r in here if r.controller == name]
            if not mine:
                continue
            w = mine[0].omega[1:]
            psd = np.mean([r.welch[out][1:] for r in mine], axis=0) * k
            ax.loglog(w, psd, color=_COLOURS.get(name, "k"),
                      label=f"{name}, OpenFAST (seeds {', '.join(str(r.seed) for r in mine)})")
            t = cl[out, "wind"](1j * w)
            ax.loglog(w, np.abs(t) ** 2 * wind_psd(model, v, w) * k, "--", color=_COLOURS.get(name, "k"), label=f"{name}, linear")
            shown.append(psd[(w >= 0.05) & (w <= 10)])
        # the range the runs span, not the linear roll-off's decades
        lo, hi = min(x.min() for x in shown), max(x.max() for x in shown)
        ax.set_ylim(lo / 3, hi * 3)
        ax.set_xlim(0.05, 10)
        ax.set_xlabel("frequency ω (rad/s)")
        ax.set_ylabel(f"PSD ({unit})")
        ax.set_title("generator speed" if out == "gen_speed" else "tower-base fore-aft moment")
        ax.axvline(3 * 7.56 * math.pi / 30, color="0.6", lw=0.8)  # 3P at rated rotor speed (7.56 rpm)
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(f"OpenFAST (solid, seed means) vs linear prediction on OpenFAST's linearisation (dashed) at "
                 f"{v:g} m/s; grey line: 3P at rated rotor speed")
    axes[1].legend(fontsize=8)
    path = folder / f"openfast_fig8_{v:g}mps.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}", file=sys.stderr)


def fig9(runs, folder, v=19.0, seed=0, span=(100.0, 300.0)) -> Path | None:
    """The paper's Fig. 9 from OpenFAST: generator speed, power, tower-base moment and pitch of
    every controller on the same TurbSim field (``seed`` at ``v`` m/s), ``span`` s of the record;
    None (and a note) when no run there kept its series (``openfast_table3.py`` keeps seed 0's
    since the figure was added)."""
    here = [r for r in runs if r.wind_speed == v and r.seed == seed and r.series]
    if not here:
        print(f"Fig. 9: no run at {v:g} m/s, seed {seed} kept its series", file=sys.stderr)
        return None
    folder.mkdir(parents=True, exist_ok=True)
    rows = (("gen_speed", "generator speed (rpm)", 30.0 / math.pi), ("power", "power (MW)", 1e-6),
            ("tower_base_my", "tower-base My (MN·m)", 1e-6), ("pitch", "blade pitch (deg)", DEG))
    fig, axes = plt.subplots(len(rows), 1, figsize=(9, 8), sharex=True, constrained_layout=True)
    for r in sorted(here, key=lambda r: r.controller != BASELINE):
        dt = float(r.meta["settings"]["record_dt"])
        n = r.series["gen_speed"].size
        t = np.arange(n) * dt
        keep = (t >= span[0]) & (t <= span[1])
        for (key, label, k), ax in zip(rows, axes):
            if key in r.series:
                x = r.series[key] * k
                unit = label[label.index("(") + 1:-1]
                # the SD over the whole 600 s record, as the paper reads its Fig. 9
                ax.plot(t[keep], x[keep], color=_COLOURS.get(r.controller, "k"), lw=0.8,
                        label=f"{r.controller}: mean {x.mean():.4g}, SD {x.std():.3g} {unit} (600 s)")
                ax.set_ylabel(label)
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="upper right")
    axes[-1].set_xlabel("time after the discarded transient (s)")
    fig.suptitle(f"OpenFAST at {v:g} m/s, seed {seed}: every controller on the same TurbSim field and sea state")
    path = folder / f"openfast_fig9_{v:g}mps.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}", file=sys.stderr)
    return path


#: Fig. 10's upper limit, %: a change above it is drawn at the edge with its value written.
TOP_PCT = 40.0


def _fig10(runs, preds, folder, baseline=BASELINE, m=4.0, reduced=None):
    """The paper's Fig. 10 from OpenFAST: per design, the tower DEL change against ROSCO's
    predicted on OpenFAST's linearisation (``preds[name, v]``, %) and measured by rainflow in
    OpenFAST (paired seeds, ± jackknife SE from two seeds up) against the wind speed; with
    ``reduced`` ({(name, v): (change %, SE pp, seeds)}) the reduced model's rainflow on the same
    seed numbers as open markers."""
    folder.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(11, 4.5), constrained_layout=True)
    names = sorted({name for name, _ in preds} - {baseline})
    for k, name in enumerate(names):
        speeds = sorted(v for n, v in preds if n == name)
        colour = _COLOURS.get(name, "k")
        ax.plot(speeds, [preds[name, v] for v in speeds], "--o", color=colour, mfc="none",
                label=f"{name}, linear prediction")
        got = [(v, _cell_stats(runs, baseline, name, v, m)) for v in speeds]
        got = [(v, st) for v, st in got if st is not None]
        if got:
            x = np.array([v for v, _ in got]) + 0.08 * (k - (len(names) - 1) / 2)  # side by side, not on top
            y = [st["tower_del"][0] for _, st in got]
            se = [st["tower_del"][1] if len(st["seeds"]) > 1 else 0.0 for _, st in got]
            ax.errorbar(x, np.minimum(y, TOP_PCT), yerr=se, fmt="s", color=colour, capsize=3,
                        label=f"{name}, OpenFAST rainflow (seeds per speed: "
                              + ", ".join(f"{v:g}: {len(st['seeds'])}" for v, st in got) + ")")
            here = [(xi, reduced[name, v]) for xi, (v, _) in zip(x, got) if (name, v) in (reduced or {})]
            if here:
                ax.errorbar([xi + 0.16 for xi, _ in here], [r[0] for _, r in here],
                            yerr=[r[1] if len(r[2]) > 1 else 0.0 for _, r in here], fmt="^", mfc="none",
                            color=colour, capsize=3, label=f"{name}, reduced model rainflow (same seed numbers)")
            for xi, yi in zip(x, y):
                if yi > TOP_PCT:  # a limit cycle's hundreds of per cent would flatten the rest: its value, written
                    ax.annotate(f"{yi:+.0f} % (off scale)", (xi, TOP_PCT), xytext=(6, -12), textcoords="offset points",
                                color=colour, fontsize=8)
    # the paper's own Table 3 (reductions, so negated): its turbine model, tuning and seeds
    ax.plot(PAPER_SPEEDS, [-x for x in PAPER_TABLE3["linear prediction"][0]], ":", color="0.45", lw=1.0,
            label="the paper: linear prediction")
    ax.plot(PAPER_SPEEDS, [-x for x in PAPER_TABLE3["rainflow"][0]], "x", color="0.45", label="the paper: rainflow")
    ax.axhline(0.0, color="0.5", lw=0.8)
    ax.set_ylim(top=TOP_PCT)
    ax.set_xlabel("mean wind speed (m/s)")
    ax.set_ylabel(f"tower-base DEL change vs {baseline} (%)")
    ax.set_title("Fig. 10 from OpenFAST: linear prediction vs rainflow (± SE over paired seeds)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    path = folder / "openfast_fig10.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {path}", file=sys.stderr)


#: The bands of :func:`pitch_sources` (rad/s): the control band, the tower mode, 3P and what lies above.
SOURCE_BANDS = ((0.05, 0.6), (0.6, 1.5), (1.5, 2.2), (2.2, 2.6), (2.6, 5.0), (5.0, 20.0))


def pitch_sources(runs, made) -> str:
    """Where a tower-damper design's pitch rate comes from, per band: the pitch-rate variance the
    run measured beside |C_β|²·S_Ω (through the generator speed) and |C_atd/jω|²·S_a (through the
    tower-top acceleration, integrated to the velocity the damper reads; its 0.05 rad/s high-pass
    aside), from the run's Welch spectra and the design's two controllers (``made``, as
    :func:`campaign_designs` makes them). Cross terms are left out, so the two need not add up to
    the measured variance; the last column is where the generator speed's spectrum peaks in the
    band. Runs made before the campaign kept the acceleration's spectrum are skipped (issue 28:
    which measurement carries the pitch above 3P)."""
    lines = [("| wind (m/s) | controller | seed | band (rad/s) | pitch-rate variance (deg²/s²) | through the generator "
              "speed | through the tower-top acceleration | generator-speed spectrum's peak (rad/s) |"),
             "|---|---|---|---|---|---|---|---|"]
    for r in runs:
        entry = made.get(r.controller, {}).get(r.wind_speed)
        d = entry and entry["design"]
        if d is None or getattr(d, "atd_controller", None) is None or "tower_top_acc" not in r.welch:
            continue
        w = r.omega[1:]
        cb, ca = closedloop.siso_response(d.pitch_controller, w), closedloop.siso_response(d.atd_controller, w)
        parts = (r.welch["pitch"][1:], np.abs(cb) ** 2 * r.welch["gen_speed"][1:],
                 np.abs(ca / (1j * w)) ** 2 * r.welch["tower_top_acc"][1:])
        for lo, hi in SOURCE_BANDS:
            cells = [DEG**2 * band_variance(w, w**2 * x, lo, hi) for x in parts]
            band = (w >= lo) & (w < hi)
            peak = w[band][np.argmax(r.welch["gen_speed"][1:][band])]
            lines.append(f"| {r.wind_speed:g} | {r.controller} | {r.seed} | {lo:g}-{hi:g} | "
                         + " | ".join(f"{c:.3g}" for c in cells) + f" | {peak:.2f} |")
    return "\n".join(lines) if len(lines) > 2 else "No run with the tower-top acceleration's spectrum and a tower damper."


def _row_tables(lines) -> list:
    """(header, first row, end) of every table keyed by wind speed and controller in ``lines``."""
    found, i = [], 0
    while i < len(lines):
        if lines[i].startswith("| wind (m/s) | controller |") and lines[i + 1 : i + 2] and lines[i + 1].startswith("|---"):
            j = i + 2
            while j < len(lines) and re.match(r"\| \d+(\.\d+)? \| ", lines[j]):
                j += 1
            found.append((lines[i], i + 2, j))
            i = j
        else:
            i += 1
    return found


def splice(docs: str, printed: str) -> tuple[str, list]:
    """``docs`` with every row of ``printed``'s (wind, controller) tables in the table of the same
    header: a row of the same wind and controller replaced, a new one inserted in order of wind,
    then controller. Rows the report does not give (runs of another store) are kept and returned,
    so that the caller can say which rows are not from this store."""
    lines, printed = docs.splitlines(), printed.splitlines()
    kept = []
    for header, a, b in _row_tables(printed):
        rows = {_row_key(r): r for r in printed[a:b]}
        target = [t for t in _row_tables(lines) if t[0] == header]
        if len(target) != 1:
            raise SystemExit(f"--docs: {len(target)} tables headed {header[:60]}... there, 1 expected")
        _, da, db = target[0]
        merged = {_row_key(r): r for r in lines[da:db]}
        kept += [r for k, r in merged.items() if k not in rows]
        merged.update(rows)
        lines[da:db] = [merged[k] for k in sorted(merged)]
    return "\n".join(lines) + ("\n" if docs.endswith("\n") else ""), kept


def _row_key(row: str) -> tuple[float, str]:
    wind, controller = (c.strip() for c in row.split("|")[1:3])
    return float(wind), controller


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--folder", default=str(STORE / "runs"),
                    help="the campaign's run folder (default: openfast_table3.STORE's, in the repository)")
    ap.add_argument("--baseline", default="ROSCO")
    ap.add_argument("--speeds", default=None,
                    help="only the runs at these wind speeds, m/s, comma-separated (docs/comparison.md: "
                         "openfast_comparison.py's, --speeds 17,19); default: every run of the store")
    ap.add_argument("--damping", action="store_true",
                    help="also the closed-loop tower-mode damping on OpenFAST's linearisations (designs again)")
    ap.add_argument("--table3", action="store_true",
                    help="also Table 3 per design beside the paper's: specification, linear prediction, OpenFAST and "
                         "reduced-model rainflow, deviation (designs again, runs the reduced model on the same seeds)")
    ap.add_argument("--docs", default=None, metavar="PAGE",
                    help="also write the (wind, controller) tables into PAGE (docs/openfast.md): each row replaced "
                         "by the store's or inserted; rows the store does not give are kept and listed; with --table3, "
                         "each design's Table 3 block replaced whole")
    ap.add_argument("--pitch-sources", action="store_true",
                    help="also the tower-damper designs' pitch rate by band, measured and through each measurement "
                         "(runs with the tower-top acceleration's spectrum; designs again)")
    ap.add_argument("--figures", default=None,
                    help="folder for Fig. 9 from OpenFAST (19 m/s, seed 0, where its series were kept) and, with "
                         "--damping, Fig. 8 per speed and Fig. 10")
    args = ap.parse_args()
    runs = validate.read_openfast_runs(args.folder)
    if args.speeds is not None:
        speeds = {float(x) for x in args.speeds.split(",")}
        runs = [r for r in runs if r.wind_speed in speeds]
        if not runs:
            ap.error(f"--speeds {args.speeds}: no run of the store at these wind speeds")
    printed = [report(Path(args.folder), runs, baseline=args.baseline)]
    print(printed[0])
    if args.figures is not None:
        fig9(runs, Path(args.figures))
    if args.pitch_sources or args.damping or args.table3:
        model, made = campaign_designs(runs)
    if args.pitch_sources:
        print("\n" + pitch_sources(runs, made))
    if args.damping or args.table3:
        reduced = reduced_model_changes(made, runs) if args.table3 else None
        damping, preds = linear_side(runs, model, made, figures=args.figures if args.damping else None, reduced=reduced)
        if args.damping:
            print("\n" + damping)
            printed.append(damping)
        if args.table3:
            printed_t3 = table3(runs, made, preds, reduced)
            print("\n" + printed_t3)
    if args.docs is not None:
        page = Path(args.docs)
        text, kept = splice(page.read_text(), "\n\n".join(printed))
        if args.table3:
            text = splice_table3(text, printed_t3)
        page.write_text(text)
        print(f"\n{page}: the store's rows written" + "".join(f"\n  kept, not from this store: {r[:70]}..." for r in kept))

if __name__ == "__main__":
    main()
