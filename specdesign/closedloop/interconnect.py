"""Closed loops as systems: the pitch (and ATD) loops closed with ``control.interconnect``.

β_cmd = −C_β·Ω_g − C_atd·z (negative feedback; :mod:`specdesign.closedloop`). These build
state-space systems with named signals; :mod:`specdesign.closedloop.maps` evaluates the same
loops in the frequency domain by formula, and the tests check that the two agree.
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from loopshaping.freqresp import as_siso

from .stability import ClosedLoopUnstableWarning

if TYPE_CHECKING:
    import control

__all__ = ["named_siso", "require_signals", "closed_loop", "closed_loop_mimo", "partial_loop", "check_stability",
           "PLANT_INPUTS"]

#: The plant inputs a pitch loop acts through: rotor-effective wind (m/s) and pitch command (rad).
PLANT_INPUTS = ("wind", "pitch_cmd")


def named_siso(sys: control.LTI | float, name: str, inp: str, out: str) -> control.StateSpace:
    """Make a SISO system a named block for ``control.interconnect``.

    Parameters
    ----------
    sys : control.LTI or float
        SISO system, or a constant gain (units of ``out`` per unit of ``inp``).
    name : str
        Name of the block (also used in error messages).
    inp : str
        Name of its input signal.
    out : str
        Name of its output signal.

    Returns
    -------
    control.StateSpace
        ``sys`` as a state-space system named ``name`` with input ``inp`` and output ``out``.

    Raises
    ------
    TypeError
        If ``sys`` is neither a python-control LTI system nor a real number (the message names
        ``name``; :func:`loopshaping.freqresp.as_siso`).
    ValueError
        If ``sys`` is not SISO or is discrete-time (the message names ``name``).

    Examples
    --------
    >>> from specdesign.closedloop import named_siso
    >>> k = named_siso(0.5, "gain", "gen_speed", "u_pitch")
    >>> k.input_labels, k.output_labels
    (['gen_speed'], ['u_pitch'])
    """
    import control

    ss = control.ss(as_siso(sys, name, proper=False))
    return control.ss(ss.A, ss.B, ss.C, ss.D, inputs=[inp], outputs=[out], name=name)


def require_signals(sys: control.LTI, name: str, inputs: Sequence[str] = (), outputs: Sequence[str] = ()) -> None:
    """Check that a named LTI system has the given input and output signals.

    Parameters
    ----------
    sys : control.LTI
        System with named signals (``input_labels``, ``output_labels``).
    name : str
        Name of the argument ``sys`` in the error message.
    inputs : sequence of str
        Input names ``sys`` must have.
    outputs : sequence of str
        Output names ``sys`` must have.

    Raises
    ------
    ValueError
        If ``sys`` lacks any of the named ``inputs``/``outputs``; the message names ``name``
        and lists the signals ``sys`` has.
    """
    missing = [s for s in inputs if s not in sys.input_labels] + [s for s in outputs if s not in sys.output_labels]
    if missing:
        raise ValueError(
            f"{name} lacks the named signals {missing}; it has inputs {sys.input_labels} and outputs "
            f"{sys.output_labels} (build it with specdesign.turbine or name them with control's inputs=/outputs=)"
        )


def closed_loop(plant: control.LTI, pitch_controller: control.LTI | float, atd_controller: control.LTI | float | None = None,
                atd_measurement: str = "tower_top_vel", *, warn: bool = True) -> control.StateSpace:
    """Close the pitch (and optional ATD) loop around ``plant`` with ``control.interconnect``.

    The pitch command is β_cmd = −C_β·Ω_g − C_atd·z (negative feedback, z the
    ``atd_measurement``); :func:`specdesign.closedloop.t_output_wind` gives the same maps by
    formula.

    Parameters
    ----------
    plant : control.LTI
        Named plant with inputs ``wind`` (m/s) and ``pitch_cmd`` (rad) (others, e.g.
        ``gen_torque``, held at zero) and outputs including ``gen_speed`` (rad/s) and, with
        ATD, ``atd_measurement``; e.g. :meth:`specdesign.turbine.TurbineModel.linearize`.
    pitch_controller : control.LTI or float
        SISO pitch controller C_β, generator speed (rad/s) → pitch (rad).
    atd_controller : control.LTI or float, optional
        SISO tower-damping controller C_atd, ``atd_measurement`` → pitch (rad); None for no ATD.
    atd_measurement : str
        Plant output the ATD controller measures (``tower_top_vel``, m/s, by default).
    warn : bool
        Check the closed loop's poles and warn when it is unstable; False skips the check.

    Returns
    -------
    control.StateSpace
        Closed loop with input ``wind`` (m/s) and outputs all plant outputs plus ``pitch_cmd``
        (rad), in the plant's units.

    Raises
    ------
    TypeError
        If ``plant`` is not a python-control LTI system, or a controller is neither an LTI
        system nor a number.
    ValueError
        If ``plant`` lacks a needed signal, or a controller is not SISO.

    Warns
    -----
    ClosedLoopUnstableWarning
        When the closed loop has a pole with Re ≥ 0 (only with ``warn=True``).

    Examples
    --------
    ROSCO's PI on the IEA 15 MW linearised at 19 m/s:

    >>> from specdesign.closedloop import closed_loop
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> cl = closed_loop(model.linearize(19.0), rosco_baseline(model, 19.0))
    >>> cl.input_labels, cl.output_labels[-1], cl.nstates
    (['wind'], 'pitch_cmd', 8)
    """
    import control

    if not isinstance(plant, control.LTI):
        raise TypeError(f"plant must be a named python-control LTI system, got {type(plant).__name__}")
    needed = ["gen_speed"] + ([atd_measurement] if atd_controller is not None else [])
    require_signals(plant, "plant", inputs=("wind", "pitch_cmd"), outputs=needed)
    p = control.ss(plant)[list(plant.output_labels), ["wind", "pitch_cmd"]]
    p = control.ss(p.A, p.B, p.C, p.D, inputs=["wind", "pitch_cmd"], outputs=list(plant.output_labels), name="plant")
    systems = [p, named_siso(pitch_controller, "pitch_controller", "gen_speed", "u_pitch")]
    terms = ["-u_pitch"]
    if atd_controller is not None:
        systems.append(named_siso(atd_controller, "atd_controller", atd_measurement, "u_atd"))
        terms.append("-u_atd")
    systems.append(control.summing_junction(inputs=terms, output="pitch_cmd", name="pitch_sum"))
    outlist = list(plant.output_labels) + ["pitch_cmd"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=UserWarning)  # unused-signal notices for plant outputs
        sys = control.interconnect(systems, inplist=["wind"], outlist=outlist, inputs=["wind"], outputs=outlist, name="closed_loop")
    if warn:
        check_stability(sys, "closed loop")
    return sys


def check_stability(sys: control.LTI, name: str = "system", tol: float = 0.0) -> bool:
    """Check that every pole of ``sys`` has real part < −``tol``, warning otherwise.

    Parameters
    ----------
    sys : control.LTI
        Continuous-time system.
    name : str
        Name of the system in the warning.
    tol : float
        Stability margin, 1/s: poles must have Re < −tol.

    Returns
    -------
    bool
        True when every pole has Re < −tol (1/s), False otherwise.

    Warns
    -----
    ClosedLoopUnstableWarning
        When some pole has Re ≥ −tol: the message names ``name`` and lists the offending poles.

    Examples
    --------
    >>> import control
    >>> from specdesign.closedloop import check_stability
    >>> check_stability(control.tf([1.0], [1.0, 1.0]))
    True
    """
    poles = np.asarray(sys.poles())
    bad = poles[poles.real >= -tol]
    if bad.size:
        listing = ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in np.sort_complex(bad))
        warnings.warn(f"{name} is unstable: poles with Re ≥ {-tol:g} 1/s: {listing}", ClosedLoopUnstableWarning, stacklevel=2)
        return False
    return True


def closed_loop_mimo(plant: control.StateSpace, controller: control.LTI,
                     measurements: Sequence[str] = ("gen_speed",)) -> control.StateSpace:
    """Close ``u = K·y`` around the turbine with one MIMO controller K.

    Use this rather than splitting a 1×2 K into separate SISO pitch and ATD controllers:
    an H∞ controller may be unstable, and two separate realisations of its unstable modes
    leave a hidden unstable mode in the loop. Note the sign: the controller's output is the
    pitch command itself, pitch_cmd = K·y (positive feedback as written; a K designed for
    β = −C_β·Ω_g − C_atd·ẋ_top is K = −[C_β, C_atd]).

    Parameters
    ----------
    plant : control.StateSpace
        Named plant with inputs ``wind`` (m/s) and ``pitch_cmd`` (rad) (others held at zero)
        and the ``measurements`` among its outputs.
    controller : control.LTI
        K with one output, the pitch command (rad), and one input per measurement (in the
        measurement's units).
    measurements : sequence of str
        Plant outputs K reads, in the order of its inputs (``gen_speed`` in rad/s,
        ``tower_top_vel`` in m/s, ...).

    Returns
    -------
    control.StateSpace
        Closed loop with input ``wind`` (m/s) and outputs every plant output plus
        ``pitch_cmd`` (rad). Stability is not checked.

    Raises
    ------
    ValueError
        If K does not have 1 output and one input per measurement, or ``plant`` lacks the
        ``wind`` or ``pitch_cmd`` input.
    """
    import control

    measurements = tuple(measurements)
    K = control.ss(controller)
    if K.ninputs != len(measurements) or K.noutputs != 1:
        raise ValueError(
            f"controller must have 1 output (pitch_cmd) and {len(measurements)} inputs "
            f"{measurements}, got {K.noutputs}×{K.ninputs}"
        )
    i_w, i_u = plant.input_labels.index("wind"), plant.input_labels.index("pitch_cmd")
    outs = list(plant.output_labels)
    Pn = control.ss(plant.A, np.asarray(plant.B)[:, [i_w, i_u]], plant.C, np.asarray(plant.D)[:, [i_w, i_u]],
               inputs=["wind", "pitch_cmd"], outputs=outs, name="plant")
    Kn = control.ss(K.A, K.B, K.C, K.D, inputs=list(measurements), outputs=["pitch_cmd"], name="K")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return control.interconnect([Pn, Kn], inplist=["wind"], outlist=outs + ["pitch_cmd"],
                               inputs=["wind"], outputs=outs + ["pitch_cmd"], name="hinf_closed_loop")


def partial_loop(plant: control.LTI, controller: control.LTI | float,
                 measurement: str = "tower_top_vel") -> control.StateSpace:
    """Close one loop on the plant: β_cmd = u − controller·measurement.

    The result is the "plant" the other controller sees in sequential loop closure.

    Parameters
    ----------
    plant : control.LTI
        Named plant with inputs ``wind`` (m/s) and ``pitch_cmd`` (rad) and ``measurement``
        among its outputs.
    controller : control.LTI or float
        SISO controller, ``measurement`` → pitch (rad), negative feedback.
    measurement : str
        Plant output the controller reads (``tower_top_vel``, m/s, by default).

    Returns
    -------
    control.StateSpace
        Named system with inputs ``wind`` (m/s) and ``pitch_cmd`` (rad, now the free input u)
        and the plant's outputs.

    Raises
    ------
    TypeError
        If ``plant`` is not a python-control LTI system, or ``controller`` is neither an LTI
        system nor a number.
    ValueError
        If ``plant`` lacks a needed signal, or ``controller`` is not SISO.

    Examples
    --------
    The plant the pitch controller sees with a tower-velocity feedback of 0.01 rad per m/s:

    >>> from specdesign.closedloop import partial_loop
    >>> from specdesign.turbine import iea15mw
    >>> p = partial_loop(iea15mw().linearize(19.0), 0.01)
    >>> p.input_labels
    ['wind', 'pitch_cmd']
    """
    import control

    if not isinstance(plant, control.LTI):
        raise TypeError(f"plant must be a named python-control LTI system, got {type(plant).__name__}")
    require_signals(plant, "plant", inputs=PLANT_INPUTS, outputs=(measurement,))
    outs = list(plant.output_labels)
    p = control.ss(plant)[outs, list(PLANT_INPUTS)]
    p = control.ss(p.A, p.B, p.C, p.D, inputs=["wind", "beta"], outputs=outs, name="plant")
    k = named_siso(controller, "controller", measurement, "u_k")
    sj = control.summing_junction(inputs=["u_ext", "-u_k"], output="beta", name="sum")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", category=UserWarning)
        sys = control.interconnect([p, k, sj], inplist=["wind", "u_ext"], outlist=outs, inputs=list(PLANT_INPUTS), outputs=outs,
                              name="partial_loop")
    return sys
