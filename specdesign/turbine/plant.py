"""The turbine as the compiled loop runs it: :class:`KernelPlant`, :func:`turbine_plant`, and
:func:`scheduled`, a :class:`~specdesign.controller.ScheduledController` built at the plant's trims.

The linear loop (:mod:`specdesign.closedloop`) and the simulator (:mod:`specdesign.simulate`)
both stand on these; :mod:`specdesign.simulate` re-exports them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..controller.lti import as_lti
from ..controller.scheduled import SCHEDULE_FILTER_OMEGA, ScheduledController
from .kernel import OUTPUT_NAMES, outputs, rhs
from .model import TurbineModel, iea15mw

__all__ = ["KernelPlant", "turbine_plant", "scheduled"]


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class KernelPlant:
    """A plant given by a compiled kernel pair, as :mod:`specdesign.turbine` defines it.

    Parameters
    ----------
    rhs : numba dispatcher
        ``@njit`` ``rhs(x, wind, pitch_cmd, gen_torque, p, dx)`` (SI units).
    outputs : numba dispatcher
        ``@njit`` ``outputs(x, wind, pitch_cmd, gen_torque, p, y)`` (SI units).
    params : numpy.ndarray
        Flat float64 parameter array ``p``.
    output_names : tuple of str
        Names of ``y`` in order; must contain ``gen_speed`` (rad/s), ``tower_top_vel`` (m/s)
        and ``pitch`` (rad).
    trim : callable
        ``trim(wind_speed) -> (x0, pitch0 rad, gen_torque N·m)``, the steady operating point.
    rated_speed : float
        Generator-speed reference Ω_rated (rad/s).
    linearize : callable, optional
        ``linearize(wind_speed) -> control.StateSpace`` with inputs (wind, pitch_cmd,
        gen_torque) and outputs ``output_names``, deviations from trim.
    name : str, optional
        Label of the plant.
    pitch_limits : tuple of float, optional
        (min, max) pitch command (rad): every controller's command is saturated there, with
        anti-windup (see :func:`simulate`).
    output_limits : dict, optional
        Output name → largest physically possible |y| (SI); a run whose output leaves it, or
        turns non-finite, has diverged and :func:`simulate` raises.
    torque_law : specdesign.rosco.TorqueLaw, optional
        The generator-torque controller below rated (``torque_control`` of :func:`simulate`);
        the plant then needs outputs ``power`` (W) and ``pitch`` (rad).
    rated_wind_speed : float, optional
        Wind speed (m/s) below which ``torque_control="auto"`` runs ``torque_law``.
    """

    rhs: object
    outputs: object
    params: np.ndarray = field(repr=False)
    output_names: tuple
    trim: object = field(repr=False)
    rated_speed: float
    linearize: object = field(default=None, repr=False)
    name: str = "plant"
    pitch_limits: tuple | None = None
    output_limits: dict = field(default_factory=dict)
    torque_law: object = None
    rated_wind_speed: float | None = None

    def index(self, name: str) -> int:
        """Position of output ``name`` in ``output_names``.

        Parameters
        ----------
        name : str
            An output name.

        Returns
        -------
        int
            Its index in ``y``.

        Raises
        ------
        ValueError
            If the plant has no such output.
        """
        if name not in self.output_names:
            raise ValueError(f"output {name!r} not among the plant outputs {self.output_names}")
        return self.output_names.index(name)


def turbine_plant(model: TurbineModel | KernelPlant | None = None) -> KernelPlant:
    """Wrap a :class:`specdesign.turbine.TurbineModel` as a KernelPlant.

    The plant's pitch limits are the model's; its output limits (divergence) twice the rated
    generator speed and the tower-base moment of 10 m of tower-top deflection.

    Parameters
    ----------
    model : TurbineModel or KernelPlant, optional
        The model (default :func:`specdesign.turbine.iea15mw`); a KernelPlant is returned as is.

    Returns
    -------
    KernelPlant
        The plant on the turbine's compiled kernel.

    Examples
    --------
    >>> turbine_plant().output_names[0]
    'gen_speed'
    """
    if model is None:
        model = iea15mw()
    if isinstance(model, KernelPlant):
        return model
    hit = _PLANTS.get(id(model))
    if hit is not None and hit[0] is model:
        return hit[1]
    trims = {}

    def trim(v):
        # a campaign asks for the same trims many times (checks, prediction, simulation): each
        # solved once per plant; the state returned as a copy, so no caller shares it
        v = float(v)
        if v not in trims:
            op = model.trim(v)
            trims[v] = (np.array(op.x, dtype=float), float(op.pitch), float(op.gen_torque))
        x, pitch, torque = trims[v]
        return x.copy(), pitch, torque

    plant = KernelPlant(
        rhs=rhs,
        outputs=outputs,
        params=np.ascontiguousarray(model.kernel_params(), dtype=float),
        output_names=tuple(OUTPUT_NAMES),
        trim=trim,
        rated_speed=float(model.rated_rotor_speed),
        linearize=model.linearize,
        name=model.name,
        pitch_limits=(float(model.pitch_min), float(model.pitch_max)),
        # divergence: twice the rated speed is far past any overspeed trip; a tower-base moment
        # of 10 m of tower-top deflection is far past the tower's strength
        output_limits={"gen_speed": 2.0 * float(model.rated_rotor_speed),
                       "tower_base_my": 10.0 * float(model.tower_base_moment_per_m)},
        torque_law=getattr(model, "torque_control", None),
        rated_wind_speed=None if getattr(model, "torque_control", None) is None else float(model.rated_wind_speed()),
    )
    if len(_PLANTS) >= _PLANTS_SIZE:
        try:  # another thread (a threaded dask worker) may have changed it meanwhile: drop any entry
            _PLANTS.pop(next(iter(_PLANTS)), None)
        except (RuntimeError, StopIteration):
            pass
    # the model is held with its plant, so its id cannot be reused while the entry lives
    _PLANTS[id(model)] = (model, plant)
    return plant


# id(model) → (model, plant): one plant per model (and its trims, and the loop checks keyed on
# it, :func:`specdesign.closedloop.loop_parts`) for the models in use, oldest dropped first
_PLANTS: dict = {}
_PLANTS_SIZE = 16


def scheduled(model: object, pitch: dict, atd: dict | None = None, *, filter_omega: float = SCHEDULE_FILTER_OMEGA,
              name: str = "designed") -> ScheduledController:
    """Build an output-blended ScheduledController from controllers designed per wind speed.

    Each controller is scheduled at the trim pitch of its wind speed.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The plant whose trim gives each wind speed's scheduling pitch.
    pitch : dict
        Wind speed (m/s) → pitch controller C_β (LTI or ``loopshaping`` Controller).
    atd : dict or None, optional
        Wind speed (m/s) → ATD controller, same keys, or None.
    filter_omega : float, optional
        Corner of the scheduling filter (rad/s).
    name : str, optional
        Label used in tables and figures.

    Returns
    -------
    ScheduledController
        The controller in ``form="output"``.

    Raises
    ------
    TypeError
        If ``pitch`` is not a non-empty dict.
    ValueError
        If ``atd`` has other wind speeds than ``pitch``, or a wind speed is outside the model's range.

    Examples
    --------
    >>> from specdesign.turbine import iea15mw, rosco_baseline
    >>> m = iea15mw()
    >>> sc = scheduled(m, {15.0: rosco_baseline(m, 15.0), 21.0: rosco_baseline(m, 21.0)})
    >>> sc.schedule_pitch.size
    2
    """
    if not isinstance(pitch, dict) or not pitch:
        raise TypeError("pitch must be a non-empty dict {wind_speed_m_s: controller}")
    if atd is not None and set(atd) != set(pitch):
        raise ValueError(f"atd must have the same wind speeds as pitch: {sorted(pitch)} vs {sorted(atd)}")
    plant = turbine_plant(model)
    vs = sorted(pitch)
    b = np.array([plant.trim(v)[1] for v in vs])
    order = np.argsort(b)
    vs = [vs[i] for i in order]
    return ScheduledController(
        schedule_pitch=b[order],
        pitch=tuple(as_lti(pitch[v], f"pitch[{v}]") for v in vs),
        atd=None if atd is None else tuple(as_lti(atd[v], f"atd[{v}]") for v in vs),
        filter_omega=filter_omega,
        name=name,
    )
