"""Command line: ``python -m specdesign demo`` and ``python -m specdesign validate CONFIG``."""
from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    from specdesign import __version__

    parser = argparse.ArgumentParser(prog="specdesign", description=__doc__)
    parser.add_argument("--version", action="version", version=f"specdesign {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the 19 m/s design loop and write its tables and figures")
    demo.add_argument("--out", default="specdesign_output", help="output folder (default: %(default)s)")
    demo.add_argument("--fast", action="store_true", help="reduced sizes (fewer seeds, shorter runs)")
    val = sub.add_parser("validate", help="run an offline validation campaign described by a TOML/JSON file")
    val.add_argument("config", help="TOML or JSON campaign file")
    val.add_argument("--out", default=None, help="output folder (default: from the config file)")
    args = parser.parse_args(argv)
    try:
        if args.command == "demo":
            from specdesign.demo import run_demo

            run_demo(out=args.out, fast=args.fast)
        else:
            from specdesign.validate import run_config

            run_config(args.config, out=args.out)
    except (ValueError, TypeError, OSError) as e:
        # bad input from the user (a file, a key, an unwritable folder): the message names it;
        # a traceback would only hide it
        print(f"specdesign {args.command}: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
