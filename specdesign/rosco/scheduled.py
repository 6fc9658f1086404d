"""ROSCO's pitch controller as the simulator runs it: :func:`rosco_scheduled`.

The baseline PI of :func:`specdesign.rosco.rosco_baseline` scheduled on the filtered pitch,
from the model's gain schedule (:func:`specdesign.rosco.rosco_gain_schedule`) or from a
DISCON.IN (:func:`specdesign.rosco.from_discon`; the IEA 15 MW's ships with the package,
:func:`iea15mw_discon`), as a :class:`specdesign.simulate.ScheduledController`.
"""
from __future__ import annotations

import dataclasses
import math
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .._checks import positive_scalar
from ..controller.discon_file import DisconSchedule
from ..controller.peak_shaving import peak_shaving_from_discon
from ..controller.scheduled import FORMS, SCHEDULE_FILTER_OMEGA, ScheduledController
from ..turbine import TurbineModel, iea15mw
from ..turbine.baseline import (
    RoscoSchedule,
    rosco_baseline,
    rosco_gain_schedule,
    speed_filter,
)
from ..turbine.plant import scheduled, turbine_plant
from ..turbine.tables import DATA_DIR

if TYPE_CHECKING:
    import control

__all__ = ["SCHEDULING_FILTERS", "ROSCO_SCHEDULE_CORNER", "ROSCO_SCHEDULE_DAMPING", "TOWER_DAMPER_DAMPING_RATIO",
           "TOWER_DAMPER_HPF_CORNER", "TOWER_DAMPER_INT_SAT", "TowerDamper", "iea15mw_discon", "rosco_scheduled",
           "tower_mode_damping", "tune_tower_damper"]


def iea15mw_discon() -> Path:
    """Path of the shipped DISCON.IN of the IEA 15 MW monopile (ROSCO 2.9.4 tuning).

    Its ``PerfFileName`` points outside the package: it reads as a schedule
    (:func:`from_discon`) but the compiled ROSCO cannot run it as it is.

    Returns
    -------
    pathlib.Path
        ``specdesign/data/iea15mw/IEA-15-240-RWT-Monopile_DISCON.IN``.

    Examples
    --------
    >>> iea15mw_discon().name
    'IEA-15-240-RWT-Monopile_DISCON.IN'
    """
    return Path(str(resources.files("specdesign").joinpath(f"{DATA_DIR}/IEA-15-240-RWT-Monopile_DISCON.IN")))


#: Scheduling filters of :func:`rosco_scheduled`: the workbench's first-order low-pass at
#: :data:`specdesign.simulate.SCHEDULE_FILTER_OMEGA` (the default), or ROSCO's own.
SCHEDULING_FILTERS = ("first_order", "rosco")

#: ROSCO's scheduling-pitch filter (``Filters.f90``): second order at this fraction of
#: F_LPFCornerFreq, with damping :data:`ROSCO_SCHEDULE_DAMPING`.
ROSCO_SCHEDULE_CORNER = 0.25
#: Damping ratio of ROSCO's scheduling-pitch filter.
ROSCO_SCHEDULE_DAMPING = 0.7


