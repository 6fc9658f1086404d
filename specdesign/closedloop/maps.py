"""Closed-loop maps wind → output in the frequency domain, by the explicit formulas.

T_{y,w} for a pitch controller and an optional ATD loop (:func:`t_output_wind`), the plant
responses of several plant cases at once (:func:`plant_responses`), one loop closed on them
(:func:`close_responses`, sequential loop closure) and QFT's general form (A + B·G)/(C + D·G)
of any map (:func:`general_form`). ω in rad/s; complex numpy arrays on an explicit grid.
"""
from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._checks import as_omega, as_psd, positive_scalar
from ..spectral import del_spectral
from .interconnect import PLANT_INPUTS, require_signals

if TYPE_CHECKING:
    import control

    #: A plant: a named LTI, or its responses {(output, input): complex array on omega}.
    PlantLike = control.LTI | Mapping[tuple[str, str], np.ndarray]
    #: A SISO loop element: an LTI, a real gain, None (open), or its response on omega.
    ElementLike = control.LTI | float | ArrayLike | None

__all__ = ["frequency_response", "siso_response", "t_output_wind", "t_gen_speed_wind", "t_tower_wind", "output_psd",
           "closed_loop_del", "closed_map", "LoopMaps", "loop_maps", "plant_responses", "close_responses", "general_coefficients",
           "general_form", "LOOP_OUTPUTS", "state_space_response"]

#: The plant outputs the pitch and ATD loops measure or shape by default.
LOOP_OUTPUTS = ("gen_speed", "tower_base_my", "tower_top_vel", "pitch")


def frequency_response(sys: control.LTI, omega: ArrayLike, output: str, input: str = "wind") -> np.ndarray:
    """Complex frequency response of ``sys[output, input]`` at s = jω.

    Parameters
    ----------
    sys : control.LTI
        Named python-control LTI system (e.g. a plant or :func:`closed_loop`).
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    output : str
        Name of the output signal.
    input : str
        Name of the input signal (``wind``, m/s, by default).

    Returns
    -------
    numpy.ndarray
        Complex response on ``omega``, in units of the output per unit of the input (e.g.
        N·m per m/s for ``tower_base_my`` over ``wind``).

    Raises
    ------
    TypeError
        If ``sys`` is not a python-control LTI system, or ``omega`` is complex.
    ValueError
        If ``omega`` is not a valid grid or ``sys`` lacks the named signals.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import frequency_response
    >>> from specdesign.turbine import iea15mw
    >>> plant = iea15mw().linearize(19.0)
    >>> t = frequency_response(plant, [0.1, 1.0], "tower_base_my")   # N·m per m/s, open loop
    >>> t.shape, t.dtype
    ((2,), dtype('complex128'))
    """
    import control

    w = as_omega(omega, "omega")
    if not isinstance(sys, control.LTI):
        raise TypeError(f"sys must be a python-control LTI system, got {type(sys).__name__}")
    require_signals(sys, "sys", inputs=(input,), outputs=(output,))
    i = sys.input_labels.index(input)
    o = sys.output_labels.index(output)
    return np.asarray(sys(1j * w, squeeze=False))[o, i, :]


def _response(P, omega, output, input):
    """P is an LTI plant or a mapping {(output, input): complex array on omega}."""
    if isinstance(P, Mapping):
        try:
            r = np.asarray(P[(output, input)], dtype=complex)
        except KeyError:
            raise ValueError(f"P has no response for (output, input) = {(output, input)!r}; keys: {sorted(P)}") from None
        if r.shape != omega.shape:
            raise ValueError(f"P[{(output, input)!r}] has shape {r.shape}, expected {omega.shape} to match omega")
        return r
    return frequency_response(P, omega, output, input)


