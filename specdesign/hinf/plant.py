"""The generalized plant of the H∞ pitch design at one operating point (see :mod:`specdesign.hinf`).

Units: wind in m/s, pitch in rad, generator speed in rad/s, tower-base moment in N·m,
frequencies in rad/s; the performance outputs z are the outputs divided by their
specifications (dimensionless).
"""
from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import control as ct
import numpy as np

from ..closedloop import named_siso
from .weights import inverse_weight, siso_weight

if TYPE_CHECKING:
    from ..spec import Specification

__all__ = ['DEFAULT_NOISE', 'DEFAULT_INTEGRAL_CORNER', 'GeneralizedPlant', 'generalized_plant']

#: Default measurement-noise levels (units of the measurement: rad/s, m/s, m/s²).
#: 0.01 m/s on the tower-top velocity keeps the ATD gain moderate: with 1e-3 the 1×2 design
#: was 3 % better at full order but needed 11 states after balanced truncation instead of 8.
DEFAULT_NOISE = {"gen_speed": 1e-3, "tower_top_vel": 1e-2, "tower_top_acc": 1e-2}
#: ω_i (rad/s) of the integrator built into the plant for an α-shifted synthesis.
DEFAULT_INTEGRAL_CORNER = 0.1


@dataclass(frozen=True)
class GeneralizedPlant:
    """Generalized plant for :func:`loopshaping.hinf.synthesize`, made by :func:`generalized_plant`.

    Parameters
    ----------
    system : control.StateSpace
        Inputs ``['wind', 'noise_<meas>'..., 'pitch_cmd']`` (m/s, measurement units, rad; the
        last input is ``pitch_u`` with an ``input_filter``), outputs ``['z_tower', 'z_speed',
        'z_pitch', 'y_<meas>'...]`` (performance outputs, dimensionless, then the noisy
        measurements in their units).
    n_meas : int
        Number of measurements (the last outputs).
    n_ctrl : int
        Number of control inputs (the last inputs), 1.
    measurements : tuple of str
        Names of the measured plant outputs.
    inverse_weights : dict
        ``'tower'``, ``'speed'``, ``'pitch'`` → the LTI weights on the outputs: W_MyT⁻¹
        (m/s per N·m), W_Ω⁻¹ (m/s per rad/s) and the pitch weight (1/rad).
    notes : tuple of str
        What was modified in the weights (:func:`inverse_weight`) and the integrator note.
    input_filter : control.StateSpace or None
        F(s) = (1 + s/ω_i)/s when built with ``integral_corner`` (the control input is then
        ``pitch_u`` and the turbine's controller is F·K), else None.
    n_plant_states : int
        The first states of ``system`` are the turbine's (and F's), the rest are weights in
        series.
    """

    system: ct.StateSpace
    n_meas: int
    n_ctrl: int
    measurements: tuple[str, ...]
    inverse_weights: dict[str, ct.StateSpace]
    notes: tuple[str, ...]
    input_filter: ct.StateSpace | None = None
    n_plant_states: int = 0


