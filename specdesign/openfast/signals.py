"""Workbench signals from an OpenFAST linearisation: channel descriptions → named plant.

:func:`plant_from_linearization` turns a :class:`~specdesign.openfast.lin.LinearizationData`
into a ``control.StateSpace`` whose inputs and outputs carry the workbench's names
(``wind``, ``pitch_cmd``, ``gen_speed``, ``tower_base_my``, ...), selected by OpenFAST
channel description with :data:`DEFAULT_SIGNALS`, which a user overrides or extends.

Matching: an entry is a description, a substring of one (case-insensitive; an exact
description always wins), or a tuple of such alternatives tried in order (the first that
matches is used). ``"d/dt <channel>"`` is the time derivative of an output channel,
d/dt(C x + D u) = C A x + C B u, exact when that channel has no feedthrough (D = 0).

States: the generator-azimuth position (``DOF_GeAz``, not its time derivative) is removed:
the azimuth-averaged model does not depend on the rotor azimuth, and what a file's A keeps
of it is the residue of the azimuths averaged (ROSCO's linear-model tools remove it too).
Then every state that nothing reads (zero column of A and of the selected C) is removed,
repeatedly: exact for the selected signals (e.g. wave-excitation states of HydroDyn whose
wave input is not selected).
"""
from __future__ import annotations

import numpy as np

from .lin import signal_label

__all__ = ["DEFAULT_SIGNALS", "REQUIRED_SIGNALS", "INPUT_SIGNALS", "AZIMUTH_STATE", "resolve_signals",
           "plant_from_linearization"]

#: Workbench signal → OpenFAST description (substring) or alternatives, tried in order.
#: Inputs: ``wind`` the InflowWind horizontal (hub-height, uniform) wind speed, the
#: rotor-effective wind of the workbench (OpenFAST v5 files also list AeroDyn's own copy of
#: it, "AD Extended input: horizontal wind speed", which InflowWind's drives: InflowWind's
#: is taken first); ``pitch_cmd`` ElastoDyn's collective blade-pitch
#: command; ``gen_torque`` ElastoDyn's generator torque. Outputs: ``gen_speed`` (GenSpeed),
#: ``tower_base_my`` (TwrBsMyt, the tower-base fore-aft moment), ``tower_top_acc`` (the
#: nacelle IMU fore-aft acceleration NcIMUTAxs, else YawBrTAxp), ``tower_top_vel`` (the time
#: derivative of the tower-top fore-aft deflection YawBrTDxt, else TTDspFA: relative to the
#: tower base, so on a floating turbine without the platform's motion), ``pitch``
#: (BldPitch1), ``power`` (GenPwr) and ``blade_root_my`` (the collective, MBC part of the
#: blades' out-of-plane root moments RootMyc1-3: their mean, as a controller reads it from
#: avrSWAP(30-32); ``linearize_deck(..., blade_moments=True)`` asks OpenFAST for all three).
DEFAULT_SIGNALS = {
    "wind": ("IfW Extended input: horizontal wind speed", "horizontal wind speed"),
    "pitch_cmd": ("collective blade-pitch command",),
    "gen_torque": ("ED Generator torque",),
    "gen_speed": ("GenSpeed",),
    "tower_base_my": ("TwrBsMyt",),
    "tower_top_acc": ("NcIMUTAxs", "YawBrTAxp"),
    "tower_top_vel": ("d/dt YawBrTDxt", "d/dt TTDspFA"),
    "pitch": ("BldPitch1",),
    "power": ("GenPwr",),
    "blade_root_my": ("RootMyc[coll]",),
}
#: Signals the design loop cannot do without: a default mapping that misses one is an error.
#: (``tower_top_vel`` is the ATD measurement that the closed-loop analysis of
#: :mod:`specdesign.closedloop` reads.) The other defaults are left out when absent.
REQUIRED_SIGNALS = ("wind", "pitch_cmd", "gen_speed", "tower_base_my", "tower_top_vel")
#: Names that are plant inputs; every other name is an output.
INPUT_SIGNALS = ("wind", "pitch_cmd", "gen_torque")
#: Description of the generator-azimuth state that is removed (see the module docstring).
AZIMUTH_STATE = "DOF_GeAz"

_DERIVATIVE = "d/dt "


def _alternatives(name, value):
    alts = (value,) if isinstance(value, str) else tuple(value)
    if not alts or not all(isinstance(a, str) and a.strip() for a in alts):
        raise TypeError(f"signals[{name!r}]={value!r} must be a description substring or a tuple of them")
    return alts


def _match(desc, text):
    exact = [i for i, d in enumerate(desc) if d == text]
    return exact or [i for i, d in enumerate(desc) if text.lower() in d.lower()]


