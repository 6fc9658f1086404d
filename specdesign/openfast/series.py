"""OpenFAST outputs as workbench series: the channels the validation reads, stacked in SI.

The result feeds :func:`specdesign.validate.indicators` like a simulation's outputs.
"""
from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from .outputs import OpenFASTOutput

__all__ = ["OPENFAST_CHANNELS", "series_from_openfast"]

#: OpenFAST channel → workbench output name.
OPENFAST_CHANNELS = {"GenSpeed": "gen_speed", "TwrBsMyt": "tower_base_my", "BldPitch1": "pitch", "GenPwr": "power"}
#: SI unit each workbench series must arrive in (read_outputs converts rpm, deg, kN·m, kW, …)
_SERIES_UNITS = {"gen_speed": "rad/s", "tower_base_my": "N·m", "pitch": "rad", "power": "W", "tower_top_acc": "m/s^2"}


def series_from_openfast(outputs: OpenFASTOutput | Iterable[OpenFASTOutput],
                         channels: Mapping[str, str] = OPENFAST_CHANNELS) -> tuple[dict[str, np.ndarray], float]:
    """Stack OpenFAST outputs (from :func:`specdesign.openfast.read_outputs`) into workbench series.

    Parameters
    ----------
    outputs : OpenFASTOutput or iterable of OpenFASTOutput
        One or more files read by :func:`~specdesign.openfast.read_outputs`; all must share
        dt and length (cut them to a common length first if needed).
    channels : mapping, default OPENFAST_CHANNELS
        OpenFAST channel → workbench output name.

    Returns
    -------
    series : dict
        Output name → (n_files, n) array in SI (N·m, rad/s, rad, W).
    dt : float
        Sample spacing (s).

    Raises
    ------
    ValueError
        No outputs, files that differ in dt or length, a channel that was not read, or a
        channel whose unit does not convert to the SI unit its output needs (a unit the
        reader does not know is not guessed).

    Examples
    --------
    >>> from specdesign.openfast import read_outputs  # doctest: +SKIP
    >>> series, dt = series_from_openfast(read_outputs(["run1.outb"], list(OPENFAST_CHANNELS)))  # doctest: +SKIP
    """
    outs = [outputs] if isinstance(outputs, OpenFASTOutput) else list(outputs)
    if not outs:
        raise ValueError("outputs is empty; pass one or more OpenFASTOutput objects")
    dts = [o.dt for o in outs]
    lens = [o.time.size for o in outs]
    if max(dts) - min(dts) > 1e-9 * max(dts) or len(set(lens)) != 1:
        raise ValueError(f"outputs must share dt and length; got dt {sorted(set(dts))} s and lengths {sorted(set(lens))}")
    series = {}
    for ch, name in channels.items():
        for o in outs:
            if ch not in o.channels:
                raise ValueError(f"{o.path}: channel {ch!r} was not read; pass channels={list(channels)} to read_outputs")
            want = _SERIES_UNITS.get(name)
            if want is not None and o.units[ch] != want:
                raise ValueError(f"{o.path}: channel {ch!r} is in {o.original_units[ch]!r}, which does not convert to "
                                 f"{want} (the unit {name!r} needs); a unit the reader does not know is not guessed")
        series[name] = np.stack([o.channels[ch] for o in outs])
    return series, dts[0]
