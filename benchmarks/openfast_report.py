"""What an OpenFAST campaign folder holds so far: Table 3's rainflow row, the actuator's cost and
where in frequency the tower-base moment changed, from the finished runs only (nothing is run).

Reads ``benchmarks/openfast_table3.py``'s folder (or any ``run_campaign(..., plant=Deck)``
store) with :func:`specdesign.validate.read_openfast_runs` and prints, per wind speed and
controller against the baseline on the seeds both have finished:

- the tower-base DEL change (1 Hz, m = 4; seeds pooled by damage, jackknife SE over the
  paired seeds), generator-speed SD and blade-root DEL changes;
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

    python benchmarks/openfast_report.py --folder build/openfast_table3/runs
    python benchmarks/openfast_report.py --folder build/openfast_table3/runs --damping
"""
from __future__ import annotations

import argparse
import math
import sys
from collections import defaultdict
from pathlib import Path

import control as ct
import numpy as np

from specdesign import spec, validate
from specdesign.closedloop import turbine_loop_poles

#: Bands of the tower-base moment's variance, rad/s: (label, low, high).
BANDS = (("wind 0.05-0.6", 0.05, 0.6), ("0.6-0.85", 0.6, 0.85), ("tower mode 0.85-1.5", 0.85, 1.5),
         ("1.5-2.2", 1.5, 2.2), ("3P 2.2-2.6", 2.2, 2.6), ("> 2.6", 2.6, np.inf))
#: Poles of the closed loop counted as the tower mode's (rad/s): around the IEA 15 MW monopile's
#: first fore-aft mode (1.07-1.1 rad/s in OpenFAST's linearisations and runs).
TOWER_MODE_BAND = (0.85, 1.4)
DEG = 180.0 / math.pi


def band_variance(omega, psd, lo, hi) -> float:
    """∫ PSD dω over lo ≤ ω < hi (rad/s), trapezoidal on the Welch grid."""
    m = (omega >= lo) & (omega < hi)
    return float(np.trapezoid(psd[m], omega[m])) if m.sum() > 1 else float("nan")


def _cell_stats(runs, base, name, v, m):
    b = {r.seed: r for r in runs if r.controller == base and r.wind_speed == v}
    d = {r.seed: r for r in runs if r.controller == name and r.wind_speed == v}
    seeds = sorted(set(b) & set(d))
    if not seeds:
        return None
    out = {"seeds": seeds}
    for ind in ("tower_del", "gen_speed_sd", "blade_del"):
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
    return out


def _pm(st, key, n) -> str:
    """A paired change ± its SE (the SE only from two seeds up)."""
    return f"{st[key][0]:+.1f} ± {st[key][1]:.1f}" if n > 1 else f"{st[key][0]:+.1f}"


def report(folder, baseline="ROSCO", m=4.0) -> str:
    runs = validate.read_openfast_runs(folder)
    if not runs:
        raise SystemExit(f"{folder}: no finished run yet")
    count = defaultdict(int)
    for r in runs:
        count[r.controller, r.wind_speed] += 1
    lines = [f"Finished runs in {folder}: " + ", ".join(f"{c} {v:g} m/s × {n}" for (c, v), n in sorted(count.items())), ""]
    names = sorted({r.controller for r in runs} - {baseline})
    speeds = sorted({r.wind_speed for r in runs})
    head = ("| wind (m/s) | controller | paired seeds | tower DEL (%) | gen-speed SD (%) | blade DEL (%) "
            f"| pitch-rate SD (deg/s): {baseline} / design | pitch travel (deg/h): {baseline} / design "
            "| at the rate limit (%): design |")
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    bands = []
    for v in speeds:
        for name in names:
            st = _cell_stats(runs, baseline, name, v, m)
            if st is None:
                continue
            n = len(st["seeds"])
            trav = st["pitch_travel", "base"], st["pitch_travel", "design"]
            lines.append(f"| {v:g} | {name} | {n} ({', '.join(map(str, st['seeds']))}) | {_pm(st, 'tower_del', n)} "
                         f"| {_pm(st, 'gen_speed_sd', n)} | {_pm(st, 'blade_del', n)} "
                         f"| {st['pitch_rate_sd', 'base'][0]:.3f} / {st['pitch_rate_sd', 'design'][0]:.3f} "
                         f"| {trav[0][0]:.0f} ({trav[0][1]} seeds) / {trav[1][0]:.0f} ({trav[1][1]} seeds) "
                         f"| {st['rate_limit_time', 'design'][0]:.2f} |")
            bands.append((v, name, st))
    lines += ["", "Tower-base moment variance by band, mean over the paired seeds (MN²·m²); design / baseline:", ""]
    head = "| wind (m/s) | controller | " + " | ".join(f"{b[0]} rad/s" for b in BANDS) + " |"
    lines += [head, "|" + "---|" * (head.count("|") - 1)]
    for v, name, st in bands:
        cells = []
        for label, _, _ in BANDS:
            vb, vd = st["band", label]
            cells.append(f"{vb / 1e12:.3g} → {vd / 1e12:.3g} (×{vd / vb:.2f})")
        lines.append(f"| {v:g} | {name} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def damping(speeds, target=25.0) -> str:
    """Closed-loop damping near the tower mode of the baseline and the QFT design (as
    openfast_table3.py designs it) on OpenFAST's linearisation at each speed."""
    from specdesign.openfast import iea15mw_monopile, linearize_deck  # OpenFAST's side only with --damping

    sys.path.insert(0, str(Path(__file__).parent))
    from openfast_table3 import designs  # the campaign's own design step, so the controllers are those run

    model = linearize_deck(iea15mw_monopile(), speeds, processes=1)
    made = designs(model, speeds, target)
    plant = validate.loop_plant(model)
    lines = ["| wind (m/s) | controller | closed-loop poles in "
             f"{TOWER_MODE_BAND[0]}-{TOWER_MODE_BAND[1]} rad/s: |p| (rad/s), ζ | least ζ |", "|---|---|---|---|"]
    for v in speeds:
        for name, c in (("baseline (ROSCO's PI on the linearisation)", spec.baseline_controller(model, v)),
                        ("QFT", ct.tf(made[v]["design"].pitch_controller))):
            p = turbine_loop_poles(plant, c, v)
            p = p[(p.imag > 0) & (np.abs(p) >= TOWER_MODE_BAND[0]) & (np.abs(p) <= TOWER_MODE_BAND[1])]
            z = -p.real / np.abs(p)
            lines.append(f"| {v:g} | {name} | " + ", ".join(f"{abs(a):.3f}, {b:.3f}" for a, b in zip(p, z))
                         + f" | {z.min() if z.size else float('nan'):.3f} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--folder", default="build/openfast_table3/runs", help="the campaign's run folder")
    ap.add_argument("--baseline", default="ROSCO")
    ap.add_argument("--damping", action="store_true", help="also the closed-loop tower-mode damping (designs again)")
    args = ap.parse_args()
    text = report(Path(args.folder))
    print(text)
    if args.damping:
        speeds = sorted({r.wind_speed for r in validate.read_openfast_runs(args.folder) if r.controller != args.baseline})
        print("\n" + damping(speeds))


if __name__ == "__main__":
    main()
