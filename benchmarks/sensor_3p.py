"""The 3P ripple in the measured generator speed of the IEA 15 MW, from OpenFAST: the amplitude
that :data:`specdesign.controller.noise.RIPPLE_3P_IEA15MW` quotes.

Runs the shipped monopile deck (``specdesign.openfast.iea15mw_monopile``) with ROSCO's DISCON at
19 m/s, steady wind with the deck's shear (the deterministic 3P: shear, tilt, tower shadow) and,
with ``--seeds``, TurbSim fields (NTM class B, adding the rotational sampling of turbulence),
``--tmax`` s each, the first ``--transient`` s discarded. The ripple is fitted locked to the
rotor azimuth (the ``Azimuth`` channel, unwrapped): after removing the record's mean and a
linear trend, least squares of ``GenSpeed`` on cos 3ψ, sin 3ψ gives the amplitude of the 3P line
(rad/s), also for the tower-top fore-aft acceleration ``YawBrTAxp`` (m/s²). The mean rotor speed
and the residual SD (what is not 3P) are printed beside it.

Run: ``nice -n 10 python benchmarks/sensor_3p.py [--tmax 120] [--transient 60] [--seeds 1]``
(about 1.7 s of OpenFAST CPU per simulated second; docs/sensors.md records a run).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from specdesign.openfast import find_openfast, iea15mw_monopile, run_case, write_case
from specdesign.openfast.turbsim import turbsim_field
from specdesign.rosco.discon import rosco_library
from specdesign.turbine import iea15mw

CHANNELS = ("Azimuth", "RotSpeed", "GenSpeed", "YawBrTAxp", "BldPitch1", "Wind1VelX")


def azimuth_line(psi: np.ndarray, x: np.ndarray, harmonic: int = 3) -> tuple[float, float, float]:
    """Amplitude and phase (rad) of the ``harmonic``-per-revolution line of ``x`` locked to the
    unwrapped azimuth ``psi`` (rad), and the SD of the rest, by least squares on
    [1, t, cos hψ, sin hψ] (the mean and a linear trend removed with the line)."""
    t = np.linspace(-1.0, 1.0, x.size)
    A = np.column_stack([np.ones_like(t), t, np.cos(harmonic * psi), np.sin(harmonic * psi)])
    coef, *_ = np.linalg.lstsq(A, x, rcond=None)
    resid = x - A @ coef
    # x ≈ c cos hψ + s sin hψ = amp·sin(hψ + phase)
    amp = float(np.hypot(coef[2], coef[3]))
    return amp, float(np.arctan2(coef[2], coef[3])), float(resid.std())


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--tmax", type=float, default=120.0)
    ap.add_argument("--transient", type=float, default=60.0)
    ap.add_argument("--wind-speed", type=float, default=19.0)
    ap.add_argument("--seeds", default="", help="comma-separated TurbSim seeds (default: steady wind only)")
    ap.add_argument("--out", default="build/sensor_3p")
    ap.add_argument("--nice", type=int, default=10)
    args = ap.parse_args()
    inst = find_openfast()
    deck = iea15mw_monopile()
    op = iea15mw().trim(args.wind_speed)
    cases = [("steady", None, None)]
    for s in filter(None, args.seeds.split(",")):
        field = turbsim_field(args.wind_speed, int(s), length=args.tmax + 30.0, install=inst)
        cases.append((f"seed{int(s)}", field.path, int(s)))
    rows = {}
    for name, wind_file, seed in cases:
        case = write_case(deck, Path(args.out) / name, tmax=args.tmax, wind_speed=args.wind_speed, wind_file=wind_file,
                          seed=seed, library=rosco_library(), parameters=deck.fst.with_name(deck.name + "_DISCON.IN"),
                          dt_out=0.025, channels=CHANNELS, initial_pitch=float(op.pitch), initial_rotor_speed=float(op.rotor_speed))
        out = run_case(case, inst, nice=args.nice)
        keep = out.time >= out.time[0] + args.transient
        psi = np.unwrap(out.channels["Azimuth"][keep])
        rot = out.channels["RotSpeed"][keep]
        row = {"mean_rotor_speed_rad_s": float(rot.mean()), "record_s": float(keep.sum() * out.dt)}
        for ch, unit in (("GenSpeed", "rad_s"), ("YawBrTAxp", "m_s2")):
            amp, phase, rest = azimuth_line(psi, out.channels[ch][keep])
            row[f"{ch}_3p_amplitude_{unit}"] = amp
            row[f"{ch}_3p_phase_rad"] = phase
            row[f"{ch}_rest_sd_{unit}"] = rest
        rows[name] = row
        print(name, json.dumps(row, indent=1), flush=True)
    Path(args.out).mkdir(parents=True, exist_ok=True)
    (Path(args.out) / "sensor_3p.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