def siso_response(sys: ElementLike, omega: ArrayLike, name: str = "controller", *,
                  method: str = "python-control") -> np.ndarray:
    """Complex response at s = jω of one SISO element of a loop.

    Parameters
    ----------
    sys : control.LTI, float, array_like or None
        A SISO python-control LTI, a real scalar gain, None (an open loop: 0), or a complex
        array already evaluated on ``omega``.
    omega : array_like
        Frequencies, rad/s (not validated here: any shape).
    name : str
        Name of the element in error messages.
    method : {"python-control", "batched"}
        How a state-space ``sys`` is evaluated: python-control's (one frequency at a time), or
        :func:`state_space_response` (every frequency at once, ~20× faster on a 25-state map
        over 2000 points, equal to round-off). A transfer function is evaluated by its
        polynomials either way.

    Returns
    -------
    numpy.ndarray
        Complex response shaped like ``omega``, in the element's units (e.g. rad per rad/s for
        a pitch controller). An integrator at ω = 0 gives inf without a warning: callers
        such as :func:`t_output_wind` take the limit there.

    Raises
    ------
    ValueError
        If an LTI ``sys`` is not SISO, an array ``sys`` does not have the shape of ``omega``,
        or ``method`` is unknown.

    Examples
    --------
    >>> import control
    >>> from specdesign.closedloop import siso_response
    >>> siso_response(control.tf([1.0], [1.0, 1.0]), [0.0, 1.0])
    array([1. +0.j , 0.5-0.5j])
    >>> siso_response(None, [0.0, 1.0])
    array([0.+0.j, 0.+0.j])
    """
    import control

    if method not in ("python-control", "batched"):
        raise ValueError(f"method={method!r} must be 'python-control' or 'batched'")
    w = np.asarray(omega, dtype=float)
    if sys is None:
        return np.zeros(w.shape, complex)
    if isinstance(sys, (int, float)):
        return np.full(w.shape, complex(sys))
    if isinstance(sys, control.LTI):
        if sys.ninputs != 1 or sys.noutputs != 1:
            raise ValueError(f"{name} must be SISO, got {sys.noutputs}x{sys.ninputs}")
        with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
            warnings.simplefilter("ignore", RuntimeWarning)
            if isinstance(sys, control.TransferFunction):
                s = 1j * w
                return np.polyval(sys.num[0][0], s) / np.polyval(sys.den[0][0], s)
            if method == "batched" and isinstance(sys, control.StateSpace):
                y = state_space_response(sys.A, sys.B, sys.C, sys.D, w.ravel())
                return y[:, 0, 0].reshape(w.shape)
            return np.asarray(sys(1j * w, squeeze=False))[0, 0, :].reshape(w.shape)
    c = np.asarray(sys, dtype=complex)
    if c.shape != w.shape:
        raise ValueError(f"{name} as a frequency response must have shape {w.shape} to match omega, got {c.shape}")
    return c


