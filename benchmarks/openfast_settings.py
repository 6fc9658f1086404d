"""What the OpenFAST campaign's settings cost and change: the shipped IEA 15 MW monopile deck
with ROSCO's DISCON at 19 m/s on one TurbSim field (13 × 13 grid, NTM class B), run with

- ``reference``: DT = 0.005 s, SeaState/HydroDyn on, the deck's full output list every step;
- ``campaign``: the same model, only the campaign's 9 channels every 0.05 s;
- ``no_hydro``: as ``campaign`` with SeaState and HydroDyn off;
- ``dt_0.01``: as ``campaign`` with DT = 0.01 s;
- ``reference_blas``: as ``campaign`` on the reference BLAS the executable links
  (``SPECDESIGN_OPENFAST_BLAS=system``), against the serial OpenBLAS the workbench picks when
  it is installed (``campaign``; give its folder in ``SPECDESIGN_OPENFAST_BLAS`` when it is not
  installed system-wide);

printing OpenFAST's CPU time per simulated second and each indicator's change against the
reference (tower-base DEL m = 4, blade-root DEL m = 10, pitch and speed SDs), after the
transient. Also TurbSim's time per grid. docs/openfast.md records a run.

Run: ``nice python benchmarks/openfast_settings.py [--tmax 160] [--transient 40] [--out DIR]
[--variants campaign,reference_blas] [--processes 1]`` (about 1.5 × tmax s of CPU per variant,
all at once unless ``--processes`` says otherwise).
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import re
import time
from pathlib import Path

from specdesign.openfast import OpenFASTRunError, find_openfast, iea15mw_monopile, run_case, write_case
from specdesign.openfast.turbsim import turbsim_field
from specdesign.rosco.discon import rosco_library
from specdesign.turbine import iea15mw
from specdesign.validate import indicators
from specdesign.validate.openfast_campaign import OPENFAST_SERIES
from specdesign.openfast import series_from_openfast

VARIANTS = {
    "reference": dict(channels=None, dt_out=None),
    "campaign": dict(),
    "no_hydro": dict(hydro=False),
    "dt_0.01": dict(dt=0.01),
    "reference_blas": dict(blas="system"),
}


def cpu_seconds(log: Path) -> float:
    """OpenFAST's own 'Total CPU Time' from its screen output (s; it prints seconds, minutes or hours)."""
    m = re.search(r"Total CPU Time:\s*([\d.Ee+-]+)\s*(seconds|minutes|hours|days)", log.read_text())
    scale = {"seconds": 1.0, "minutes": 60.0, "hours": 3600.0, "days": 86400.0}
    return float(m.group(1)) * scale[m.group(2)] if m else float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--tmax", type=float, default=160.0)
    ap.add_argument("--transient", type=float, default=40.0)
    ap.add_argument("--wind-speed", type=float, default=19.0)
    ap.add_argument("--out", default="build/openfast_settings")
    ap.add_argument("--processes", type=int, default=None, help="OpenFAST runs at a time (default: all at once)")
    ap.add_argument("--variants", default=",".join(VARIANTS),
                    help="comma-separated, the first is the reference of the changes (default: %(default)s)")
    args = ap.parse_args()
    inst = find_openfast()
    t0 = time.monotonic()
    wind = turbsim_field(args.wind_speed, 0, length=args.tmax, install=inst)
    print(f"TurbSim 13x13, {args.tmax:g} s: {wind.seconds:.1f} s wall ({'cached' if not wind.seconds else 'made'})")
    deck = iea15mw_monopile()
    discon_in = deck.fst.with_name(f"{deck.name}_DISCON.IN")
    op = iea15mw().trim(args.wind_speed)
    out = Path(args.out).resolve()

    def run(name, kw):
        base = dict(tmax=args.tmax, wind_speed=args.wind_speed, wind_file=wind.path, seed=0, library=rosco_library(),
                    parameters=discon_in, dt_out=0.05, initial_pitch=op.pitch, initial_rotor_speed=op.rotor_speed)
        kw = dict(kw)
        blas = kw.pop("blas", None)
        base.update(kw)
        case = write_case(deck, out / name, **base)
        t = time.monotonic()
        o = run_case(case, inst, channels=list(OPENFAST_SERIES),
                     env=None if blas is None else {"SPECDESIGN_OPENFAST_BLAS": blas})
        wall = time.monotonic() - t
        series, dt = series_from_openfast(o, OPENFAST_SERIES)
        keep = o.time >= args.transient - 1e-9
        # the reference writes every step: compare on the campaign's 0.05 s samples
        step = int(round(0.05 / dt))
        rec = {k: a[:, keep][:, ::step] for k, a in series.items()}
        ind = indicators(rec, dt * step, 4.0).as_dict()
        return name, {k: float(v[0]) for k, v in ind.items()}, cpu_seconds(case.log), wall, case.outb.stat().st_size

    def attempt(kv):  # a variant OpenFAST refuses is a row of the result, not the end of it
        try:
            return run(*kv)
        except OpenFASTRunError as e:
            print(f"{kv[0]}: {e}\n")
            return None

    chosen = {k: VARIANTS[k] for k in args.variants.split(",")}
    with cf.ThreadPoolExecutor(args.processes or len(chosen)) as pool:  # CPU time is what is compared
        res = {r[0]: r[1:] for r in pool.map(attempt, chosen.items()) if r is not None}
    first = next(iter(chosen))
    ref = res[first][0]
    print(f"\n{args.tmax:g} s simulated at {args.wind_speed:g} m/s, indicators after {args.transient:g} s")
    print("| variant | CPU s per simulated s | output MB | tower DEL | blade DEL | pitch SD | gen-speed SD |")
    print("|---|---|---|---|---|---|---|")
    for name, (ind, cpu, wall, size) in res.items():
        def d(k):
            return "—" if name == first else f"{100 * (ind[k] / ref[k] - 1):+.2f} %"
        print(f"| {name} | {cpu / args.tmax:.2f} | {size / 1e6:.1f} | {d('tower_del')} | {d('blade_del')} | "
              f"{d('pitch_sd')} | {d('gen_speed_sd')} |")
    print(f"\n{first}: tower DEL {ref['tower_del'] / 1e6:.2f} MN·m, blade DEL {ref['blade_del'] / 1e6:.2f} MN·m; "
          f"wall {time.monotonic() - t0:.0f} s")


if __name__ == "__main__":
    main()
