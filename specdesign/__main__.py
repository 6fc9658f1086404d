"""Command line: ``python -m specdesign demo`` and ``python -m specdesign validate CONFIG``.

A user error (a bad campaign or controller file, a missing file, an output folder that
cannot be written) is reported on one line naming the file and the key, with exit code 2
and no traceback; a programming error keeps its traceback.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _one_line(e: BaseException) -> str:
    msg = " ".join(str(e).split("\n")).strip()
    name = getattr(e, "filename", None)  # an OSError raised by the system names its file here
    if name is not None and str(name) not in msg:
        msg = f"{name}: {msg}"
    return msg or type(e).__name__


def _writable(folder: str, key: str) -> None:
    """Create ``folder`` and write a probe file there, before minutes of work."""
    path = Path(folder)
    try:
        path.mkdir(parents=True, exist_ok=True)
        probe = path / ".specdesign_write_test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        raise type(e)(f"{key}: the output folder {path} cannot be created or written ({e.strerror or e}); "
                      "choose a writable folder") from None


def main(argv: list[str] | None = None) -> int:
    from specdesign import __version__

    parser = argparse.ArgumentParser(prog="specdesign", description=__doc__.splitlines()[0],
                                     epilog="Campaign file schema: docs/validation.md.")
    parser.add_argument("--version", action="version", version=f"specdesign {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the 19 m/s design loop and write its tables and figures")
    demo.add_argument("--out", default="specdesign_output", help="output folder (default: %(default)s)")
    demo.add_argument("--fast", action="store_true", help="reduced sizes (fewer seeds, shorter runs)")
    val = sub.add_parser("validate", help="run an offline validation campaign described by a TOML/JSON file")
    val.add_argument("config", help="TOML or JSON campaign file (schema: docs/validation.md)")
    val.add_argument("--out", default=None, help="output folder (default: from the config file)")
    args = parser.parse_args(argv)
    from specdesign.validate import ConfigError

    try:
        if args.command == "demo":
            from specdesign.demo import run_demo

            _writable(args.out, "--out")
            run_demo(out=args.out, fast=args.fast)
        else:
            from specdesign.validate import run_config

            run_config(args.config, out=args.out)
    except (ConfigError, OSError) as e:
        # bad input from the user (a file, a key, an unwritable folder): the message names it
        # and says what it must be; a traceback would only hide it. Other exceptions are
        # programming errors and keep their traceback.
        print(f"specdesign {args.command}: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"specdesign {args.command}: interrupted", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":
    sys.exit(main())