def t_output_wind(P: PlantLike, C: ElementLike, omega: ArrayLike, output: str, atd_controller: ElementLike = None,
                  atd_measurement: str = "tower_top_vel") -> np.ndarray:
    """Closed-loop response wind → ``output`` at jω by the explicit formula.

    With β_cmd = −C·Ω_g − C_atd·z and Δ = 1 + C·P_{Ω,β} + C_atd·P_{z,β} (see
    :mod:`specdesign.closedloop`),

        T_{y,w} = [P_{y,w} + C(P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w}) + C_atd(P_{y,w}P_{z,β} − P_{y,β}P_{z,w})] / Δ.

    Where C is infinite (an integrator evaluated at ω = 0; |C| > 1e15 counts as infinite,
    since a state-space evaluation returns a huge finite number there) the limit C → ∞ is
    returned, (P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w})/P_{Ω,β}.

    Parameters
    ----------
    P : control.LTI or Mapping
        Named plant LTI (inputs ``wind`` m/s, ``pitch_cmd`` rad), or a mapping
        {(output, input): complex response on ``omega``} with the needed keys (e.g.
        :func:`plant_responses` of one plant).
    C : control.LTI, float, array_like or None
        Pitch controller C_β on generator speed (rad per rad/s), or its complex response on
        ``omega``; sign β = −C·Ω_g.
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    output : str
        Plant output y (e.g. ``gen_speed``, rad/s, or ``tower_base_my``, N·m).
    atd_controller : control.LTI, float, array_like or None
        ATD controller C_atd on ``atd_measurement`` (rad per measurement unit), or its
        response; None for no ATD.
    atd_measurement : str
        Plant output z the ATD controller measures (``tower_top_vel``, m/s, by default).

    Returns
    -------
    numpy.ndarray
        Complex T_{y,w} on ``omega``, output units per m/s.

    Raises
    ------
    TypeError
        If ``P`` is neither an LTI system nor a mapping.
    ValueError
        If ``omega`` is not a valid grid, ``P`` lacks a needed signal or response, or a
        controller is not SISO or has the wrong shape.

    Examples
    --------
    The formula agrees with :func:`closed_loop` (``control.interconnect``):

    >>> import numpy as np
    >>> from specdesign.closedloop import closed_loop, frequency_response, t_output_wind
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> plant, c = model.linearize(19.0), rosco_baseline(model, 19.0)
    >>> omega = np.array([0.1, 1.0])                                  # rad/s
    >>> t = t_output_wind(plant, c, omega, "tower_base_my")           # N·m per m/s
    >>> bool(np.allclose(t, frequency_response(closed_loop(plant, c), omega, "tower_base_my")))
    True
    """
    w = as_omega(omega, "omega")
    c = siso_response(C, w, "C")
    infinite = ~np.isfinite(c) | (np.abs(np.nan_to_num(c, nan=np.inf)) > 1e15)
    c = np.where(infinite, 0.0, c)
    signals = (output, "gen_speed") + ((atd_measurement,) if atd_controller is not None else ())
    R = {(o, i): _response(P, w, o, i) for o in signals for i in PLANT_INPUTS}
    k = None if atd_controller is None else siso_response(atd_controller, w, "atd_controller")
    out = closed_map(R, c, k, output, atd_measurement)
    if infinite.any():
        yw, yb = R[(output, "wind")], R[(output, "pitch_cmd")]
        ow, ob = R[("gen_speed", "wind")], R[("gen_speed", "pitch_cmd")]
        out[infinite] = ((yw * ob - yb * ow) / ob)[infinite]
    return out


def closed_map(R: Mapping, c, k, output: str, atd_measurement: str = "tower_top_vel") -> np.ndarray:
    """The closed-loop formula of :func:`t_output_wind` on responses already evaluated.

    T_{y,w} = [P_{y,w} + c(P_{y,w}P_{Ω,β} − P_{y,β}P_{Ω,w}) + k(P_{y,w}P_{z,β} − P_{y,β}P_{z,w})]
    / (1 + c·P_{Ω,β} + k·P_{z,β}), elementwise: the arrays may stack plant cases, e.g.
    (n_omega, n_cases) from :func:`plant_responses`, with c and k broadcasting against them.
    No checks and no limit at an infinite c: the fast path of design loops.

    Parameters
    ----------
    R : Mapping
        {(output, input): complex array} with input "wind" (per m/s) and "pitch_cmd" (per rad)
        for ``output``, "gen_speed" and, with ``k``, ``atd_measurement``.
    c : complex array_like
        Pitch-controller response C_β(jω) (rad per rad/s).
    k : complex array_like or None
        ATD-controller response C_atd(jω) (rad per unit of ``atd_measurement``), or None for
        no ATD loop.
    output : str
        The output y.
    atd_measurement : str
        The ATD loop's measurement z.

    Returns
    -------
    numpy.ndarray
        T_{y,w}(jω), complex, output units per m/s, broadcast shape of the inputs.
    """
    yw, yb = R[(output, "wind")], R[(output, "pitch_cmd")]
    ow, ob = R[("gen_speed", "wind")], R[("gen_speed", "pitch_cmd")]
    num = yw + c * (yw * ob - yb * ow)
    den = 1 + c * ob
    if k is not None:
        zw, zb = R[(atd_measurement, "wind")], R[(atd_measurement, "pitch_cmd")]
        num = num + k * (yw * zb - yb * zw)
        den = den + k * zb
    return num / den


