"""Specification-driven design timings (issue 14): run ``python benchmarks/bench_spec_driven.py``.

At one operating point (default 19 m/s), best of ``--repeat`` runs, beside the issue's targets:

1. the feasibility check of a specification pair (``feasibility.pitch_feasibility``);
2. the specification for a 25 % target (``feasibility.specification_for_target``: the convex
   Youla design on the ladder and the bisection, each certified over 5 plant cases);
3. the same target as a whole-band element specification, the user's entry point
   ``feasibility.shape_whole_band(base, 25)`` (the elements follow a
   certificate's envelope and are certified by a Youla design that meets them at every plant case);
4. the design that meets it (``qft.design_qft(spec=...)``: reduction + QFT checks);
5. the fixed-structure QFT design at the same point (``qft.design_qft``), for comparison.
"""
from __future__ import annotations

import argparse
import os
import warnings

from timing import timed

from specdesign import feasibility as fz
from specdesign import spec
from specdesign.qft import design_qft, spec_from_certified, spec_notch
from specdesign.turbine import iea15mw


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--speed", type=float, default=19.0)
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--fixed", action="store_true", help="also time the fixed-structure design (~1 min)")
    args = ap.parse_args(argv)
    model, v = iea15mw(), args.speed
    warnings.simplefilter("ignore", UserWarning)  # cvxpy's "solution may be inaccurate" on some rungs
    fz.achievable_pitch(model, v, 1.5)  # imports and first compilations out of the timings
    t_spec, ts = timed(lambda: fz.specification_for_target(model, v, 25.0), args.repeat)
    t_check, res = timed(lambda: fz.pitch_feasibility(model, v, ts.tower, ts.speed), args.repeat)
    t_design, d = timed(lambda: design_qft(model, v, spec=spec_from_certified(ts)), args.repeat)
    base = spec.baseline_analysis(model, v)
    t_whole, whole = timed(lambda: fz.shape_whole_band(base, 25.0), args.repeat)
    print(f"{'step at ' + format(v, 'g') + ' m/s':<52}{'time':>9}{'target':>9}{'ratio':>8}   (load {os.getloadavg()[0]:.1f})")
    for name, t, target in (("pitch_feasibility (check of the pair)", t_check, None),
                            ("specification_for_target (25 %, 5 plant cases)", t_spec, None),
                            ("  check + specification", t_check + t_spec, 1.0),
                            ("shape_whole_band (25 %, elements)", t_whole, None),
                            ("  check + element specification", t_check + t_whole, 1.0),
                            ("design_qft(spec=...) (reduction + QFT checks)", t_design, 10.0)):
        ratio = f"{t / target:7.2f}×" if target else ""
        print(f"{name:<52}{t:8.2f}s{(format(target, 'g') + 's') if target else '':>9}{ratio:>8}")
    print(f"feasible: {res.feasible}; promise {ts.promise.exact_del:.2f} %, prediction {d.del_reduction:.2f} %, "
          f"order {int(d.parameters['order'])}, all specs met: {d.success}")
    print(f"whole band: {whole.message}")
    if args.fixed:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            t_fixed, _ = timed(lambda: design_qft(model, v, spec=spec_notch()), 1)
        print(f"{'design_qft (fixed structure, DEL target)':<52}{t_fixed:8.2f}s")


if __name__ == "__main__":
    main()