def rosco_scheduled(model: TurbineModel | None = None, wind_speeds: ArrayLike | None = None, *, name: str = "ROSCO",
                    form: str = "gains", schedule: object = None,
                    scheduling_filter: str = "first_order",
                    tower_damper: TowerDamper | None = None, peak_shaving: bool = True) -> ScheduledController:
    """The ROSCO baseline PI (tower damping off unless asked) with its gain schedule on filtered pitch.

    ``form="gains"`` (default) is ROSCO's own scheduling: K_p and K_i of
    :func:`rosco_baseline` at ``wind_speeds``, placed at each speed's trim pitch, interpolated
    linearly in the filtered pitch command, applied to one error filtered by
    :func:`speed_filter` with one integrator of K_i(β_f)·e_f, integrator and output saturated
    at the model's pitch limits as ROSCO's PI does (anti-windup). ``form="output"`` blends the
    outputs of the local PIs instead (the general scheme of
    :func:`specdesign.simulate.scheduled`; kept for comparison).

    Parameters
    ----------
    model : TurbineModel, optional
        The reduced turbine model (default :func:`specdesign.turbine.iea15mw`).
    wind_speeds : array_like, optional
        Scheduling wind speeds (m/s). Default: every whole m/s where the model's above-rated
        range and the gain schedule overlap (12-25 m/s for the IEA 15 MW).
    name : str, optional
        Label of the controller in tables and figures.
    form : {"gains", "output"}, optional
        ROSCO's gain scheduling, or output blending of the local PIs.
    schedule : RoscoSchedule or DisconSchedule, optional
        The gains to schedule. Default :func:`rosco_gain_schedule` of ``model``. A
        :class:`~specdesign.rosco.DisconSchedule` (:func:`~specdesign.rosco.from_discon`) runs
        the DISCON.IN's own controller: its gains at its ``PC_GS_angles`` (``wind_speeds``
        must then be None; gains per generator-side rad/s times ``WE_GearboxRatio`` on the
        model's rotor speed), its speed filter (``F_LPFType``, ``F_LPFCornerFreq``,
        ``F_LPFDamping``) and its pitch limits within the model's (``form="gains"`` only).
    scheduling_filter : {"first_order", "rosco"}, optional
        The low-pass giving the scheduling pitch: ``"first_order"`` (default) at
        :data:`specdesign.simulate.SCHEDULE_FILTER_OMEGA` = 0.1 rad/s; ``"rosco"`` ROSCO's
        own, second order at :data:`ROSCO_SCHEDULE_CORNER` × the speed filter's corner
        (``F_LPFCornerFreq``; 1.0081 rad/s for the model's own schedule), damping
        :data:`ROSCO_SCHEDULE_DAMPING`, discretised by Tustin as ROSCO does.
    tower_damper : TowerDamper, optional
        ROSCO's fore-aft tower damper (``TD_Mode = 1``) added to every local controller as
        the ATD path, e.g. :func:`tune_tower_damper`. Default: none, except with a
        DisconSchedule whose file has ``TD_Mode = 1``, which runs the file's ``FA_KI`` and
        ``FA_HPFCornerFreq`` (its ``FA_IntSat`` is not applied: the simulator's ATD path is
        linear). A TowerDamper given here replaces the file's.
    peak_shaving : bool, optional
        With a DisconSchedule whose file has ``PS_Mode = 1``: run ROSCO's peak shaving, the
        PI's lower limit lifted to ``PS_BldPitchMin`` at ROSCO's filtered wind-speed estimate
        (its extended Kalman filter, ported, on the model's Cp table:
        :func:`specdesign.controller.peak_shaving.peak_shaving_from_discon`). True (default);
        False runs the file without it, as ``PS_Mode = 0`` would. Ignored otherwise.

    Returns
    -------
    specdesign.simulate.ScheduledController
        The scheduled controller, for :func:`specdesign.simulate.simulate`.

    Raises
    ------
    ValueError
        For an unknown ``form`` or ``scheduling_filter``, a wind speed outside the model's or
        the schedule's range, or a DisconSchedule with ``wind_speeds``, with ``form="output"``,
        with peak shaving on an estimator the workbench does not run (``WE_Mode`` not 2: the
        message names the file, line and key; pass ``peak_shaving=False``) or whose reference speed (``PC_RefSpd`` / ``WE_GearboxRatio``) differs from the model's
        rated rotor speed by more than 0.1 %.
    TypeError
        For a ``schedule`` that is neither a RoscoSchedule nor a DisconSchedule.
    RuntimeError
        If the scheduled gains at a scheduling speed differ from :func:`rosco_baseline`
        (an internal consistency check).

    Examples
    --------
    >>> sc = rosco_scheduled()
    >>> sc.form, sc.schedule_pitch.size
    ('gains', 14)
    >>> from specdesign.rosco import from_discon, iea15mw_discon
    >>> sc = rosco_scheduled(schedule=from_discon(iea15mw_discon()), scheduling_filter="rosco")
    >>> sc.schedule_pitch.size, round(sc.filter_omega, 4), sc.filter_damping
    (30, 0.252, 0.7)
    """
    if model is None:
        model = iea15mw()
    if scheduling_filter not in SCHEDULING_FILTERS:
        raise ValueError(f"scheduling_filter must be one of {SCHEDULING_FILTERS}, got {scheduling_filter!r}")
    if tower_damper is not None and not isinstance(tower_damper, TowerDamper):
        raise TypeError(f"tower_damper must be a TowerDamper (tune_tower_damper) or None, got {type(tower_damper).__name__}")
    if isinstance(schedule, DisconSchedule):
        if tower_damper is None and schedule.td_mode == 1:
            tower_damper = TowerDamper(schedule.fa_ki, schedule.fa_hpf_corner, schedule.fa_int_sat)
        sc = _discon_scheduled(model, schedule, wind_speeds, name, form, scheduling_filter)
        ps = peak_shaving_from_discon(schedule.path, model.tsr_grid, model.pitch_grid, model.cp_table) \
            if peak_shaving else None
        if ps is not None:
            sc = dataclasses.replace(sc, peak_shaving=ps)
        return sc if tower_damper is None else _with_damper(sc, tower_damper)
    if schedule is not None and not isinstance(schedule, RoscoSchedule):
        raise TypeError(f"schedule must be a RoscoSchedule or a DisconSchedule (from_discon), got {type(schedule).__name__}")
    filt = ({} if scheduling_filter == "first_order" else
            {"filter_omega": ROSCO_SCHEDULE_CORNER * 1.0081, "filter_damping": ROSCO_SCHEDULE_DAMPING})
    # The gains of rosco_baseline: pole placement on the straight-line fits of A, B_β.
    sched = rosco_gain_schedule(model) if schedule is None else schedule
    if wind_speeds is None:
        wind_speeds = _default_speeds(model, sched)
    vs = [float(v) for v in np.atleast_1d(np.asarray(wind_speeds, dtype=float))]
    if form == "output":
        sc = dataclasses.replace(scheduled(model, {v: rosco_baseline(model, v, schedule=sched) for v in vs},
                                           name=name), **filt)
        return sc if tower_damper is None else _with_damper(sc, tower_damper)
    if form != "gains":
        raise ValueError(f"form must be one of {FORMS}, got {form!r}")
    v = np.array(sorted(set(vs)))
    kp, ki = sched.gains(v)
    plant = turbine_plant(model)
    beta = np.array([plant.trim(s)[1] for s in v])
    order = np.argsort(beta)
    sc = ScheduledController.gain_scheduled_pi(beta[order], kp[order], ki[order], speed_filter(), name=name,
                                               pitch_limits=(model.pitch_min, model.pitch_max), **filt)
    # Same controller as rosco_baseline at each speed (checked against its transfer function).
    jw = 1j * np.array([0.05, 0.5, 2.0])
    for k, s in enumerate(v[order]):
        ref = np.asarray(rosco_baseline(model, float(s), schedule=sched)(jw), complex)
        if not np.allclose(np.asarray(sc.pitch[k](jw), complex), ref, rtol=1e-9, atol=0):
            raise RuntimeError(f"rosco_scheduled's gains at {s:g} m/s differ from rosco_baseline")
    return sc if tower_damper is None else _with_damper(sc, tower_damper)