def t_gen_speed_wind(P: PlantLike, C: ElementLike, omega: ArrayLike, **atd: Any) -> np.ndarray:
    """Eq. (4): T_{Ω,w} = P_{Ω,w}/(1 + C·P_{Ω,β}) at jω; see :func:`t_output_wind`.

    Parameters
    ----------
    P : control.LTI or Mapping
        Named plant LTI or its responses (as in :func:`t_output_wind`).
    C : control.LTI, float, array_like or None
        Pitch controller C_β (rad per rad/s) or its response on ``omega``.
    omega : array_like
        Frequencies, rad/s.
    **atd : dict, optional
        ``atd_controller`` and ``atd_measurement`` of :func:`t_output_wind`.

    Returns
    -------
    numpy.ndarray
        Complex T_{Ω,w} on ``omega``, (rad/s) per (m/s).
    """
    return t_output_wind(P, C, omega, "gen_speed", **atd)


def t_tower_wind(P: PlantLike, C: ElementLike, omega: ArrayLike, **atd: Any) -> np.ndarray:
    """Corrected Eq. (5): the tower-base moment's closed-loop map T_{MyT,w} at jω.

    T_{MyT,w} = [P_{MyT,w} + C(P_{MyT,w}P_{Ω,β} − P_{MyT,β}P_{Ω,w})]/(1 + C·P_{Ω,β}); see
    :func:`t_output_wind`.

    Parameters
    ----------
    P, C, omega, **atd
        As :func:`t_gen_speed_wind` and :func:`t_output_wind` take them: the named plant (or its
        responses), the pitch controller C_β (rad per rad/s, or its response), the frequencies
        (rad/s) and the ATD's ``atd_controller`` and ``atd_measurement``.

    Returns
    -------
    numpy.ndarray
        Complex T_{MyT,w} on ``omega``, N·m per m/s.
    """
    return t_output_wind(P, C, omega, "tower_base_my", **atd)


def output_psd(sys: control.LTI, omega: ArrayLike, wind_psd: ArrayLike, output: str, input: str = "wind") -> np.ndarray:
    """One-sided output PSD S_y = |T_{y,w}(jω)|²·S_W(ω).

    Parameters
    ----------
    sys : control.LTI
        Closed-loop (or open-loop) named LTI system.
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    wind_psd : array_like
        One-sided wind PSD S_W on ``omega``, (m/s)² per rad/s (e.g.
        :func:`specdesign.wind.rotor_effective_spectrum`).
    output : str
        Name of the output y.
    input : str
        Name of the disturbance input (``wind`` by default).

    Returns
    -------
    numpy.ndarray
        S_y on ``omega``, output units² per rad/s (one-sided).

    Raises
    ------
    TypeError
        If ``sys`` is not an LTI system, or ``omega`` or ``wind_psd`` is complex.
    ValueError
        If ``omega`` is not a valid grid, ``wind_psd`` does not match it or is negative or
        non-finite, or ``sys`` lacks the named signals.
    """
    w = as_omega(omega, "omega")
    s_w = as_psd(wind_psd, w.size, "wind_psd")
    return np.abs(frequency_response(sys, w, output, input)) ** 2 * s_w


