"""The export itself: :func:`export_discon` (a controller or design → library + parameter file).

See :mod:`specdesign.export` for what the pair is and how OpenFAST and the workbench run it.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import positive_scalar
from .._files import atomic_write
from ..controller.lti import as_lti, is_lti_like
from ..controller.scheduled import ScheduledController, controller_bank, schedule_filter_coefficients
from ..controller.torque import TORQUE_PARAMS, TorqueLaw
from ..turbine import TurbineModel, iea15mw
from .library import discon_library
from .parameters import TORQUE_MODES, DisconParameters, write_parameters

__all__ = ["PARAMETER_FILE", "DisconExport", "discon_parameters", "export_discon"]

#: File name of the parameter file :func:`export_discon` writes in its folder.
PARAMETER_FILE = "DISCON_specdesign.IN"


@dataclass(frozen=True)
class DisconExport:
    """An exported controller: the library and the parameter file it reads.

    Parameters
    ----------
    library : pathlib.Path
        The compiled Bladed-interface library (a copy in the export folder).
    parameters : pathlib.Path
        The parameter file (``DLL_InFile`` of ServoDyn).
    dt : float
        The controller's sample time (s): ServoDyn's ``DLL_DT``.
    torque : str
        The generator-torque law: "constant", "power", "rosco" or "rosco_power".
    name : str
        Label of the controller.
    """

    library: Path
    parameters: Path
    dt: float
    torque: str
    name: str


def _as_controller(obj: object, name: str | None):
    """``obj`` as what :func:`controller_bank` takes: a ScheduledController or an LTI."""
    if isinstance(obj, ScheduledController):
        if obj.peak_shaving is not None:  # the library runs no wind-speed estimator
            raise ValueError(f"controller_or_design {obj.name!r} carries ROSCO's peak shaving "
                             f"({obj.peak_shaving.name}), which the exported library does not run: export "
                             "dataclasses.replace(controller, peak_shaving=None), or run the deck's own ROSCO DISCON")
        return obj, name or obj.name
    if hasattr(obj, "pitch_controller"):  # a design record: QFTDesign, HinfDesign
        label = name or f"{type(obj).__name__} at {getattr(obj, 'wind_speed', float('nan')):g} m/s"
        return ScheduledController.fixed(as_lti(obj.pitch_controller, "pitch_controller"),
                                         getattr(obj, "atd_controller", None), name=label), label
    if is_lti_like(obj):
        return obj, name or "controller"
    raise TypeError(f"controller_or_design must be a design (with pitch_controller), a ScheduledController, a "
                    f"python-control LTI or a loopshaping Controller, got {type(obj).__name__}")


def _torque(torque, model: TurbineModel):
    """(mode name, TorqueLaw or None) of the ``torque`` argument; ROSCO's law is "rosco_power"
    exactly when it holds constant power above rated (its ``const_power``, ``VS_ConstPower``)."""
    if isinstance(torque, TorqueLaw):
        return ("rosco_power" if torque.const_power else "rosco"), torque
    law = getattr(model, "torque_control", None)
    if torque is None:
        if law is None:
            return "constant", None
        return ("rosco_power" if law.const_power else "rosco"), law
    if torque not in TORQUE_MODES:
        raise ValueError(f"torque={torque!r} must be one of {tuple(TORQUE_MODES)}, None or a specdesign.rosco.TorqueLaw")
    if torque in ("rosco", "rosco_power") and law is None:
        raise ValueError(f"torque={torque!r} needs a model with a torque law (torque_control); pass a TorqueLaw instead")
    if torque == "rosco_power":
        law = dataclasses.replace(law, const_power=True)
    elif torque == "rosco" and law.const_power:  # the model's law as simulate(torque_control="rosco") runs it
        return "rosco_power", law
    return torque, law


def discon_parameters(controller_or_design: object, *, dt: float = 0.02, model: TurbineModel | None = None,
                      torque: str | TorqueLaw | None = None, pitch_rate_limit: float = math.inf,
                      atd_highpass: float = 0.0, gearbox_ratio: float = 1.0,
                      name: str | None = None) -> DisconParameters:
    """The parameters the library reads for a controller: its discrete bank, limits and torque law.

    Parameters
    ----------
    controller_or_design : object
        The controller or design (see :func:`export_discon`).
    dt : float, optional
        Sample time (s).
    model : TurbineModel, optional
        The turbine (default :func:`specdesign.turbine.iea15mw`).
    torque : {"constant", "power", "rosco", "rosco_power"}, TorqueLaw or None, optional
        The generator-torque law (see :func:`export_discon`).
    pitch_rate_limit : float, optional
        Largest rate of the pitch command (rad/s), inf for none.
    atd_highpass : float, optional
        Corner (rad/s) of the tower-top velocity estimate; 0 the plain integral.
    gearbox_ratio : float, optional
        Generator / rotor speed (-).
    name : str, optional
        Label.

    Returns
    -------
    DisconParameters
        The parameter set (write it with :func:`write_parameters`).

    Raises
    ------
    TypeError, ValueError
        As :func:`export_discon`.
    """
    dt = positive_scalar(dt, "dt")
    model = iea15mw() if model is None else model
    ctrl, label = _as_controller(controller_or_design, name)
    mode, law = _torque(torque, model)
    rate = float(pitch_rate_limit)
    if not rate > 0:
        raise ValueError(f"pitch_rate_limit={pitch_rate_limit!r} must be > 0 rad/s (inf for none)")
    hp = float(atd_highpass)
    if not (hp >= 0 and math.isfinite(hp)):
        raise ValueError(f"atd_highpass={atd_highpass!r} must be a finite corner >= 0 rad/s")
    gear = positive_scalar(gearbox_ratio, "gearbox_ratio")
    sched, mats, fw, pi = controller_bank(ctrl, dt)
    K = sched.size
    n = max(1, max(m[0].shape[0] for m in mats))
    A, B, C, D = np.zeros((K, n, n)), np.zeros((K, n, 2)), np.zeros((K, n)), np.zeros((K, 2))
    for q, (a, b, c, d, _, _) in enumerate(mats):
        k = a.shape[0]
        A[q, :k, :k], B[q, :k], C[q, :k], D[q] = a, b, c, d
    cmd = (float(model.pitch_min), float(model.pitch_max))
    kw = {}
    if pi is not None:
        kp, ki, Af, Bf, Cf, Df, lim = pi
        # as simulate narrows them: the PI's own limits within the plant's
        kw = dict(pi_kp=np.asarray(kp, float), pi_ki=np.asarray(ki, float), pi_A=np.asarray(Af, float).reshape(
            Bf.size, Bf.size), pi_B=np.asarray(Bf, float), pi_C=np.asarray(Cf, float), pi_D=np.asarray(Df, float),
            pi_limits=(max(lim[0], cmd[0]), min(lim[1], cmd[1])))
    return DisconParameters(
        dt=dt, gearbox_ratio=gear, rated_speed=float(model.rated_rotor_speed), pitch_limits=cmd,
        pitch_rate_limit=rate, torque_mode=TORQUE_MODES[mode], rated_torque=float(model.rated_generator_torque),
        max_torque=float(law.max_torque) if law is not None else float(model.rated_generator_torque),
        rated_power=float(model.rated_power), generator_efficiency=float(model.generator_efficiency),
        # ROSCO's generator-speed filter (F_LPFCornerFreq, F_LPFDamping): the law's, or ROSCO's defaults
        speed_filter=(law.filter_corner, law.filter_damping) if law is not None else (1.0081, 0.7),
        torque_law=law.params() if mode in ("rosco", "rosco_power") else np.zeros(TORQUE_PARAMS),
        schedule_filter=schedule_filter_coefficients(fw, getattr(ctrl, "filter_damping", None), dt),
        atd_highpass=hp, schedule_pitch=np.asarray(sched, float), integrator_gain=np.array([m[4] for m in mats]),
        slow_states=np.array([m[5] for m in mats], dtype=np.int64), A=A, B=B, C=C, D=D, name=label, **kw)


def export_discon(controller_or_design: object, folder: str | Path, *, dt: float = 0.02,
                  model: TurbineModel | None = None, torque: str | TorqueLaw | None = None,
                  pitch_rate_limit: float = math.inf, atd_highpass: float = 0.0, gearbox_ratio: float = 1.0,
                  name: str | None = None, cache: str | Path | None = None,
                  compiler: str | None = None) -> DisconExport:
    """Export a controller as a DISCON library (Bladed interface) and its parameter file.

    The pitch controller is discretised as :func:`specdesign.simulate.simulate` runs it (Tustin
    at ``dt``, its integrator apart, the same anti-windup and scheduling); the library runs
    those matrices with the generator-torque law and the pitch limits, so in the workbench's
    simulator (:class:`specdesign.rosco.Discon`) its records equal the Python controller's.

    Parameters
    ----------
    controller_or_design : object
        A design with ``pitch_controller`` and ``atd_controller`` (``design_qft``,
        ``design_hinf``), a :class:`~specdesign.simulate.ScheduledController` (``scheduled``,
        ``rosco_scheduled``: ROSCO-form gains), a python-control LTI (``rosco_baseline``) or a
        ``loopshaping`` Controller; β = −C·(Ω − Ω_rated) − C_atd·ẋ_top about the pitch
        measured at the initialisation.
    folder : str or pathlib.Path
        Where the library copy and the parameter file go (created).
    dt : float, optional
        Sample time (s) of the controller: ServoDyn's ``DLL_DT``, or the simulator's ``dt``.
    model : TurbineModel, optional
        The turbine (default :func:`specdesign.turbine.iea15mw`): its rated speed (the
        reference), pitch limits, rated torque and power, generator efficiency, torque law.
    torque : {"constant", "power", "rosco", "rosco_power"}, TorqueLaw or None, optional
        Generator torque: "constant" the rated torque (the simulator above rated); "power"
        P_rated/(η·Ω_f) capped at the law's maximum torque, everywhere (for runs above rated);
        "rosco" the model's ROSCO torque law as ``simulate(..., torque_control="rosco")`` runs
        it (rated torque in region 3, or rated power if its ``const_power`` is set);
        "rosco_power" that law with constant power in region 3 and its ceiling, as ROSCO runs
        ``VS_ConstPower = 1`` (the simulator's law with ``const_power``); a given
        :class:`~specdesign.rosco.TorqueLaw` runs as it is (``simulate(..., torque_control=law)``).
        None (default): "rosco" if the model has a torque law, else "constant".
    pitch_rate_limit : float, optional
        Largest rate of the pitch command (rad/s); default inf (the workbench's controllers
        have none; its actuator model limits the pitch rate). For OpenFAST without a pitch
        actuator, give the turbine's (e.g. ``model.pitch_rate_limit``).
    atd_highpass : float, optional
        Corner w (rad/s) of the tower-top velocity the ATD loop uses, estimated from the
        measured acceleration avrSWAP(53) as s/(s + w)²·a; 0 (default) the plain integral of
        the acceleration since the start. OpenFAST's acceleration carries a bias (gravity
        through the tower-top tilt): use ~0.05 rad/s there (2.6° of phase at the 1.1 rad/s
        tower mode per factor). Unused without an ATD loop.
    gearbox_ratio : float, optional
        Generator / rotor speed (-): avrSWAP(20) is the generator speed; the workbench's
        models are on the rotor shaft (ratio 1, the IEA 15 MW is direct drive).
    name : str, optional
        Label written in the file.
    cache, compiler : optional
        Of :func:`discon_library`.

    Returns
    -------
    DisconExport
        ``library`` and ``parameters`` (paths), ``dt``, ``torque``, ``name``.

    Raises
    ------
    TypeError
        For an object that is not a controller or a design.
    ValueError
        For a non-positive ``dt`` or ``gearbox_ratio``, an unknown ``torque``, a non-positive
        ``pitch_rate_limit`` or a negative ``atd_highpass``, or a ScheduledController with
        ROSCO's peak shaving (its wind-speed estimator is not exported).
    CompilerNotFoundError
        If no C compiler is found to build the library.

    Examples
    --------
    >>> import tempfile
    >>> from specdesign.turbine import iea15mw, rosco_baseline
    >>> m = iea15mw()
    >>> rec = export_discon(rosco_baseline(m, 19.0), tempfile.mkdtemp(), model=m)
    >>> rec.parameters.name, rec.torque
    ('DISCON_specdesign.IN', 'rosco')
    """
    p = discon_parameters(controller_or_design, dt=dt, model=model, torque=torque, pitch_rate_limit=pitch_rate_limit,
                          atd_highpass=atd_highpass, gearbox_ratio=gearbox_ratio, name=name)
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    built = discon_library(cache=cache, compiler=compiler)
    lib = folder / built.name
    data = built.read_bytes()
    if not lib.is_file() or lib.read_bytes() != data:
        # renamed into place, never rewritten: an OpenFAST run with this folder's library loaded
        # (a campaign exporting beside a running one) would crash on a truncated mapped file
        atomic_write(lib, lambda tmp: tmp.write_bytes(data))
    mode = {v: k for k, v in TORQUE_MODES.items()}[p.torque_mode]
    params = write_parameters(p, folder / PARAMETER_FILE,
                              comment=f"written by specdesign.export.export_discon for {lib.name}")
    return DisconExport(library=lib.resolve(), parameters=params.resolve(), dt=p.dt, torque=mode, name=p.name)