def resolve_signals(data, signals=None) -> dict:
    """Which input/output of ``data`` each workbench signal is.

    Parameters
    ----------
    data : LinearizationData
        An averaged linearisation (:func:`specdesign.openfast.read_linearization`).
    signals : dict, optional
        Overrides and additions to :data:`DEFAULT_SIGNALS`: name → description substring,
        a tuple of alternatives, or None to leave a default signal out. A name given here is
        required to match.

    Returns
    -------
    dict
        name → (kind, index, derivative): kind ``"input"`` or ``"output"``, the index in
        ``data.u_desc`` / ``data.y_desc``, and True for a ``"d/dt"`` output. Inputs first.

    Raises
    ------
    ValueError
        A required signal matches no description (the message names the signal, what was
        tried and lists the file's descriptions), or one alternative matches several.
    TypeError
        An entry of ``signals`` that is not a string, a tuple of strings or None.
    """
    if signals is not None and not isinstance(signals, dict):
        raise TypeError(f"signals must be a dict {{name: description}}, got {type(signals).__name__}")
    user = dict(signals or {})
    table = {**DEFAULT_SIGNALS, **user}
    for name in REQUIRED_SIGNALS:
        if table.get(name) is None:
            raise ValueError(f"signals[{name!r}] cannot be None: the design loop needs {name!r}; give its OpenFAST description")
    out = {}
    for name, value in table.items():
        if value is None:
            continue
        kind = "input" if name in INPUT_SIGNALS else "output"
        desc = data.u_desc if kind == "input" else data.y_desc
        found = None
        for alt in _alternatives(name, value):
            deriv = kind == "output" and alt.startswith(_DERIVATIVE)
            hits = _match(desc, alt[len(_DERIVATIVE):].strip() if deriv else alt)
            if len(hits) > 1:
                raise ValueError(f"signal {name!r}: {alt!r} matches several {kind}s {[desc[i] for i in hits]}; "
                                 "give a longer description in signals=")
            if hits:
                found = (kind, hits[0], deriv)
                break
        if found is None:
            if name in user or name in REQUIRED_SIGNALS:
                listing = "; ".join(desc)
                raise ValueError(f"signal {name!r}: no OpenFAST {kind} matches {_alternatives(name, value)} in "
                                 f"{', '.join(data.paths) or 'the linearisation'}; its {kind}s are: {listing}. "
                                 f"Map {name!r} to one of them with signals={{{name!r}: '<description>'}}")
            continue
        out[name] = found
    return dict(sorted(out.items(), key=lambda kv: kv[1][0] != "input"))


def _reduced_states(A, C, x_desc):
    keep = [i for i, d in enumerate(x_desc) if not (AZIMUTH_STATE in d and not d.startswith("ED First time derivative"))]
    while True:
        Ak, Ck = A[np.ix_(keep, keep)], C[:, keep]
        unread = [j for j in range(len(keep)) if not np.any(Ak[:, j]) and not np.any(Ck[:, j])]
        if not unread:
            return keep
        keep = [k for j, k in enumerate(keep) if j not in unread]


def plant_from_linearization(data, signals=None):
    """The named workbench plant of one averaged OpenFAST linearisation.

    Parameters
    ----------
    data : LinearizationData
        An averaged linearisation in SI (:func:`specdesign.openfast.read_linearization`).
    signals : dict, optional
        Overrides of :data:`DEFAULT_SIGNALS` (:func:`resolve_signals`).

    Returns
    -------
    plant : control.StateSpace
        Inputs and outputs named as the workbench names them (inputs in the order
        wind, pitch_cmd[, gen_torque], then outputs in the mapping's order), deviations from
        the operating point, SI; states named by their OpenFAST descriptions, the azimuth
        and the unread states removed (module docstring).
    used : dict
        name → the OpenFAST description it was read from (``"d/dt ..."`` for derivatives).

    Raises
    ------
    ValueError
        As :func:`resolve_signals`, or a ``"d/dt"`` channel with a feedthrough (D ≠ 0).

    Examples
    --------
    >>> from importlib import resources
    >>> from specdesign.openfast import read_linearization
    >>> lin = read_linearization(resources.files("specdesign") / "data/iea15mw/sample_floating_19mps.1.lin")
    >>> plant, used = plant_from_linearization(lin)
    >>> plant.input_labels[:2], used["tower_base_my"]
    (['wind', 'pitch_cmd'], 'ED TwrBsMyt, (N-m)')
    """
    import control

    sel = resolve_signals(data, signals)
    ins = sorted((n for n, s in sel.items() if s[0] == "input"), key=lambda n: (INPUT_SIGNALS.index(n)))
    outs = [n for n, s in sel.items() if s[0] == "output"]
    iu = [sel[n][1] for n in ins]
    B, Du = data.B[:, iu], data.D[:, iu]
    rows_c, rows_d, used = [], [], {}
    for n in outs:
        _, i, deriv = sel[n]
        if deriv:
            if np.any(data.D[i]):
                raise ValueError(f"signal {n!r}: d/dt of {data.y_desc[i]!r} needs a channel without feedthrough (its D row "
                                 "is not zero); map it to another channel")
            rows_c.append(data.C[i] @ data.A)
            rows_d.append(data.C[i] @ B)
            used[n] = _DERIVATIVE + data.y_desc[i]
        else:
            rows_c.append(data.C[i])
            rows_d.append(Du[i])
            used[n] = data.y_desc[i]
    for n in ins:
        used[n] = data.u_desc[sel[n][1]]
    C, D = np.array(rows_c).reshape(len(outs), -1), np.array(rows_d).reshape(len(outs), len(ins))
    keep = _reduced_states(data.A, C, data.x_desc)
    states = [signal_label(data.x_desc[k]) for k in keep]
    plant = control.ss(data.A[np.ix_(keep, keep)], B[keep], C[:, keep], D, inputs=ins, outputs=outs, states=states)
    return plant, {n: used[n] for n in ins + outs}