def closed_loop_del(sys: control.LTI, omega: ArrayLike, wind_psd: ArrayLike, m: float, output: str = "tower_base_my",
                    method: str = "dirlik", input: str = "wind") -> float:
    """Damage-equivalent load at 1 Hz of ``output`` from its spectrum |T|²·S_W.

    S-N curve N(S) = (S_ref/S)^m with S the cycle range.

    Parameters
    ----------
    sys, omega, wind_psd, input
        The system, the grid (rad/s), the wind PSD ((m/s)² per rad/s) and the disturbance input,
        as :func:`output_psd` takes them.
    m : float
        Wöhler exponent (-), > 0.
    output : str
        Name of the output (``tower_base_my``, N·m, by default).
    method : str
        One of :func:`specdesign.spectral.damage_rate`'s methods ("dirlik", "narrowband",
        "tovo_benasciutti", ...).

    Returns
    -------
    float
        DEL at 1 Hz, a RANGE, in output units (N·m for ``tower_base_my``).

    Raises
    ------
    TypeError
        If ``sys`` is not an LTI system, or an array argument is complex.
    ValueError
        If ``m`` is not a positive finite number, ``omega`` or ``wind_psd`` is invalid,
        ``sys`` lacks the named signals, or ``method`` is unknown.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import closed_loop, closed_loop_del
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> from specdesign.wind import rotor_effective_spectrum
    >>> model = iea15mw()
    >>> cl = closed_loop(model.linearize(19.0), rosco_baseline(model, 19.0))
    >>> omega = np.logspace(-2, 1, 400)                                        # rad/s
    >>> s_w = rotor_effective_spectrum(omega, 19.0, model.rotor_radius)        # (m/s)² per rad/s
    >>> print(f"{closed_loop_del(cl, omega, s_w, 4.0) / 1e6:.1f} MN·m")
    32.2 MN·m
    """
    m = positive_scalar(m, "m")
    w = as_omega(omega, "omega")
    return float(del_spectral(w, output_psd(sys, w, wind_psd, output, input), m, method))


@dataclass(frozen=True)
class LoopMaps:
    """Open- and closed-loop wind maps on one grid (the paper's Fig. 1), complex arrays.

    Made by :func:`loop_maps`; plotted by :func:`specdesign.plots.turbine.plot_open_vs_baseline`.

    Parameters
    ----------
    omega : numpy.ndarray
        Frequency grid, rad/s.
    gen_open : numpy.ndarray
        Open-loop P_{Ω,w}(jω), (rad/s) per (m/s).
    gen_closed : numpy.ndarray
        Closed-loop T_{Ω,w}(jω), (rad/s) per (m/s).
    tower_open : numpy.ndarray
        Open-loop P_{MyT,w}(jω), N·m per m/s.
    tower_closed : numpy.ndarray
        Closed-loop T_{MyT,w}(jω), N·m per m/s.
    controller : numpy.ndarray
        Pitch controller C_β(jω), rad per rad/s.
    loop : numpy.ndarray
        Loop transfer L = C_β·P_{Ω,β} (-).
    """

    omega: np.ndarray
    gen_open: np.ndarray
    gen_closed: np.ndarray
    tower_open: np.ndarray
    tower_closed: np.ndarray
    controller: np.ndarray
    loop: np.ndarray


def loop_maps(plant: control.LTI, pitch_controller: ElementLike, omega: ArrayLike, atd_controller: ElementLike = None,
              atd_measurement: str = "tower_top_vel") -> LoopMaps:
    """Evaluate the open- and closed-loop wind maps of :class:`LoopMaps` on one grid.

    Parameters
    ----------
    plant : control.LTI
        Named plant with inputs ``wind`` (m/s), ``pitch_cmd`` (rad) and outputs ``gen_speed``
        (rad/s), ``tower_base_my`` (N·m) (and the ATD measurement with ATD).
    pitch_controller : control.LTI, float or array_like
        Pitch controller C_β (rad per rad/s), or its response on ``omega``.
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    atd_controller : control.LTI, float, array_like or None
        ATD controller C_atd on ``atd_measurement``; None for no ATD.
    atd_measurement : str
        Plant output the ATD controller measures (``tower_top_vel``, m/s, by default).

    Returns
    -------
    LoopMaps
        The open- and closed-loop maps, the controller's response and the loop transfer.

    Raises
    ------
    TypeError
        If ``plant`` is not an LTI system.
    ValueError
        If ``omega`` is not a valid grid, ``plant`` lacks a needed signal, or a controller is
        not SISO.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import loop_maps
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> maps = loop_maps(model.linearize(19.0), rosco_baseline(model, 19.0), np.logspace(-2, 1, 200))
    >>> maps.tower_closed.shape
    (200,)
    """
    w = as_omega(omega, "omega")
    c = siso_response(pitch_controller, w, "pitch_controller")
    atd = dict(atd_controller=atd_controller, atd_measurement=atd_measurement)
    return LoopMaps(
        omega=w,
        gen_open=frequency_response(plant, w, "gen_speed"),
        gen_closed=t_gen_speed_wind(plant, pitch_controller, w, **atd),
        tower_open=frequency_response(plant, w, "tower_base_my"),
        tower_closed=t_tower_wind(plant, pitch_controller, w, **atd),
        controller=c,
        loop=c * frequency_response(plant, w, "gen_speed", "pitch_cmd"),
    )


