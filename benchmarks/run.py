"""Run every benchmark in this folder, one after the other, in one go.

python benchmarks/run.py            # all
python benchmarks/run.py fatigue    # only bench_fatigue.py
Each script prints its timings beside the reference tools' as ratios.
"""
from __future__ import annotations

import runpy
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv):
    scripts = sorted(HERE.glob("bench_*.py"))
    if argv:
        scripts = [s for s in scripts if any(a in s.stem for a in argv)]
    for script in scripts:
        print(f"\n=== {script.name} ===", flush=True)
        runpy.run_path(str(script), run_name="__main__")


if __name__ == "__main__":
    main(sys.argv[1:])