def _with_damper(sc: ScheduledController, damper: TowerDamper) -> ScheduledController:
    """``sc`` with ROSCO's (unscheduled) tower damper as the ATD controller of every local."""
    return dataclasses.replace(sc, atd=(damper.controller(),) * sc.schedule_pitch.size)


def _default_speeds(model, sched):
    """Every whole m/s where both the model and the gain schedule hold."""
    lo, hi = getattr(model, "wind_range", (11.0, 25.0))
    lo, hi = max(lo, float(np.min(sched.v))), min(hi, float(np.max(sched.v)))
    return np.arange(math.ceil(lo), math.floor(hi) + 0.5, 1.0)


def _discon_scheduled(model, schedule, wind_speeds, name, form, scheduling_filter):
    """rosco_scheduled with a DisconSchedule: its own gains, speed filter and pitch limits."""
    import control  # python-control loads matplotlib.pyplot: only when a schedule or damper is built

    where = f"schedule ({schedule.path})"
    if wind_speeds is not None:
        raise ValueError(f"wind_speeds must be None with a DisconSchedule: {where} schedules on its own PC_GS_angles")
    if form != "gains":
        raise ValueError(f"form must be 'gains' with a DisconSchedule ({where} holds gains, not designed controllers)")
    n = schedule.gearbox_ratio
    ref = schedule.reference_speed / n
    if abs(ref - model.rated_rotor_speed) > 1e-3 * model.rated_rotor_speed:
        raise ValueError(f"{where}: PC_RefSpd / WE_GearboxRatio = {ref:.6g} rad/s but the model's rated rotor speed is "
                         f"{model.rated_rotor_speed:.6g} rad/s: the DISCON.IN is for another turbine")
    wf = schedule.filter_corner
    speed = speed_filter(wf, schedule.filter_damping) if schedule.filter_type == 2 else control.tf([wf], [1.0, wf])
    filt = ({"filter_omega": SCHEDULE_FILTER_OMEGA} if scheduling_filter == "first_order" else
            {"filter_omega": ROSCO_SCHEDULE_CORNER * wf, "filter_damping": ROSCO_SCHEDULE_DAMPING})
    lim = (max(model.pitch_min, schedule.pitch_min), min(model.pitch_max, schedule.pitch_max))
    # ROSCO's gains act on the generator speed: N times the rotor speed the model feeds back
    return ScheduledController.gain_scheduled_pi(schedule.pitch, schedule.kp * n, schedule.ki * n, speed, name=name,
                                                 pitch_limits=lim, **filt)