def plant_responses(plants: Sequence[control.LTI], omega: ArrayLike, outputs: Sequence[str] = LOOP_OUTPUTS, *,
                    method: str = "python-control") -> dict[tuple[str, str], np.ndarray]:
    """Frequency responses of several plant cases from both plant inputs to some outputs.

    Parameters
    ----------
    plants : sequence of control.LTI
        Named plants (the cases), each with inputs ``wind`` (m/s) and ``pitch_cmd`` (rad).
    omega : array_like
        Frequencies, rad/s: 1-D, increasing, non-negative.
    outputs : sequence of str
        Plant outputs to evaluate (default :data:`LOOP_OUTPUTS`).
    method : {"python-control", "batched"}
        ``"python-control"``: each channel by :func:`frequency_response` (python-control
        evaluates the whole plant once per frequency). ``"batched"``: one batched solve of
        (jωI − A)X = B per plant for the selected channels, ~100× faster on long grids, equal
        to round-off (the tests compare them); the fixed-structure QFT tuner keeps the first,
        whose round-off its documented designs were made with.

    Returns
    -------
    dict
        {(output, input): complex array (n_omega, n_cases)} for every output and both inputs
        of :data:`PLANT_INPUTS`, in output units per input unit.

    Raises
    ------
    TypeError
        If a plant is not an LTI system.
    ValueError
        If ``omega`` is not a valid grid or a plant lacks a named signal; an empty ``plants``
        also raises (numpy cannot stack nothing); an unknown ``method``.
    """
    if method == "batched":
        w = as_omega(omega, "omega")
        per_plant = [_batched(P, w, outputs) for P in plants]
        return {key: np.stack([r[key] for r in per_plant], axis=1) for key in per_plant[0]}
    if method != "python-control":
        raise ValueError(f"method={method!r} must be 'python-control' or 'batched'")
    return {
        (o, i): np.stack([frequency_response(P, omega, o, i) for P in plants], axis=1)
        for o in outputs for i in PLANT_INPUTS
    }


def _batched(P, w, outputs):
    import control

    if not isinstance(P, control.LTI):
        raise TypeError(f"each plant must be a python-control LTI system, got {type(P).__name__}")
    require_signals(P, "plant", inputs=PLANT_INPUTS, outputs=tuple(outputs))
    ss = control.ss(P)
    oi = [ss.output_labels.index(o) for o in outputs]
    ii = [ss.input_labels.index(i) for i in PLANT_INPUTS]
    y = state_space_response(np.asarray(ss.A), np.asarray(ss.B)[:, ii], np.asarray(ss.C)[oi],
                             np.asarray(ss.D)[np.ix_(oi, ii)], w)
    return {(o, i): y[:, k, j] for k, o in enumerate(outputs) for j, i in enumerate(PLANT_INPUTS)}