def generalized_plant(
    plant: ct.StateSpace,
    w_tower: Specification | ct.LTI,
    w_speed: Specification | ct.LTI,
    w_pitch: ct.LTI | float | None = None,
    measurements: Sequence[str] = ("gen_speed",),
    *,
    noise: Mapping[str, float] | None = None,
    noise_band: tuple[float, float] = (1e-3, 1.0),
    rolloff: float = 10.0,
    shift: float = 1e-3,
    min_damping: float = 0.0,
    integral_corner: float | None = None,
) -> GeneralizedPlant:
    """The generalized plant at one operating point (see the module docstring).

    Parameters
    ----------
    plant : control.StateSpace
        Named linear turbine model (:meth:`specdesign.turbine.TurbineModel.linearize`) with
        inputs ``wind`` (m/s), ``pitch_cmd`` (rad) and outputs ``gen_speed`` (rad/s),
        ``tower_base_my`` (N·m) and the measurements. Other inputs are held at zero.
    w_tower, w_speed : Specification or SISO LTI
        Specifications W_MyT (N·m per m/s) and W_Ω (rad/s per m/s).
    w_pitch : SISO LTI or number, optional
        Pitch-activity weight (1/rad). Default 0.1·(1 + s/0.5)/(1 + s/20): pitch is cheap at
        low frequency and 40× dearer above the actuator bandwidth.
    measurements : tuple of str
        Measured outputs: ``("gen_speed",)`` for a pitch controller, ``("gen_speed",
        "tower_top_vel")`` for pitch + active tower damping (a 1×2 controller).
    noise : dict, optional
        Noise level per measurement in its units (default :data:`DEFAULT_NOISE`).
    noise_band : (float, float)
        The noise is high-pass, level·(s + a)/(s + b) with (a, b) = ``noise_band`` rad/s:
        with integral action a measurement offset at DC would pass to Ω_g and meet the
        speed weight's near-infinite low-frequency gain, so the noise is kept out of DC
        (a > 0 keeps its zero off the imaginary axis).
    rolloff : float
        Passed to :func:`inverse_weight`, rad/s.
    shift : float
        Passed to :func:`inverse_weight`, rad/s.
    min_damping : float
        Passed to :func:`inverse_weight`, damping ratio (-).
    integral_corner : float, optional
        Corner ω_i (rad/s): put F(s) = (1 + s/ω_i)/s in front of the pitch input, so the control
        input becomes ``pitch_u`` and the controller F·K has exact integral action (needed by
        an α-shifted synthesis, which would otherwise move the controller's integrator to −α).
        The pitch weight stays on ``pitch_cmd``.

    Returns
    -------
    GeneralizedPlant
        The interconnection and what :func:`loopshaping.hinf.synthesize` needs to know.

    Raises
    ------
    TypeError
        If ``plant`` is not a ``control.StateSpace``, or a weight is not an LTI system or a
        number.
    ValueError
        If ``measurements`` is empty or has duplicates; the plant lacks ``wind``,
        ``pitch_cmd``, ``gen_speed``, ``tower_base_my`` or a measurement; a measurement has
        no positive noise level; ``noise_band`` is not 0 < a < b; ``integral_corner`` is not
        a positive frequency; or a specification cannot be inverted (:func:`inverse_weight`).

    Examples
    --------
    A first-order stand-in for the turbine (use :meth:`specdesign.turbine.TurbineModel.linearize`):

    >>> import control as ct
    >>> from specdesign.hinf import generalized_plant
    >>> P = ct.ss([[-1.0]], [[1.0, -2.0]], [[1.0], [1e6]], [[0.0, 0.0], [0.0, 0.0]],
    ...           inputs=["wind", "pitch_cmd"], outputs=["gen_speed", "tower_base_my"])
    >>> gp = generalized_plant(P, ct.tf(1e6, [1, 1]), ct.tf(1, [1, 1]))
    >>> gp.system.input_labels
    ['wind', 'noise_gen_speed', 'pitch_cmd']
    >>> gp.system.output_labels
    ['z_tower', 'z_speed', 'z_pitch', 'y_gen_speed']
    >>> gp.n_meas, gp.n_ctrl, gp.n_plant_states
    (1, 1, 1)
    """
    if not isinstance(plant, ct.StateSpace):
        raise TypeError(f"plant must be a named control.StateSpace, got {type(plant).__name__}")
    measurements = tuple(measurements)
    if not measurements:
        raise ValueError("measurements must name at least one plant output, e.g. ('gen_speed',)")
    need_out = {"gen_speed", "tower_base_my", *measurements}
    missing = [s for s in ("wind", "pitch_cmd") if s not in plant.input_labels]
    missing += sorted(s for s in need_out if s not in plant.output_labels)
    if missing:
        raise ValueError(
            f"plant lacks the named signals {missing}; it has inputs {plant.input_labels} and "
            f"outputs {plant.output_labels}"
        )
    if len(set(measurements)) != len(measurements):
        raise ValueError(f"measurements={measurements} has duplicates")
    noise = dict(DEFAULT_NOISE if noise is None else noise)
    for mname in measurements:
        level = noise.get(mname)
        if level is None or not (np.isfinite(level) and level > 0):
            raise ValueError(
                f"noise[{mname!r}]={level!r}: give a positive noise level (units of {mname}) for "
                "every measurement; a noise-free measurement makes the H∞ problem ill posed"
            )
    a, b = noise_band
    if not (0 < a < b):
        raise ValueError(f"noise_band={noise_band!r} must be (a, b) rad/s with 0 < a < b")
    kw = dict(rolloff=rolloff, shift=shift, min_damping=min_damping)
    wt_inv, n1 = inverse_weight(w_tower, name="w_tower", **kw)
    ws_inv, n2 = inverse_weight(w_speed, name="w_speed", **kw)
    if w_pitch is None:
        w_pitch = 0.1 * ct.tf([1 / 0.5, 1], [1 / 20.0, 1])
    elif isinstance(w_pitch, (int, float)):
        w_pitch = ct.tf([float(w_pitch)], [1])
    wp = siso_weight(w_pitch, "w_pitch")

    i_w, i_u = plant.input_labels.index("wind"), plant.input_labels.index("pitch_cmd")
    Pn = ct.ss(
        plant.A, np.asarray(plant.B)[:, [i_w, i_u]], plant.C, np.asarray(plant.D)[:, [i_w, i_u]],
        inputs=["wind", "pitch_cmd"], outputs=list(plant.output_labels), name="plant",
    )
    input_filter, control = None, "pitch_cmd"
    if integral_corner is not None:
        if not (np.isfinite(integral_corner) and integral_corner > 0):
            raise ValueError(f"integral_corner={integral_corner!r} must be a positive frequency in rad/s")
        # pitch_cmd = F(s)·u with F = (1 + s/ω_i)/s: the integrator is part of the plant (and of
        # its states, so an α-shift moves it and the controller keeps exact integral action).
        f = ct.ss(ct.tf([1.0 / integral_corner, 1.0], [1.0, 0.0]))
        input_filter = ct.ss(f.A, f.B, f.C, f.D, inputs=["pitch_u"], outputs=["pitch_cmd"], name="F_int")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            Pn = ct.interconnect([Pn, input_filter], inplist=["wind", "pitch_u"], outlist=list(plant.output_labels) + ["pitch_cmd"],
                                 inputs=["wind", "pitch_u"], outputs=list(plant.output_labels) + ["pitch_cmd"], name="plant")
        Pn = ct.ss(Pn.A, Pn.B, Pn.C, Pn.D, inputs=["wind", "pitch_u"],
                   outputs=list(plant.output_labels) + ["pitch_cmd"], name="plant")
        control = "pitch_u"
    systems = [
        Pn,
        named_siso(wt_inv, "W_tower_inv", "tower_base_my", "z_tower"),
        named_siso(ws_inv, "W_speed_inv", "gen_speed", "z_speed"),
        named_siso(wp, "W_pitch", "pitch_cmd", "z_pitch"),
    ]
    for mname in measurements:
        nf = noise[mname] * ct.tf([1, a], [1, b])
        systems.append(named_siso(nf, f"N_{mname}", f"noise_{mname}", f"n_{mname}"))
        systems.append(ct.summing_junction(inputs=[mname, f"n_{mname}"], output=f"y_{mname}",
                                           name=f"sum_{mname}"))
    inputs = ["wind"] + [f"noise_{x}" for x in measurements] + [control]
    outputs = ["z_tower", "z_speed", "z_pitch"] + [f"y_{x}" for x in measurements]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # unused plant outputs
        sys = ct.interconnect(systems, inplist=inputs, outlist=outputs, inputs=inputs,
                              outputs=outputs, name="generalized_plant")
    return GeneralizedPlant(
        system=ct.ss(sys), n_meas=len(measurements), n_ctrl=1, measurements=measurements,
        inverse_weights={"tower": wt_inv, "speed": ws_inv, "pitch": ct.ss(wp)},
        notes=n1 + n2 + (() if input_filter is None else (
            f"integrator (1 + s/{integral_corner:g})/s built into the plant: the controller is F·K",)),
        input_filter=input_filter, n_plant_states=Pn.nstates,
    )