#: Corner (rad/s) of the tower damper's high-pass on acceleration (ROSCO's ``FA_HPFCornerFreq``)
#: by default: a decade below the IEA 15 MW's first tower mode (1.08 rad/s), so the
#: high-pass costs under 6° of phase at the mode while removing the accelerometer's offset.
TOWER_DAMPER_HPF_CORNER = 0.1
#: Default saturation (rad) of the damper's pitch contribution (``FA_IntSat``): 5°.
TOWER_DAMPER_INT_SAT = math.radians(5.0)
#: Default target damping ratio of the first tower fore-aft mode for :func:`tune_tower_damper`.
TOWER_DAMPER_DAMPING_RATIO = 0.2


@dataclasses.dataclass(frozen=True)
class TowerDamper:
    """ROSCO's fore-aft tower damper (``TD_Mode = 1``, ``Controllers.f90``: ForeAftDamping).

    ROSCO adds Δβ = ``FA_KI`` · ∫ HPF(a_top) dt to the collective pitch command, a_top the
    tower-top fore-aft acceleration (m/s²) high-passed at ``FA_HPFCornerFreq``, the integral
    saturated at ±``FA_IntSat``. The integral of the high-passed acceleration is the
    high-passed tower-top velocity, so in the workbench's convention (β −= C_atd·ẋ_top) the
    damper is C_atd(s) = −K·s/(s + ω_c) on the velocity (:meth:`controller`).

    Parameters
    ----------
    gain : float
        ``FA_KI`` (rad·s/m, i.e. rad per m/s of tower-top velocity), positive (pitch to
        feather when the tower moves downwind).
    hpf_corner : float, optional
        ``FA_HPFCornerFreq`` (rad/s).
    int_sat : float, optional
        ``FA_IntSat`` (rad). The workbench's simulator runs the damper linearly (no
        saturation); :class:`specdesign.rosco.Discon` applies it.
    damping_ratio : float or None, optional
        The tower-mode damping ratio the gain was tuned for (:func:`tune_tower_damper`), or
        None for a gain given by hand or read from a DISCON.IN.
    """

    gain: float
    hpf_corner: float = TOWER_DAMPER_HPF_CORNER
    int_sat: float = TOWER_DAMPER_INT_SAT
    damping_ratio: float | None = None

    def __post_init__(self):
        for k in ("gain", "hpf_corner", "int_sat"):
            object.__setattr__(self, k, positive_scalar(getattr(self, k), k))

    def controller(self) -> control.TransferFunction:
        """C_atd(s) = −K·s/(s + ω_c) on tower-top velocity (m/s → rad; β −= C_atd·ẋ_top).

        Returns
        -------
        control.TransferFunction
            The damper as the workbench's ATD controller (input ``tower_top_vel``, output
            ``pitch_cmd``).
        """
        import control  # python-control loads matplotlib.pyplot: only when the damper is built

        return control.tf([-self.gain, 0.0], [1.0, self.hpf_corner], inputs="tower_top_vel", outputs="pitch_cmd")

    def discon_values(self) -> dict:
        """The DISCON.IN entries that switch ROSCO's damper on with this gain (for ``write_discon``).

        Returns
        -------
        dict
            ``TD_Mode``, ``FA_KI`` (rad·s/m), ``FA_HPFCornerFreq`` (rad/s), ``FA_IntSat`` (rad).
        """
        return {"TD_Mode": 1, "FA_KI": self.gain, "FA_HPFCornerFreq": self.hpf_corner, "FA_IntSat": self.int_sat}