def state_space_response(a: ArrayLike, b: ArrayLike, c: ArrayLike, d: ArrayLike, omega: ArrayLike, *,
                         sample_time: float | None = None) -> np.ndarray:
    """C(sI − A)⁻¹B + D at every ω at once (python-control solves one frequency at a time), at
    s = jω, or at z = e^{jωT} for a discrete system of sample time T (``sample_time``).

    Modal when A's eigenvectors are well conditioned (C·V·diag(1/(s − λ))·V⁻¹·B), else one
    batched solve per frequency.

    Parameters
    ----------
    a, b, c, d : array_like
        (n, n), (n, m), (p, n), (p, m) state-space matrices (SI units of the system).
    omega : array_like
        (nw,) frequencies, rad/s.
    sample_time : float, optional
        T (s, > 0) of a discrete system; None (default): continuous.

    Returns
    -------
    numpy.ndarray
        (nw, p, m) complex frequency response.

    Examples
    --------
    >>> import numpy as np
    >>> y = state_space_response([[-1.0]], [[1.0]], [[1.0]], [[0.0]], [0.0, 1.0])
    >>> np.round(y[:, 0, 0], 3)     # 1/(jω + 1)
    array([1. +0.j , 0.5-0.5j])
    """
    a, b, c, d = (np.atleast_2d(np.asarray(x, float)) for x in (a, b, c, d))
    w = np.asarray(omega, float)
    if sample_time is not None and not (np.isfinite(sample_time) and sample_time > 0):
        raise ValueError(f"sample_time={sample_time!r} must be a sample time > 0 (s), or None for a continuous system")
    if a.size == 0:  # a static gain
        return np.broadcast_to(d, (w.size,) + d.shape).astype(complex)
    s = 1j * w if sample_time is None else np.exp(1j * w * sample_time)
    lam, v = np.linalg.eig(a)
    if np.linalg.cond(v) < 1e6:  # diagonalisable, well-conditioned
        cv, vb = c @ v, np.linalg.solve(v, b)
        return (cv[None, :, :] * (1.0 / (s[:, None] - lam[None, :]))[:, None, :]) @ vb + d
    x = np.linalg.solve(s[:, None, None] * np.eye(a.shape[0]) - a, np.broadcast_to(b, (w.size,) + b.shape))
    return c @ x + d


def close_responses(R: Mapping[tuple[str, str], np.ndarray], k: ArrayLike, measurement: str,
                    outputs: Sequence[str]) -> dict[tuple[str, str], np.ndarray]:
    """Close one loop, β_cmd = u − k·m, on frequency responses (sequential loop closure).

    With the loop on m closed, y_w = P_{y,w} − P_{y,β}·k·P_{m,w}/(1 + k·P_{m,β}) and
    y_u = P_{y,β}/(1 + k·P_{m,β}).

    Parameters
    ----------
    R : Mapping
        {(output, input): complex response} with the inputs ``wind`` and ``pitch_cmd`` for
        every output in ``outputs`` and for ``measurement`` (e.g. :func:`plant_responses`).
    k : array_like
        Complex response of the controller closed on ``measurement`` (rad per measurement
        unit), broadcastable to the responses (e.g. shape (n_omega, 1) for several cases).
    measurement : str
        The output m the closed controller reads.
    outputs : sequence of str
        Outputs to return.

    Returns
    -------
    dict
        {(output, "wind"): ..., (output, "pitch_cmd"): ...} complex responses with the loop
        closed; ``pitch_cmd`` is now the free input u (rad).

    Raises
    ------
    KeyError
        If ``R`` lacks a needed (output, input) response.
    """
    dk = 1 + k * R[(measurement, "pitch_cmd")]
    out = {}
    for y in outputs:
        yb = R[(y, "pitch_cmd")]
        out[(y, "wind")] = R[(y, "wind")] - yb * k * R[(measurement, "wind")] / dk
        out[(y, "pitch_cmd")] = yb / dk
    return out


