"""Health-aware LPV MPC (issue 17 part 2; Boutrous, Nejjari and Puig): the energy / blade and
tower damage trade-off as the health weight varies (docs/health_mpc.md), and the fit of the blade-root
moment's centre of thrust to OpenFAST (specdesign/turbine/kernel.py).

Trade-off: ROSCO (gain-scheduled) and HealthMPC with ψ ∈ {0, 3, 10, 30, 100} (blade-moment
excursions, the workbench's penalty) and ψ_acc ∈ {10, 30, 100} (Boutrous et al.'s health-aware
accumulated-moment term), IEA 15 MW, the same class-B wind for all (speeds × seeds), DELs fatigue-pooled over the runs
(specdesign.mpc.health_report). Writes docs/figures/health_mpc.png and prints a markdown table.

--fit-centre: reads the IEA-15-240-RWT UMaineSemi linearisation deck shipped with the rosco
package (mean RootMyc over blades and azimuths per wind speed), fits r_T/R = c0 + c1 β + c2 β²
to RootMyc / (T/3) with T from this model's Ct table at OpenFAST's operating point, and prints
the coefficients and the model's moment against OpenFAST's per wind speed.

Run: python benchmarks/health_mpc.py [--seeds 2] [--duration 300] [--speeds 15 19 23]
     python benchmarks/health_mpc.py --fit-centre
"""
from __future__ import annotations

import argparse
import importlib.util
import time
from pathlib import Path

import numpy as np

from specdesign import turbine


def fit_centre():
    from specdesign.openfast.lin import read_lin_file
    from specdesign.turbine.kernel import BLADE_COUNT, THRUST_CENTRE_COEFFS

    spec = importlib.util.find_spec("rosco")
    deck = (Path(list(spec.submodule_search_locations)[0]).parent / "Examples" / "Test_Cases" / "IEA-15-240-RWT"
            / "IEA-15-240-RWT-UMaineSemi" / "linearizations")
    cases = {}
    for f in sorted(deck.glob("lin_*.lin")):
        lin = read_lin_file(f)
        y = dict(zip(lin.y_desc, lin.y_op))
        my = np.mean([y[f"ED RootMyc{b}, (kN-m)"] for b in (1, 2, 3)]) * 1e3
        cases.setdefault(lin.wind_speed, []).append((my, np.deg2rad(y["ED BldPitch1, (deg)"]), lin.rotor_speed,
                                                     y["ED RotThrust, (kN)"] * 1e3))
    m = turbine.iea15mw()
    R, area = m.rotor_radius, np.pi * m.rotor_radius**2
    rows = []
    for v, r in sorted(cases.items()):
        my, beta, omega, thrust_of = np.mean(r, axis=0)
        _, ct = m.rotor_coefficients(omega * R / v, beta)
        thrust = 0.5 * m.air_density * area * v**2 * float(ct)
        rows.append((v, beta, omega, my, thrust, thrust_of))
    rows = np.array(rows)
    fit = rows[:, 0] >= 7.0
    frac = rows[:, 3] / (rows[:, 4] / BLADE_COUNT) / R
    c2, c1, c0 = np.polyfit(rows[fit, 1], frac[fit], 2)
    print(f"OpenFAST deck: {deck}")
    print(f"fit (7-24 m/s): c0 = {c0:.5f}, c1 = {c1:.5f}, c2 = {c2:.5f} (kernel: {THRUST_CENTRE_COEFFS})")
    print("| wind (m/s) | pitch (deg) | OpenFAST RootMyc (MN·m) | model r_T·T/3 (MN·m) | error | r_T/R | "
          "OpenFAST RotThrust (kN) | model thrust (kN) |")
    print("|---|---|---|---|---|---|---|---|")
    for v, beta, omega, my, thrust, thrust_of in rows:
        y = m.evaluate_outputs([omega, 0.0, 0.0, beta, 0.0], v, beta, m.rated_generator_torque)[6]
        mark = "" if v >= 7.0 else " (outside the fit)"
        print(f"| {v:g}{mark} | {np.rad2deg(beta):.2f} | {my / 1e6:.2f} | {y / 1e6:.2f} | {100 * (y / my - 1):+.1f} % | "
              f"{turbine.kernel.thrust_centre(beta):.3f} | {thrust_of / 1e3:.0f} | {thrust / 1e3:.0f} |")


def tradeoff(args):
    from matplotlib import use  # noqa: F401  (the Figure below needs no backend)

    from specdesign.fatigue import BLADE_M, TOWER_M
    from specdesign.mpc.health_report import health_tradeoff, plot_tradeoff

    m = turbine.iea15mw()
    t0 = time.perf_counter()
    pts = health_tradeoff(m, args.speeds, list(range(1, args.seeds + 1)), duration=args.duration,
                          transient=args.transient)
    took = time.perf_counter() - t0
    ref = next(p for p in pts if p.label.startswith("ψ"))
    print(f"IEA 15 MW, wind {', '.join(f'{v:g}' for v in args.speeds)} m/s (class B), seeds 1..{args.seeds}, "
          f"{args.duration:g} s recorded after {args.transient:g} s; reference {ref.label}")
    print("| controller | mean power (MW) | energy vs ref | blade DEL m=10 (MN·m) | blade damage vs ref | "
          "tower DEL m=4 (MN·m) | tower damage vs ref | gen.-speed SD (rpm) | max speed (rpm) | pitch-rate SD (deg/s) "
          "| CPU per sample (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    rpm = 30 / np.pi
    for p in pts:
        cpu = "–" if not np.isfinite(p.cpu_per_step) else f"{1e3 * p.cpu_per_step:.2f}"
        print(f"| {p.label} | {p.mean_power / 1e6:.3f} | {100 * (p.mean_power / ref.mean_power - 1):+.2f} % "
              f"| {p.blade_del / 1e6:.3f} | {(p.blade_del / ref.blade_del) ** BLADE_M:.3g} "
              f"| {p.tower_del / 1e6:.2f} | {(p.tower_del / ref.tower_del) ** TOWER_M:.3g} "
              f"| {p.speed_sd * rpm:.3f} | {p.max_speed * rpm:.2f} | {np.rad2deg(p.pitch_rate_sd):.3f} | {cpu} |")
    out = Path(__file__).resolve().parents[1] / "docs" / "figures" / "health_mpc.png"
    plot_tradeoff(pts).savefig(out, dpi=110)
    print(f"figure: {out.relative_to(out.parents[2])}; {took:.0f} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--duration", type=float, default=300.0)
    ap.add_argument("--transient", type=float, default=60.0)
    ap.add_argument("--speeds", type=float, nargs="+", default=[15.0, 19.0, 23.0])
    ap.add_argument("--fit-centre", action="store_true", help="fit the blade moment's centre of thrust to OpenFAST")
    args = ap.parse_args()
    if args.fit_centre:
        fit_centre()
    else:
        tradeoff(args)


if __name__ == "__main__":
    main()