def _damper_loop(model: TurbineModel, wind_speed: float, hpf_corner: float):
    """(A, b, c, tower pole of the plant): speed loop closed with ROSCO's PI, Δβ = K·c·x closes the damper."""
    import control  # python-control loads matplotlib.pyplot: only when a schedule or damper is built

    plant = model.linearize(wind_speed)
    g = plant[["gen_speed", "tower_top_vel"], "pitch_cmd"]
    pi = control.ss(rosco_baseline(model, wind_speed))
    pi = control.ss(pi.A, pi.B, pi.C, pi.D, inputs="gen_speed", outputs="beta_pi")
    g = control.ss(g.A, g.B, g.C, g.D, inputs="pitch_cmd", outputs=["gen_speed", "tower_top_vel"])
    hpf = control.ss(control.tf([1.0, 0.0], [1.0, hpf_corner]))
    hpf = control.ss(hpf.A, hpf.B, hpf.C, hpf.D, inputs="tower_top_vel", outputs="y")
    junction = control.summing_junction(["u", "-beta_pi"], "pitch_cmd")
    m = control.interconnect([g, pi, hpf, junction], inplist=["u"], outlist=["y"])
    if np.any(np.asarray(m.D) != 0):  # the plant is strictly proper: no algebraic loop
        raise RuntimeError("the tower damper's loop has a direct feedthrough")
    # The tower mode of the plant at fixed pitch: its complex pole nearest √(k/m).
    wt = math.sqrt(model.tower_modal_stiffness / model.tower_modal_mass)
    p = np.linalg.eigvals(np.asarray(g.A))
    p = p[p.imag > 0]
    return np.asarray(m.A), np.asarray(m.B), np.asarray(m.C), p[np.argmin(np.abs(np.abs(p) - wt))]


def _tracked_poles(a, b, c, start, gains):
    """The tower pole followed from ``start`` along ``gains`` (small steps): one pole per gain."""
    pole, out = start, []
    for k in gains:
        p = np.linalg.eigvals(a + k * (b @ c))
        p = p[p.imag > 0]
        pole = p[np.argmin(np.abs(p - pole))]
        out.append(pole)
    return np.array(out)


def _zeta(pole):
    return -pole.real / np.abs(pole)


def tower_mode_damping(model: TurbineModel | None, wind_speed: float, damper: TowerDamper | None) -> float:
    """Damping ratio of the first tower fore-aft mode with ROSCO's PI and ``damper`` closed.

    On the linearisation at ``wind_speed`` (m/s), the speed loop closed with
    :func:`rosco_baseline`, the damper's gain raised from 0 in small steps with the tower
    pole followed from the fixed-pitch plant's (so the mode is the tower's, not the PI's).

    Parameters
    ----------
    model : TurbineModel or None
        The turbine (default :func:`specdesign.turbine.iea15mw`).
    wind_speed : float
        Operating point, m/s.
    damper : TowerDamper or None
        The damper (None: ROSCO without one).

    Returns
    -------
    float
        ζ (-) of the tower mode.
    """
    model = iea15mw() if model is None else model
    corner = TOWER_DAMPER_HPF_CORNER if damper is None else damper.hpf_corner
    a, b, c, start = _damper_loop(model, float(wind_speed), corner)
    k = 0.0 if damper is None else damper.gain
    return float(_zeta(_tracked_poles(a, b, c, start, np.linspace(0.0, k, 201))[-1]))