def general_coefficients(R: Mapping[tuple[str, str], np.ndarray], output: str,
                         measurement: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """General-form coefficients A, B, C, D for y = ``output`` with the loop on ``measurement`` open.

    T_{y,w} = (A + B·G)/(C + D·G) for a controller G on ``measurement`` (β = −G·m) with
    A = P_{y,w}, B = P_{y,w}P_{m,β} − P_{y,β}P_{m,w} (0 when y = m), C = 1, D = P_{m,β}.

    Parameters
    ----------
    R : Mapping
        {(output, input): complex response} with the inputs ``wind`` and ``pitch_cmd`` for
        ``output`` and ``measurement``.
    output : str
        The output y.
    measurement : str
        The output m the controller G reads.

    Returns
    -------
    tuple of numpy.ndarray
        Complex A (output units per m/s), B (their product with D's units), C (ones, -) and
        D (measurement units per rad), shaped like the responses.

    Raises
    ------
    KeyError
        If ``R`` lacks a needed (output, input) response.
    """
    yw, yb = R[(output, "wind")], R[(output, "pitch_cmd")]
    nw, nb = R[(measurement, "wind")], R[(measurement, "pitch_cmd")]
    B = np.zeros_like(yw) if output == measurement else yw * nb - yb * nw
    return yw, B, np.ones_like(yw), nb


def general_form(plant: control.LTI | Sequence[control.LTI], omega: ArrayLike, output: str = "tower_base_my",
                 measurement: str = "gen_speed", closed_controller: ElementLike = None,
                 closed_measurement: str = "tower_top_vel") -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """QFT's general form: A, B, C, D of T_{output,w} = (A + B·G)/(C + D·G).

    G is a controller on ``measurement`` (β = −G·m), the one a QFT design shapes; any other
    controller is already closed (:func:`general_coefficients`, :func:`close_responses`).

    Parameters
    ----------
    plant : control.LTI or sequence of control.LTI
        Named plant (inputs ``wind`` m/s, ``pitch_cmd`` rad) or a non-empty list of them
        (plant cases).
    omega : array_like
        Frequencies, rad/s.
    output : str
        The output y (``tower_base_my``, N·m, by default).
    measurement : str
        The output G reads (``gen_speed``, rad/s, by default).
    closed_controller : control.LTI, float or None
        SISO controller already closed on ``closed_measurement`` (sequential closure,
        β_cmd = u − K·m), or None.
    closed_measurement : str
        The output ``closed_controller`` reads (``tower_top_vel``, m/s, by default).

    Returns
    -------
    tuple of numpy.ndarray
        Complex A, B, C, D of shape (n_omega,) for one plant or (n_omega, n_cases) for a list.
        Units: A in output units per m/s, D in measurement units per rad, B their product, C (-).

    Raises
    ------
    TypeError
        If ``plant`` is not an LTI system or a non-empty list of them.
    ValueError
        If ``omega`` is not a valid grid, a plant lacks a named signal, or
        ``closed_controller`` is not SISO.

    Examples
    --------
    With G = ROSCO's PI the general form gives back T_{MyT,w}:

    >>> import numpy as np
    >>> from specdesign.closedloop import general_form, siso_response, t_tower_wind
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> plant, c = model.linearize(19.0), rosco_baseline(model, 19.0)
    >>> omega = np.array([0.1, 1.0])
    >>> A, B, C, D = general_form(plant, omega)
    >>> g = siso_response(c, omega)
    >>> bool(np.allclose((A + B * g) / (C + D * g), t_tower_wind(plant, c, omega)))
    True
    """
    import control

    single = isinstance(plant, control.LTI)
    plants = [plant] if single else list(plant)
    if not plants or not all(isinstance(p, control.LTI) for p in plants):
        raise TypeError("plant must be a named python-control LTI system or a non-empty list of them")
    w = np.asarray(omega, float)
    outs = tuple(dict.fromkeys((output, measurement) + ((closed_measurement,) if closed_controller is not None else ())))
    R = plant_responses(plants, w, outs)
    if closed_controller is not None:
        R = close_responses(R, siso_response(closed_controller, w)[:, None], closed_measurement, outs)
    A, B, C, D = general_coefficients(R, output, measurement)
    if single:
        return A[:, 0], B[:, 0], C[:, 0], D[:, 0]
    return A, B, C, D
