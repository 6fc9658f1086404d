"""Command line: ``specdesign demo`` and ``specdesign validate CONFIG`` (also ``python -m specdesign``).

Also the campaign files behind ``validate``: reading and checking a TOML/JSON campaign and the
controller files it names (every key at every level, before the first simulation; schema:
``docs/validation.md``), running it with :func:`specdesign.validate.run_campaign` and writing
its tables, indicators and figures.

A user error (a bad campaign or controller file, a missing file, an output folder that
cannot be written) is reported on one line naming the file and the key, with exit code 2
and no traceback; a programming error keeps its traceback.
"""
from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import tomllib
from pathlib import Path

import numpy as np

from loopshaping.controller import Controller

from . import __version__, turbine
from ._checks import distinct_keys
from .openfast.install import blas_folder, build_openfast, find_openfast
from .plots import validation as pv
from .rosco import rosco_scheduled
from .simulate import ScheduledController, scheduled
from .validate import (
    INDICATORS,
    Campaign,
    acceptance,
    check_campaign_step,
    check_plant_step,
    run_campaign,
    seeds_from,
    table2,
    table3,
)
from .wind import RECORD_LENGTH

__all__ = ["main", "ConfigError", "read_config", "load_controller", "run_config", "output_folder"]


def main(argv: list[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; default ``sys.argv[1:]``.

    Returns
    -------
    int
        Exit status: 0 on success, 2 for a user error (printed on one line), 130 when
        interrupted.

    Raises
    ------
    SystemExit
        From the argument parser (``--help``, ``--version``, an invalid command or option).

    Examples
    --------
    >>> main(["--version"])  # doctest: +SKIP
    specdesign 0.1.0
    """
    parser = argparse.ArgumentParser(prog="specdesign", description=_DESCRIPTION,
                                     epilog="Campaign file schema: docs/validation.md.")
    parser.add_argument("--version", action="version", version=f"specdesign {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    demo = sub.add_parser("demo", help="run the design loop at one wind speed (19 m/s by default) and write its tables "
                                        "and figures")
    demo.add_argument("--out", default="specdesign_output", help="output folder (default: %(default)s)")
    demo.add_argument("--fast", action="store_true", help="reduced sizes (fewer seeds, shorter runs)")
    demo.add_argument("--method", choices=("target", "notch"), default=None,
                      help="target: the specification for the DEL target and the design that meets it "
                           "(default); notch: the notch specification and the fixed-structure design")
    demo.add_argument("--wind-speed", default=None, metavar="M_S",
                      help="operating point of the design in m/s, within the design range (default 19)")
    demo.add_argument("--target", default=None, metavar="PCT",
                      help="tower-base DEL reduction to design for, %% between 0 and 100 (default 25)")
    demo.add_argument("--lifetime", action="store_true",
                      help="instead: ROSCO vs the scheduled QFT designs from cut-in to cut-out over a Weibull climate, "
                           "the lifetime tower-base DEL change with its SE")
    demo.add_argument("--seeds", default=None, metavar="N",
                      help="paired seeds (per wind bin with --lifetime), at least 2 (default 50, 8 with --fast; "
                           "--lifetime: 6, 3 with --fast)")
    demo.add_argument("--duration", default=None, metavar="S",
                      help="recorded seconds per run, 1-86400 (default 600; 300 with --fast)")
    demo.add_argument("--bin-width", default=None, metavar="M_S",
                      help="--lifetime: wind bin width in m/s, dividing cut-out minus cut-in (default 2)")
    demo.add_argument("--design-speeds", default=None,
                      help="--lifetime: comma-separated wind speeds of the QFT designs in m/s (default 15,17,...,25)")
    val = sub.add_parser("validate", help="run an offline validation campaign described by a TOML/JSON file")
    val.add_argument("config", help="TOML or JSON campaign file (schema: docs/validation.md)")
    val.add_argument("--out", default=None, help="output folder (default: from the config file)")
    ofa = sub.add_parser("openfast", help="build OpenFAST and TurbSim from source, or show the ones found")
    ofa.add_argument("action", choices=("build", "find"), help="build: from SOURCE into the cache; find: print the executables")
    ofa.add_argument("source", nargs="?", help="build: an OpenFAST source tarball or folder")
    ofa.add_argument("--source-version", default=None, help="build: the source's version X.Y.Z (default: from its name)")
    ofa.add_argument("--cache", default=None, help="build cache (default: $SPECDESIGN_OPENFAST_CACHE or ~/.cache/specdesign/openfast)")
    args = parser.parse_args(argv)
    _choose_backend()
    try:
        if args.command == "demo":
            from specdesign.demo import check_demo_options, check_lifetime_options, run_demo

            # every option checked before any design or simulation: a user error is one line
            seeds = _number_arg(args.seeds, "--seeds", integer=True)
            duration = _number_arg(args.duration, "--duration")
            target = _number_arg(args.target, "--target")
            target = 25.0 if target is None else target
            if args.lifetime:
                from specdesign.demo import LIFETIME_DESIGN_SPEEDS, run_lifetime_demo

                _only_without_lifetime(args)
                bin_width = _number_arg(args.bin_width, "--bin-width")
                bin_width = 2.0 if bin_width is None else bin_width
                speeds = _speeds_arg(args.design_speeds, LIFETIME_DESIGN_SPEEDS)
                try:
                    check_lifetime_options(seeds, duration, speeds, bin_width, fast=args.fast, target_reduction=target)
                except (TypeError, ValueError) as e:
                    raise _option_error(e) from None
                output_folder(args.out, "--out")
                run_lifetime_demo(out=args.out, fast=args.fast, n_seeds=seeds, duration=duration, bin_width=bin_width,
                                  design_speeds=speeds, target_reduction=target)
            else:
                for flag, given in (("--bin-width", args.bin_width), ("--design-speeds", args.design_speeds)):
                    if given is not None:
                        raise ConfigError(f"{flag} belongs to --lifetime; the design demo designs at --wind-speed")
                speed = _number_arg(args.wind_speed, "--wind-speed")
                speed = 19.0 if speed is None else speed
                try:
                    check_demo_options(speed, target, seeds, duration, fast=args.fast)
                except (TypeError, ValueError) as e:
                    raise _option_error(e) from None
                output_folder(args.out, "--out")
                run_demo(out=args.out, fast=args.fast, method=args.method or "target", wind_speed=speed,
                         target_reduction=target, n_seeds=seeds, duration=duration)
        elif args.command == "openfast":
            _openfast_command(args)
        else:
            run_config(args.config, out=args.out, echo=True)
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


# argparse prints these as they are: plain text, no reST markup (the module docstring has it)
_DESCRIPTION = ("Fatigue-based pitch-controller design: 'specdesign demo' runs the design loop (19 m/s by default), "
                "'specdesign validate CONFIG' reruns an offline validation campaign from a TOML/JSON file "
                "(also 'python -m specdesign').")


#: The demo functions' argument names → the command line's options, for their messages.
_DEMO_FLAGS = {"wind_speed": "--wind-speed", "target_reduction": "--target", "n_seeds": "--seeds",
               "duration": "--duration", "bin_width": "--bin-width", "design_speeds": "--design-speeds"}


def _option_error(e: BaseException) -> ConfigError:
    """A demo option's ValueError/TypeError as a ConfigError naming the command-line option."""
    text = _one_line(e)
    name = next((n for n in _DEMO_FLAGS if text.startswith(n)), None)
    return ConfigError(text if name is None else _DEMO_FLAGS[name] + text[len(name):])


def _number_arg(text, flag, *, integer=False):
    """A numeric option's text as a float (an int with ``integer``), None when not given; else a
    ConfigError naming ``flag`` (argparse's own error is two lines and a usage)."""
    if text is None:
        return None
    try:
        return int(text) if integer else float(text)
    except ValueError:
        what = "a whole number" if integer else "a number"
        raise ConfigError(f"{flag}={text!r} must be {what}") from None


def _only_without_lifetime(args):
    """Refuse the design demo's options given with --lifetime (silently unused otherwise)."""
    for flag, given in (("--wind-speed", args.wind_speed), ("--method", args.method)):
        if given is not None:
            raise ConfigError(f"{flag} belongs to the design demo; --lifetime designs at --design-speeds with the "
                              "target specification")


def _openfast_command(args) -> None:
    """``specdesign openfast build SOURCE`` / ``specdesign openfast find``: the executables' paths and version on stdout."""
    if args.action == "build":
        if args.source is None:
            raise ConfigError("openfast build needs SOURCE: an OpenFAST source tarball or folder")
        try:
            found = build_openfast(args.source, cache=args.cache, version=args.source_version)
        except (ValueError, RuntimeError) as e:  # a bad source or missing tools: the message says which
            raise ConfigError(str(e)) from None
    else:
        found = find_openfast(require_turbsim=False)
    blas = blas_folder()
    print(f"openfast {found.openfast}\nturbsim {found.turbsim}\nversion {found.version}\n"
          f"blas {blas if blas is not None else 'the libblas.so.3 the executables link (no serial OpenBLAS found)'}")


def _speeds_arg(text, default):
    """``--design-speeds`` as floats (m/s); a malformed list is the user's error (ConfigError)."""
    if text is None:
        return default
    try:
        return tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ConfigError(f"--design-speeds={text!r} must be comma-separated wind speeds in m/s, e.g. 15,19,23") from None


def _choose_backend() -> None:
    """The one place a backend is chosen: the commands only write figure files, so a process
    that has not chosen one (no MPLBACKEND, pyplot not yet imported) gets the non-interactive Agg."""
    if "matplotlib.pyplot" not in sys.modules and not os.environ.get("MPLBACKEND"):
        import matplotlib

        matplotlib.use("Agg")


def _one_line(e: BaseException) -> str:
    msg = " ".join(str(e).split("\n")).strip()
    name = getattr(e, "filename", None)  # an OSError raised by the system names its file here
    if name is not None and str(name) not in msg:
        msg = f"{name}: {msg}"
    return msg or type(e).__name__


def output_folder(folder: str | os.PathLike, key: str, *, source: str | os.PathLike | None = None) -> Path:
    """Create an output folder and check that a file can be written there, before minutes of work.

    Parameters
    ----------
    folder : str or os.PathLike
        The folder (created with its parents).
    key : str
        What named it (``--out``, ``output``), for the message.
    source : str or os.PathLike, optional
        The file that named it, for the message.

    Returns
    -------
    pathlib.Path
        The folder.

    Raises
    ------
    OSError
        The folder cannot be created or written (the same OSError subclass, naming the folder,
        the key and the file).
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        probe = folder / ".specdesign_write_test"
        probe.write_text("")
        probe.unlink()
    except OSError as e:
        where = f"{source}: {key}" if source is not None else key
        raise type(e)(f"{where}: the output folder {folder} cannot be created or written "
                      f"({e.strerror or e}); choose a writable folder") from None
    return folder


# One schema for campaign files: key → (check, what it must be). Every key of the file is
# checked, at every level, before the first simulation: a typo or a wrong type is an error
# naming the file and the key, not a traceback after minutes of simulation.
_TOP_KEYS = ("turbine", "wind_speeds", "seeds", "duration", "dt", "record_dt", "transient", "wohler_exponent",
             "turbulence_class", "controllers", "baseline", "designed", "promised", "output", "linear_twin", "volterra",
             "torque_control")
_CONTROLLER_KEYS = {"rosco": {"kind", "wind_speeds", "name"}, "file": {"kind", "file", "name"}}


class ConfigError(ValueError):
    """A campaign or controller file that does not follow the schema (``docs/validation.md``).

    The message names the file and the key, and says what the key must be; the command line
    prints it on one line and exits with code 2.
    """


def _is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _need(ok, path, key, what):
    if not ok:
        raise ConfigError(f"{path}: {key} must be {what}")


def _number(cfg, key, path, default, *, positive=True):
    v = cfg.get(key, default)
    _need(_number_ok(v, positive), path, key, "a positive number" if positive else "a number ≥ 0")
    return float(v)


def _number_ok(v, positive):
    return _is_number(v) and (v > 0 if positive else v >= 0)


def _coefficients(v, path, where):
    ok = isinstance(v, list) and len(v) > 0 and all(_is_number(x) for x in v)
    _need(ok, path, where, "a non-empty list of finite numbers (descending powers of s)")
    return np.asarray(v, float)


def load_controller(spec: dict, base: str | os.PathLike, model, *, config: str | os.PathLike | None = None,
                    name: str = "controller"):
    """A controller from a campaign-file entry (``docs/validation.md``: kind "rosco" or "file").

    Every key of the entry and of the controller file it names is checked.

    Parameters
    ----------
    spec : dict
        The entry: ``kind`` ("rosco" or "file", the default), ``wind_speeds`` (rosco, m/s),
        ``file`` (a controller JSON file, relative to ``base``), ``name`` (a label).
    base : str or os.PathLike
        Folder that relative controller-file paths start from.
    model : TurbineModel
        The turbine (ROSCO's gains, the range of wind speeds).
    config : str or os.PathLike, optional
        The campaign file, named in error messages (default ``base``).
    name : str, default "controller"
        The entry's name in the campaign file (``controllers.NAME``).

    Returns
    -------
    LTI or ScheduledController
        A transfer function (python-control), or a :class:`~specdesign.simulate.ScheduledController`
        (ROSCO, a schedule, or a pitch + ATD pair).

    Raises
    ------
    ConfigError
        An entry or controller file that does not follow the schema, naming the file and the key.
    FileNotFoundError
        A controller file that does not exist.
    OSError
        A controller file that cannot be read.
    """
    import control

    where = f"controllers.{name}"
    base = Path(base)
    src = config if config is not None else base
    if not isinstance(spec, dict):
        raise ConfigError(f"{src}: {where} must be a table with 'kind' = \"rosco\" or 'file' = \"<controller.json>\"")
    kind = spec.get("kind", "file")
    if not isinstance(kind, str) or kind not in _CONTROLLER_KEYS:
        raise ConfigError(f"{src}: {where}.kind={kind!r} must be \"rosco\" or \"file\"")
    extra = set(spec) - _CONTROLLER_KEYS[kind]
    if extra:
        raise ConfigError(f"{src}: unknown key(s) {sorted(extra)} in {where}; allowed for kind \"{kind}\": "
                          f"{sorted(_CONTROLLER_KEYS[kind])}")
    label = spec.get("name", name)
    _need(isinstance(label, str) and label, src, f"{where}.name", "a non-empty string (the controller's label)")
    if kind == "rosco":
        vs = spec.get("wind_speeds")
        if vs is not None:
            vs = _wind_speeds(vs, model, src, f"{where}.wind_speeds")
        try:
            return rosco_scheduled(model, vs, name=label)
        except ValueError as e:
            raise ConfigError(f"{src}: {where}.wind_speeds: {e}") from None
    _need(isinstance(spec.get("file"), str) and spec["file"], src, f"{where}.file", "the path of a controller JSON file")
    path = (base / spec["file"]).resolve()
    if not path.exists():
        raise FileNotFoundError(f"{src}: {where}.file: controller file {path} does not exist")
    if not path.is_file():
        raise ConfigError(f"{src}: {where}.file: {path} is not a file; give the path of a controller JSON file")
    try:
        text = path.read_bytes()
    except OSError as e:
        raise type(e)(f"{src}: {where}.file: cannot read {path} ({e.strerror or e})") from None
    data = _load_json(text, path, "a controller file")

    def tf(d, key):
        if isinstance(d, dict) and "elements" in d:
            try:
                num, den = Controller.from_dict(d).polys()
            except (TypeError, ValueError) as e:
                raise ConfigError(f"{path}: {key}: {e}") from None
        elif isinstance(d, dict) and set(d) == {"num", "den"}:
            num, den = _coefficients(d["num"], path, f"{key}.num"), _coefficients(d["den"], path, f"{key}.den")
            _need(den[0] != 0, path, f"{key}.den", "a list whose leading coefficient is non-zero")
        else:
            raise ConfigError(f"{path}: {key} must hold exactly 'num' and 'den' coefficient lists (descending powers "
                              f"of s) or a loopshaping Controller ('elements', from Controller.to_dict); got {d!r:.80}")
        _need(np.any(num != 0), path, key, "a non-zero controller (num is all zeros; leave an unused loop out)")
        _need(np.trim_zeros(num, "f").size <= den.size, path, key, "proper (no more zeros than poles)")
        return control.tf(num, den)

    def per_speed(items, key, n):
        _need(isinstance(items, list) and len(items) == n, path, key, f"a list of one controller per wind speed ({n})")
        return [tf(c, f"{key}[{i}]") for i, c in enumerate(items)]

    if not isinstance(data, dict):
        raise ConfigError(f"{path}: a controller file holds a JSON object, got {type(data).__name__}")
    keys = set(data)
    if keys & {"num", "den", "elements", "version"}:  # one controller
        return tf(data, "the file")
    if "wind_speeds" in keys:
        extra = keys - {"wind_speeds", "pitch", "atd"}
        if extra:
            raise ConfigError(f"{path}: unknown key(s) {sorted(extra)}; a scheduled controller has 'wind_speeds', "
                              "'pitch' and optionally 'atd'")
        vs = _wind_speeds(data["wind_speeds"], model, path, "wind_speeds")
        _need("pitch" in keys, path, "pitch", f"a list of one controller per wind speed ({len(vs)})")
        pitch = per_speed(data["pitch"], "pitch", len(vs))
        atd = None if data.get("atd") is None else per_speed(data["atd"], "atd", len(vs))
        try:
            return scheduled(model, dict(zip(vs, pitch)), None if atd is None else dict(zip(vs, atd)), name=label)
        except (TypeError, ValueError) as e:
            raise ConfigError(f"{path}: {e}") from None
    if "pitch" in keys:
        extra = keys - {"pitch", "atd"}
        if extra:
            raise ConfigError(f"{path}: unknown key(s) {sorted(extra)}; a pitch + ATD controller has 'pitch' and 'atd'")
        c = tf(data["pitch"], "pitch")
        if data.get("atd") is not None:
            return ScheduledController.fixed(c, tf(data["atd"], "atd"), name=label)
        return c
    raise ConfigError(f"{path}: unknown key(s) {sorted(keys)}; a controller file holds {{'num', 'den'}}, "
                      "{'elements'} (Controller.to_dict), {'pitch', 'atd'} or {'wind_speeds', 'pitch', 'atd'} "
                      "(docs/validation.md)")


def _wind_speeds(vs, model, path, key, operating=False) -> list:
    """Distinct wind speeds (m/s) inside the model's range, or ConfigError naming ``key``;
    ``operating``: the model's operating range (cut-in to cut-out) when it has a torque law
    (a campaign's speeds), else its design range (a controller's schedule)."""
    _need(isinstance(vs, list) and vs and all(_is_number(v) for v in vs), path, key,
          "a non-empty list of wind speeds in m/s")
    _need(len({float(v) for v in vs}) == len(vs), path, key, f"a list of distinct wind speeds, got {vs}")
    if operating and getattr(model, "torque_control", None) is not None:
        lo, hi = model.operating_range
        for v in vs:
            if not lo <= float(v) <= hi:
                raise ConfigError(f"{path}: {key}: wind_speed={v!r} m/s is outside the operating range {lo:g}-{hi:g} "
                                  "m/s (cut-in to cut-out)")
        return [float(v) for v in vs]
    for v in vs:
        try:
            model.check_wind_speed(v)
        except ValueError as e:
            raise ConfigError(f"{path}: {key}: {e}") from None
    return [float(v) for v in vs]


def _load_json(text: bytes, path: Path, what: str):
    """JSON with every object's keys distinct (a repeated key would silently keep the last)."""
    def repeated(k):
        return ConfigError(f"{path}: key {k!r} appears twice in one object; keep one")

    try:
        return json.loads(text, object_pairs_hook=distinct_keys(repeated))
    except (json.JSONDecodeError, UnicodeDecodeError) as e:
        raise ConfigError(f"{path}: {what} must be valid UTF-8 JSON ({e})") from None


def _read_config(path: Path) -> dict:
    try:
        text = path.read_bytes()
    except OSError as e:
        raise type(e)(f"{path}: cannot read the campaign file ({e.strerror or e})") from None
    if path.suffix.lower() == ".toml":
        try:
            return tomllib.loads(text.decode())
        except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
            raise ConfigError(f"{path}: invalid TOML ({e})") from None
    if path.suffix.lower() != ".json":
        raise ConfigError(f"{path}: a campaign file is a .toml or .json file (by its extension)")
    return _load_json(text, path, "a .json campaign file")


#: a run longer than a day (transient or recorded) is a typo, not a fatigue campaign
_MAX_DURATION = 86400.0
#: seeds are non-negative and below 2**32 (numpy's SeedSequence takes them as given)
_MAX_SEED = 2**32


def _checked_seeds(seeds, path) -> np.ndarray:
    """The campaign's seeds (:func:`seeds_from`: an int n → 0..n−1), each 0 ≤ s < 2**32."""
    items = seeds if isinstance(seeds, list) else [seeds]
    ok = all(isinstance(s, int) and not isinstance(s, bool) and 0 <= s < _MAX_SEED for s in items)
    _need(ok, path, "seeds", "an integer n ≥ 1 (the seeds 0..n−1) or a non-empty list of distinct integers "
          f"0 ≤ seed < 2**32, got {seeds!r:.80}")
    try:
        return seeds_from(seeds)
    except ValueError as e:
        raise ConfigError(f"{path}: {e}") from None


def read_config(path: str | os.PathLike, out: str | os.PathLike | None = None) -> dict:
    """Read and check a campaign file completely, before anything runs (schema: ``docs/validation.md``).

    Parameters
    ----------
    path : str or os.PathLike
        The campaign file (``.toml`` or ``.json``).
    out : str or os.PathLike, optional
        Output folder (the ``--out`` option); default the file's ``output`` key, else
        ``validation_output``, beside the file.

    Returns
    -------
    dict
        The arguments of the campaign: ``controllers`` (loaded), ``wind_speeds``, ``seeds``,
        ``kwargs`` for :func:`~specdesign.validate.run_campaign`, ``baseline``, ``designed``,
        ``promised`` and ``out`` (created and checked writable).

    Raises
    ------
    ConfigError
        A key or value that does not follow the schema (a ValueError), naming the file and the key.
    FileNotFoundError
        The file, or a controller file it names, does not exist.
    OSError
        A file that cannot be read or an output folder that cannot be written, naming it.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"config file {path} does not exist")
    if not path.is_file():
        raise ConfigError(f"{path}: not a file; give a .toml or .json campaign file")
    cfg = _read_config(path)
    if not isinstance(cfg, dict):
        raise ConfigError(f"{path}: a campaign file holds a table (TOML) or an object (JSON)")
    unknown = set(cfg) - set(_TOP_KEYS)
    if unknown:
        raise ConfigError(f"{path}: unknown key(s) {sorted(unknown)}; allowed: {sorted(_TOP_KEYS)}")
    for key in ("wind_speeds", "seeds", "controllers"):
        if key not in cfg:
            raise ConfigError(f"{path}: missing required key {key!r}")
    _need(cfg.get("turbine", "iea15mw") == "iea15mw", path, "turbine", "\"iea15mw\" (the only embedded model)")
    model = turbine.iea15mw()
    vs = _wind_speeds(cfg["wind_speeds"], model, path, "wind_speeds", operating=True)
    seeds = _checked_seeds(cfg["seeds"], path)
    kw = dict(duration=_number(cfg, "duration", path, RECORD_LENGTH), dt=_number(cfg, "dt", path, 0.02),
              record_dt=_number(cfg, "record_dt", path, 0.1), transient=_number(cfg, "transient", path, 60.0, positive=False),
              m=_number(cfg, "wohler_exponent", path, 4.0))
    for key in ("duration", "transient"):
        _need(kw[key] <= _MAX_DURATION, path, key, f"at most {_MAX_DURATION:g} s (one day) per run, got {kw[key]:g} s")
    rec = kw["record_dt"] / kw["dt"]
    _need(abs(rec - round(rec)) <= 1e-9 * rec and round(rec) >= 1, path, "record_dt", f"a whole multiple of dt={kw['dt']:g} s")
    _need(kw["duration"] >= 10 * kw["record_dt"], path, "duration",
          f"at least 10 output samples, ≥ {10 * kw['record_dt']:g} s at record_dt={kw['record_dt']:g} s")
    try:
        check_plant_step(model, vs, kw["dt"])
    except ValueError as e:
        raise ConfigError(f"{path}: {e}") from None
    tc = cfg.get("turbulence_class", "B")
    _need(tc in ("A", "B", "C"), path, "turbulence_class", "\"A\", \"B\" or \"C\" (IEC 61400-1 NTM)")
    twin = cfg.get("linear_twin", False)
    _need(isinstance(twin, bool), path, "linear_twin", "true or false (a TOML/JSON boolean, not a string)")
    vol = cfg.get("volterra", 0)
    _need(isinstance(vol, int) and not isinstance(vol, bool) and vol in (0, 1, 2, 3), path, "volterra",
          "0 (none) or an order 1, 2 or 3 (an integer)")
    torque = cfg.get("torque_control", "auto")
    _need(torque in ("auto", "rosco", "none"), path, "torque_control",
          "\"auto\" (ROSCO's torque law below rated, torque held above), \"rosco\" (the law in every run) or "
          "\"none\" (torque held)")
    ctrl = cfg["controllers"]
    _need(isinstance(ctrl, dict) and ctrl, path, "controllers", "a table of named controllers ([controllers.NAME])")
    controllers = {str(n): load_controller(spec, path.parent, model, config=path, name=str(n)) for n, spec in ctrl.items()}
    names = list(controllers)
    baseline, designed = cfg.get("baseline", names[0]), cfg.get("designed", names[-1])
    for key, val in (("baseline", baseline), ("designed", designed)):
        _need(isinstance(val, str) and val in controllers, path, key, f"one of the controllers {names}")
    _need(len(names) < 2 or baseline != designed, path, "designed",
          f"another controller than baseline={baseline!r} (Tables 2-3 compare the two)")
    try:  # the step each controller's sampled loop needs, as run_campaign checks it, but naming the file
        check_campaign_step(model, controllers, np.asarray(vs, float), kw["dt"])
    except ValueError as e:
        raise ConfigError(f"{path}: dt: {e}") from None
    promised = cfg.get("promised")
    if "promised" in cfg:  # a JSON null is not "no promise": leave the key out for that
        _need(isinstance(promised, dict), path, "promised", "a table wind speed (m/s) → promised DEL reduction (%)")
        out_p = {}
        for k, val in promised.items():
            try:
                v = float(k)
            except ValueError:
                raise ConfigError(f"{path}: promised: key {k!r} must be a wind speed in m/s") from None
            if isinstance(val, dict):  # TOML reads 19.5 = … as the dotted key 19 → 5
                raise ConfigError(f"{path}: promised.{k} must be a promised reduction in %, got a table; "
                                  f"quote a decimal wind speed in TOML: \"{k}.{next(iter(val), '5')}\" = …")
            _need(any(abs(v - w) < 1e-9 for w in vs), path, f"promised.{k}", f"at one of the wind_speeds {vs}")
            _need(_is_number(val) and val < 100, path, f"promised.{k}", "a promised reduction in % (a number < 100)")
            _need(v not in out_p, path, f"promised.{k}", f"given once (the wind speed {v:g} m/s appears twice)")
            out_p[v] = float(val)
        promised = out_p
    output = cfg.get("output", "validation_output")
    _need(isinstance(output, str) and output, path, "output", "a folder name")
    if out is not None:
        folder = output_folder(out, "--out", source=path)
    else:
        folder = output_folder(path.parent / output, "output", source=path)
    kw.update(turbulence_class=tc, linear_twin=twin, volterra=int(vol), model=model,
              torque_control=None if torque == "none" else torque)
    return dict(controllers=controllers, wind_speeds=vs, seeds=seeds, kwargs=kw, baseline=baseline,
                designed=designed, promised=promised, out=folder)


def run_config(path: str | os.PathLike, out: str | os.PathLike | None = None, *, echo: bool = False) -> Campaign:
    """Run the campaign described by a TOML/JSON file and write its tables and figures.

    The whole file is checked first (:func:`read_config`). Writes into the output folder:
    ``table2.md/.csv``, ``table3.md/.csv`` (with two or more controllers),
    ``indicators.csv``, ``fig8_<v>mps.png``, ``fig9_<v>mps.png`` and ``fig10.png`` (with the
    promise when the file gives one; :func:`specdesign.plots.validation.save_validation_figures`).

    Parameters
    ----------
    path : str or os.PathLike
        The campaign file (schema: ``docs/validation.md``).
    out : str or os.PathLike, optional
        Output folder; default the file's ``output`` key, else ``validation_output``, beside
        the file.
    echo : bool, default False
        Print what the campaign is, then Table 3 and Table 2 (with two or more controllers)
        and the path of every file written, to standard output (``specdesign validate`` does).

    Returns
    -------
    Campaign
        The campaign's results (:func:`~specdesign.validate.run_campaign`).

    Raises
    ------
    ConfigError
        See :func:`read_config`.
    OSError
        See :func:`read_config`; also an output file that cannot be written.
    """
    c = read_config(path, out)
    say = (lambda msg: print(msg, flush=True)) if echo else (lambda msg: None)
    kw = c["kwargs"]
    say(f"{path}: {len(c['controllers'])} controller(s) ({', '.join(c['controllers'])}) × "
        f"{len(c['wind_speeds'])} wind speed(s) × {len(c['seeds'])} seed(s) × {kw['duration']:g} s")
    camp = run_campaign(c["controllers"], c["wind_speeds"], c["seeds"], keep_series=1, **kw)
    folder, baseline, designed = c["out"], c["baseline"], c["designed"]
    written = [folder / "indicators.csv"]
    _write_indicators(camp, written[0])
    if len(camp.controllers) >= 2:
        t2, t3 = table2(camp, designed, baseline), table3(camp, designed, baseline, promised=c["promised"])
        # Table 3 first: the promise against what rainflow measured is the answer a campaign gives
        for t, stem in ((t3, "table3"), (t2, "table2")):
            (folder / f"{stem}.md").write_text(t.to_markdown())
            t.to_csv(folder / f"{stem}.csv")
            written += [folder / f"{stem}.md", folder / f"{stem}.csv"]
            say("\n" + t.to_markdown())
    else:
        say(f"one controller ({camp.controllers[0]}): no Tables 2-3 (they compare a design with a baseline); "
            "the indicators are in indicators.csv")
    acc = acceptance(camp, designed, baseline) if len(camp.controllers) >= 2 else None
    written += pv.save_validation_figures(camp, folder, acc, promised=c["promised"])
    say(f"\nwrote {len(written)} files to {folder}:")
    for f in written:
        say(f"  {f}")
    return camp


def _write_indicators(camp: Campaign, path: Path) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["controller", "wind_speed_m_s", "seed", "tower_del_Nm", "gen_speed_sd_rad_s", "mean_power_W",
                    "pitch_sd_rad", "pitch_rate_sd_rad_s", "blade_del_Nm", "pitch_travel_rad_per_h", "rate_limit_time"])
        for c, name in enumerate(camp.controllers):
            for i, v in enumerate(camp.wind_speeds):
                for s, seed in enumerate(camp.seeds):
                    w.writerow([name, v, int(seed)] + [repr(float(camp.values[k][c, i, s])) for k in INDICATORS])