def tune_tower_damper(model: TurbineModel | None = None, damping_ratio: float = TOWER_DAMPER_DAMPING_RATIO, *,
                      wind_speeds: ArrayLike | None = None, hpf_corner: float = TOWER_DAMPER_HPF_CORNER,
                      int_sat: float = TOWER_DAMPER_INT_SAT, max_gain: float = 0.5) -> TowerDamper:
    """ROSCO's tower damper with its one gain ``FA_KI`` set by a damping-ratio rule.

    The rule: the smallest K such that, on the linear model with ROSCO's PI closed
    (:func:`tower_mode_damping`), the first tower fore-aft mode has damping ratio at least
    ``damping_ratio`` at every wind speed of ``wind_speeds`` (ROSCO's gain is one number,
    not scheduled, so the speed that needs the most sets it; equality holds there).

    Parameters
    ----------
    model : TurbineModel, optional
        Default :func:`specdesign.turbine.iea15mw`.
    damping_ratio : float, optional
        Target ζ (-) of the tower mode (default 0.2, about twice the IEA 15 MW's aerodynamic
        damping with ROSCO's PI at 13-18 m/s, three times at 25 m/s).
    wind_speeds : array_like, optional
        Wind speeds (m/s) where the rule holds (default: every whole m/s of the model's
        above-rated range where ROSCO's gain schedule holds, as :func:`rosco_scheduled`).
    hpf_corner, int_sat : float, optional
        ``FA_HPFCornerFreq`` (rad/s) and ``FA_IntSat`` (rad) of the damper.
    max_gain : float, optional
        Largest K (rad·s/m) searched.

    Returns
    -------
    TowerDamper
        With ``damping_ratio`` recorded.

    Raises
    ------
    ValueError
        If ``damping_ratio`` is not in (0, 1), or no K up to ``max_gain`` reaches it.
    """
    model = iea15mw() if model is None else model
    z = positive_scalar(damping_ratio, "damping_ratio")
    if not z < 1:
        raise ValueError(f"damping_ratio must be in (0, 1), got {damping_ratio!r}")
    hpf_corner = positive_scalar(hpf_corner, "hpf_corner")
    if wind_speeds is None:
        wind_speeds = _default_speeds(model, rosco_gain_schedule(model))
    gains = np.linspace(0.0, positive_scalar(max_gain, "max_gain"), 501)
    need = 0.0
    for v in np.atleast_1d(np.asarray(wind_speeds, dtype=float)):
        a, b, c, start = _damper_loop(model, float(v), hpf_corner)
        poles = _tracked_poles(a, b, c, start, gains)
        zeta = _zeta(poles)
        i = int(np.argmax(zeta >= z))
        if zeta[i] < z:
            raise ValueError(f"no tower-damper gain up to max_gain = {max_gain} rad·s/m gives damping ratio {z} at "
                             f"{v:g} m/s (best {zeta.max():.3f}); lower damping_ratio or raise max_gain")
        if i == 0:
            continue
        # ζ is smooth in K: refine the crossing between the two grid points by bisection.
        lo, hi = gains[i - 1], gains[i]
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            if _zeta(_tracked_poles(a, b, c, poles[i - 1], [mid])[0]) >= z:
                hi = mid
            else:
                lo = mid
        need = max(need, hi)
    if need == 0:
        raise ValueError(f"the tower mode already has damping ratio {z} or more at every wind speed without a damper: "
                         "nothing to tune (raise damping_ratio)")
    return TowerDamper(gain=need, hpf_corner=hpf_corner, int_sat=int_sat, damping_ratio=z)
