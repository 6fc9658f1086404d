"""Stability of the linearised turbine loop as the simulator runs it: poles, hidden modes, messages.

The loop is β = −C_β·Ω_g − C_atd·ẋ_top around the linearisation at a wind speed, with a
scheduled controller blended at the trim pitch of that wind speed (:func:`loop_parts`,
:func:`local_response`); the simulator (:mod:`specdesign.simulate`) warns and the validation
refuses where :func:`unstable_poles` finds any. Below rated (a model with a torque law, at a
wind speed under its rated wind speed) the pitch loop is open, as the simulator runs it (the
pitch command sits at fine pitch): the controller counts as zero there and the loop is the
linearisation, with the torque loop closed in it.
"""
from __future__ import annotations

import warnings
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from .._checks import positive_scalar
from ..controller.lti import as_lti, split_integrator
from ..controller.scheduled import ScheduledController
from ..turbine.plant import KernelPlant, turbine_plant

if TYPE_CHECKING:
    import control

    from ..turbine import TurbineModel

__all__ = ["ClosedLoopUnstableWarning", "fine_pitch_lift", "loop_parts", "local_response", "closed_loop_matrices", "turbine_loop_poles",
           "hidden_origin_poles", "unstable_poles", "unstable_message", "trim_weights", "ORIGIN_TOL",
           "UNSTABLE_CONTROLLER_RATE", "MAX_SENSITIVITY", "DESIGN_MAX_SENSITIVITY", "CERTIFICATE_MAX_SENSITIVITY",
           "MIN_DECAY_RATE"]


#: Growth rate (1/s) above which a controller's own pole counts as unstable (a controller with
#: one is refused by :func:`specdesign.qft.design_qft` and by the certificate's follow path:
#: wherever the pitch saturates the loop opens and the mode grows): slower modes grow less
#: than e-fold over a 10-minute record.
UNSTABLE_CONTROLLER_RATE = 1e-3

#: Peak M_s of the pitch loop's sensitivity |S| = |1/(1 + C·P_{Ω,β})| the feasibility checks and
#: the convex design impose by default: 2 (6 dB), the usual robustness rule (it guarantees a gain
#: margin of at least M_s/(M_s − 1) = 2 and a phase margin of at least 2·asin(1/(2·M_s)) = 29°).
MAX_SENSITIVITY = 2.0
#: Peak of |S| the designers require (both loops and the actuator): design_qft, its bounds check
#: and design_hinf's plant-case check; below :data:`MAX_SENSITIVITY`, so a design keeps margin on
#: the feasibility verdict.
DESIGN_MAX_SENSITIVITY = 1.9
#: Peak of |S| of the certificate (specification_for_target, CertificateSearch): below
#: :data:`DESIGN_MAX_SENSITIVITY`, so that the plant cases and a reduced-order controller fitted
#: to the certificate keep their margins in the design.
CERTIFICATE_MAX_SENSITIVITY = 1.8
#: Least decay rate (1/s) of a designed closed loop, every pole left of −0.02: the QFT designs'
#: ``min_decay``, the H∞ synthesis' α-shift (:data:`specdesign.hinf.DEFAULT_DECAY_RATE`) and the
#: multi-model H∞ step's ``decay_rate``; a mode that decays at 0.02 1/s falls by e in 50 s.
MIN_DECAY_RATE = 0.02


class ClosedLoopUnstableWarning(UserWarning):
    """A closed loop has poles with non-negative real part.

    Issued by :func:`specdesign.closedloop.closed_loop` and
    :func:`specdesign.closedloop.check_stability`; a subclass of ``UserWarning``, so it can
    be filtered on its own (``warnings.simplefilter("error", ClosedLoopUnstableWarning)``).
    """


def loop_parts(model: TurbineModel | KernelPlant | None, controller: Any,
               wind_speed: float) -> tuple[control.StateSpace, list[int], control.StateSpace]:
    """The linearised loop at ``wind_speed`` as :func:`specdesign.simulate.simulate` runs it.

    A ScheduledController is blended at the trim pitch of ``wind_speed`` (as
    :func:`specdesign.validate.closed_loop_response` blends it), its locals' integrators
    summed into one (:func:`specdesign.simulate.split_integrator`). Below the rated wind speed
    of a plant with a torque law the pitch loop is open: ``K`` is zero.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The turbine, with a linearisation (None: the embedded IEA 15 MW, as
        :func:`specdesign.simulate.turbine_plant` takes it).
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        Anything :func:`specdesign.simulate.simulate` runs with a linear form: a SISO pitch
        controller C_β (rad per rad/s) or a scheduled pitch (and ATD) controller.
    wind_speed : float
        Operating point, m/s.

    Returns
    -------
    G : control.StateSpace
        The plant's linearisation (inputs wind m/s, pitch_cmd rad, gen_torque N·m by position;
        deviations from trim).
    rows : list of int
        Indices of (gen_speed, tower_top_vel) among the outputs of ``G``.
    K : control.StateSpace
        The continuous 1×2 controller on them, β = −K·[Ω_g, ẋ_top] = −C_β·Ω_g − C_atd·ẋ_top
        (rad per rad/s, rad per m/s).

    Raises
    ------
    ValueError
        If the plant has no linearisation, or the controller is not SISO / is discrete-time.
    TypeError
        If the controller is neither an LTI system, a Controller nor a ScheduledController.
    """
    plant = turbine_plant(model)  # one plant per model: the model and its plant share the cache
    key = (id(plant), id(controller), float(wind_speed))
    hit = _PARTS.get(key)
    if hit is not None and hit[0] is plant and hit[1] is controller:
        G, rows, K2 = hit[2]
        return G, list(rows), K2
    G, rows, K2 = _loop_parts(plant, controller, wind_speed)
    if len(_PARTS) >= _PARTS_SIZE:
        try:  # another thread (a threaded dask worker) may have changed it meanwhile: drop any entry
            _PARTS.pop(next(iter(_PARTS)), None)
        except (RuntimeError, StopIteration):
            pass
    # plant and controller held with the entry, so their ids cannot be reused while it lives
    _PARTS[key] = (plant, controller, (G, tuple(rows), K2))
    return G, rows, K2


# (id(plant), id(controller), v) → (plant, controller, parts): a campaign checks every loop
# up front, again before simulating it and in the simulator; built once. The objects are
# frozen records and python-control systems, which the workbench never changes in place.
_PARTS: dict = {}
_PARTS_SIZE = 256


def _loop_parts(plant, controller, wind_speed):
    """:func:`loop_parts` computed."""
    import control

    if plant.linearize is None:
        raise ValueError(f"plant {plant.name!r} has no linearisation: its closed-loop poles are unknown")
    G = control.ss(plant.linearize(wind_speed))
    names = list(plant.output_names)
    rows = [names.index("gen_speed"), names.index("tower_top_vel")]
    open_pitch = plant.rated_wind_speed is not None and wind_speed < plant.rated_wind_speed
    if open_pitch:
        # below rated the pitch PI sits at fine pitch (saturated): the pitch loop is open, the
        # torque loop (closed in the linearisation) alone acts
        cb = ca = control.ss([], [], [], [[0.0]])
    elif isinstance(controller, ScheduledController):
        w = trim_weights(plant, controller, wind_speed)
        parts = [(w[q], controller.local(q)) for q in range(len(w)) if w[q] != 0]
        # blend as the simulator runs the locals: the integrators (split_integrator) summed into
        # one, so two locals integrating the same error leave no spurious pole at s = 0
        cb = _blend([(wq, c) for wq, (c, _) in parts])
        ca = _blend([(wq, a) for wq, (_, a) in parts if a is not None])
    else:
        cb, ca = control.ss(as_lti(controller, "controller")), control.ss([], [], [], [[0.0]])
    K2 = control.ss([], [], [], [[1.0, 1.0]]) * control.append(cb, ca)  # [C_β, C_atd]: 1×2
    return G, rows, K2


def trim_weights(plant: KernelPlant, controller: ScheduledController, wind_speed: float) -> list[float]:
    """Blend weights of a ScheduledController's locals at the trim pitch of ``wind_speed``.

    Linear interpolation in the scheduling pitch (rad), as the simulator blends them.

    Parameters
    ----------
    plant : KernelPlant
        The simulated plant (:func:`specdesign.simulate.turbine_plant`), for its trim.
    controller : specdesign.simulate.ScheduledController
        The scheduled controller.
    wind_speed : float
        Operating point, m/s.

    Returns
    -------
    list of float
        One weight (-) per local controller, summing to 1.

    Examples
    --------
    At 19 m/s the trim pitch is one of ROSCO's scheduling pitches:

    >>> from specdesign.closedloop import trim_weights
    >>> from specdesign.rosco import rosco_scheduled
    >>> from specdesign.simulate import turbine_plant
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> w = trim_weights(turbine_plant(model), rosco_scheduled(model), 19.0)
    >>> len(w), sum(w)
    (14, 1.0)
    """
    b0 = plant.trim(wind_speed)[1]
    K = controller.schedule_pitch.size
    return [float(np.interp(b0, controller.schedule_pitch, np.eye(K)[q])) for q in range(K)]


def local_response(model: TurbineModel | KernelPlant | None, controller: Any, wind_speed: float,
                   s: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """A controller's responses (C_β(s), C_atd(s)) at the complex frequencies ``s``.

    A ScheduledController is blended at ``wind_speed`` as the simulator blends it. Below the
    rated wind speed of a plant with a torque law both are zero (the pitch loop is open).

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The turbine (for the trim pitch that sets a schedule's blend).
    controller : LTI, Controller or ScheduledController
        Anything :func:`specdesign.simulate.simulate` runs with a linear form.
    wind_speed : float
        Operating point, m/s.
    s : array_like of complex
        Laplace variable, e.g. ``1j * omega`` with omega in rad/s.

    Returns
    -------
    c_beta : numpy.ndarray
        C_β(s), rad per rad/s, complex, shaped like ``s``. An integrator evaluated at s = 0
        gives inf (or nan) silently: the closed-loop formulas take the limit there.
    c_atd : numpy.ndarray
        C_atd(s), rad per m/s (zeros without ATD), complex, shaped like ``s``.

    Raises
    ------
    TypeError
        If the controller is neither an LTI system, a Controller nor a ScheduledController.
    ValueError
        If the controller is not SISO or is discrete-time.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import local_response
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> cb, ca = local_response(model, rosco_baseline(model, 19.0), 19.0, 1j * np.array([0.1, 1.0]))
    >>> np.round(np.abs(cb), 3), ca
    (array([0.448, 0.086]), array([0.+0.j, 0.+0.j]))
    """
    s = np.asarray(s)
    plant = turbine_plant(model)
    if plant.rated_wind_speed is not None and wind_speed < plant.rated_wind_speed:
        # below rated the pitch loop is open (the PI saturated at fine pitch): as loop_parts
        if not isinstance(controller, ScheduledController):
            as_lti(controller, "controller")  # the same type checks as above rated
        return np.zeros_like(s, dtype=complex), np.zeros_like(s, dtype=complex)
    with warnings.catch_warnings(), np.errstate(divide="ignore", invalid="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        if isinstance(controller, ScheduledController):
            w = trim_weights(plant, controller, wind_speed)
            K = len(w)
            cb = sum(w[q] * np.asarray(controller.pitch[q](s)) for q in range(K) if w[q] != 0)
            ca = 0.0 if controller.atd is None else sum(w[q] * np.asarray(controller.atd[q](s)) for q in range(K)
                                                        if w[q] != 0)
            return np.asarray(cb, complex), np.asarray(ca, complex) * np.ones_like(s)
        c = as_lti(controller, "controller")
        return np.asarray(c(s), complex), np.zeros_like(s)


def closed_loop_matrices(model: TurbineModel | KernelPlant | None, controller: Any, wind_speed: float, *,
                         parts: tuple | None = None) -> tuple[np.ndarray, np.ndarray]:
    """State matrix and wind input column of the linearised closed loop at ``wind_speed``.

    The loop is β = −C_β·Ω_g − C_atd·ẋ_top (:func:`loop_parts`), with the algebraic loop
    through the feedthroughs solved for β.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The turbine, with a linearisation.
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        Anything :func:`specdesign.simulate.simulate` runs with a linear form.
    wind_speed : float
        Operating point, m/s.
    parts : tuple, optional
        :func:`loop_parts` of the same arguments, if already at hand (then ``model``,
        ``controller`` and ``wind_speed`` are not used).

    Returns
    -------
    A : numpy.ndarray
        (n, n) closed-loop state matrix, 1/s; states [plant; controller].
    b : numpy.ndarray
        (n,) column of the wind input (per m/s).

    Raises
    ------
    ValueError
        If the loop is ill-posed, 1 + K(∞)·P(∞) = 0, or :func:`loop_parts` raises.
    """
    G, rows, K = loop_parts(model, controller, wind_speed) if parts is None else parts
    A, B, C, D = (np.asarray(x, dtype=float) for x in (G.A, G.B, G.C, G.D))
    Ak, Bk, Ck, Dk = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (K.A, K.B, K.C, K.D))
    nk = Ak.shape[0] if K.nstates else 0
    Ak, Bk, Ck = Ak.reshape(nk, nk), Bk.reshape(nk, 2), Ck.reshape(1, nk)
    bw, bu = B[:, 0], B[:, 1]
    cm, dmw, dmu = C[rows], D[rows, 0], D[rows, 1]
    den = 1.0 + float(Dk[0] @ dmu)  # u = −K·(cm x + dmw w + dmu u): solved for u
    if abs(den) < 1e-12:
        raise ValueError("the loop is ill-posed: 1 + K(∞)·P(∞) = 0 (the controller cancels the plant's feedthrough)")
    ux, uc, uw = -(Dk[0] @ cm) / den, -Ck[0] / den, -float(Dk[0] @ dmw) / den
    mx, mc, mw = cm + np.outer(dmu, ux), np.outer(dmu, uc), dmw + dmu * uw
    Acl = np.block([[A + np.outer(bu, ux), np.outer(bu, uc)], [Bk @ mx, Ak + Bk @ mc]])
    return Acl, np.concatenate([bw + bu * uw, Bk @ mw])


#: Relative size (of the largest |pole|) under which a closed-loop pole counts as s = 0.
ORIGIN_TOL = 1e-9


def turbine_loop_poles(model: TurbineModel | KernelPlant | None, controller: Any, wind_speed: float) -> np.ndarray:
    """Poles of the linearised turbine at ``wind_speed`` closed by ``controller``.

    The loop is β = −C_β·Ω_g − C_atd·ẋ_top.

    Parameters
    ----------
    model : TurbineModel or KernelPlant
        The turbine (:class:`specdesign.simulate.KernelPlant` with a linearisation).
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        Anything :func:`specdesign.simulate.simulate` runs with a linear form; a
        ScheduledController is blended at the trim pitch of ``wind_speed``, as
        :func:`specdesign.validate.closed_loop_response` blends it.
    wind_speed : float
        Operating point, m/s.

    Returns
    -------
    numpy.ndarray
        Complex closed-loop poles, 1/s (plant and controller states), unsorted.

    Raises
    ------
    ValueError
        If the plant has no linearisation, the loop is ill-posed, or the controller is not
        SISO / is discrete-time.
    TypeError
        If the controller is of an unsupported type.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import turbine_loop_poles
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> p = turbine_loop_poles(model, rosco_baseline(model, 19.0), 19.0)
    >>> p.size, bool(np.all(p.real < 0))
    (8, True)
    """
    return np.linalg.eigvals(closed_loop_matrices(model, controller, wind_speed)[0])


def hidden_origin_poles(A: ArrayLike, b: ArrayLike, poles: ArrayLike | None = None) -> np.ndarray:
    """Mark the poles at s = 0 whose mode the input cannot excite.

    A pole at s = 0 (within :data:`ORIGIN_TOL`) is hidden when the input ``b`` cannot excite
    its mode (PBH test: left eigenvector ⟂ b), i.e. a conserved quantity such as
    ∫ẋ_top − x_top when an ATD controller integrates the tower-top velocity (a 1×2 H∞
    controller split into its SISO pitch and ATD parts does). Such a mode neither grows nor
    responds to the wind: it is no instability.

    Parameters
    ----------
    A : array_like
        (n, n) state matrix, 1/s.
    b : array_like
        (n,) input column (e.g. the wind's, per m/s).
    poles : array_like, optional
        The eigenvalues of ``A`` (1/s), in any order; default: computed here.

    Returns
    -------
    numpy.ndarray
        Boolean mask over ``poles``: True for a hidden pole at s = 0.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import hidden_origin_poles
    >>> A = np.array([[0.0, 0.0], [0.0, -1.0]])                 # poles 0 and −1 1/s
    >>> hidden_origin_poles(A, np.array([0.0, 1.0]))            # the input drives only s = −1
    array([ True, False])
    """
    import scipy.linalg

    lam, wl = scipy.linalg.eig(A, left=True, right=False)
    if poles is None:
        poles = lam
    scale = max(1.0, float(np.max(np.abs(lam), initial=0.0)))
    at0 = np.abs(lam) <= ORIGIN_TOL * scale
    nb = float(np.linalg.norm(b))
    hidden0 = at0 & (np.abs(wl.conj().T @ b) <= 1e-8 * np.linalg.norm(wl, axis=0) * max(nb, 1e-300))
    out = np.zeros(np.size(poles), bool)
    # match the given poles to the eigenvalues just computed (the same ones, maybe reordered)
    for z in lam[hidden0]:
        cand = np.flatnonzero(~out & (np.abs(np.asarray(poles) - z) <= ORIGIN_TOL * scale))
        if cand.size:
            out[cand[0]] = True
    return out


def unstable_poles(model: TurbineModel | KernelPlant | None, controller: Any, wind_speed: float, *,
                   parts: tuple | None = None) -> np.ndarray:
    """The closed-loop poles with Re ≥ 0 at ``wind_speed``; empty when the loop is stable.

    A pole at s = 0 (within :data:`ORIGIN_TOL`) counts as unstable (the response to the wind
    would drift), unless the wind cannot excite its mode (:func:`hidden_origin_poles`).

    Parameters
    ----------
    model, controller, wind_speed, parts
        As :func:`closed_loop_matrices` takes them: the turbine (with a linearisation), a
        controller with a linear form, the operating point (m/s) and, optionally, the loop parts.

    Returns
    -------
    numpy.ndarray
        The unstable poles, 1/s, complex, sorted (``numpy.sort_complex``).

    Raises
    ------
    ValueError
        As :func:`closed_loop_matrices`.

    Examples
    --------
    >>> from specdesign.closedloop import unstable_poles
    >>> from specdesign.rosco import rosco_baseline
    >>> from specdesign.turbine import iea15mw
    >>> model = iea15mw()
    >>> unstable_poles(model, rosco_baseline(model, 19.0), 19.0)
    array([], dtype=complex128)
    """
    A, b = closed_loop_matrices(model, controller, wind_speed, parts=parts)
    p = np.linalg.eigvals(A)
    scale = max(1.0, float(np.max(np.abs(p), initial=0.0)))
    cand = (p.real >= 0) | (np.abs(p) <= ORIGIN_TOL * scale)
    if np.any(cand & (np.abs(p) <= ORIGIN_TOL * scale)):
        cand &= ~hidden_origin_poles(A, b, p)
    return np.sort_complex(p[cand])


def unstable_message(controller: Any, wind_speed: float, poles: ArrayLike) -> str:
    """One line naming the controller, the wind speed and its unstable poles.

    Parameters
    ----------
    controller : object
        The controller (its ``name`` attribute, or else its type name, is quoted).
    wind_speed : float
        Operating point, m/s.
    poles : array_like of complex
        The unstable poles, 1/s (e.g. :func:`unstable_poles`).

    Returns
    -------
    str
        The message.

    Examples
    --------
    >>> import numpy as np
    >>> from specdesign.closedloop import unstable_message
    >>> unstable_message(object(), 19.0, np.array([0.05 + 1.2j]))
    "controller 'object' destabilises the linearised turbine at 19 m/s (closed-loop poles 0.05+1.2j)"
    """
    name = getattr(controller, "name", None) or type(controller).__name__
    listing = ", ".join(f"{z.real:.4g}{z.imag:+.4g}j" for z in poles)
    return f"controller {name!r} destabilises the linearised turbine at {wind_speed:g} m/s (closed-loop poles {listing})"


def _blend(weighted):
    """Σ w·C as one state-space system with a single integrator: Σ w·r/s + Σ w·C_r."""
    import control

    r, rest = 0.0, control.ss([], [], [], [[0.0]])
    for wq, c in weighted:
        rq, cr = split_integrator(c)
        r, rest = r + wq * rq, rest + wq * control.ss(cr)
    return rest + control.ss(control.tf([r], [1.0, 0.0])) if r != 0 else rest


def fine_pitch_lift(controller, deficit: float, duration: float = 60.0, n: int = 6001) -> float:
    """How far a pitch controller lifts the pitch for a sustained speed deficit (rad; ≤ 0: it does not).

    Below rated the rotor runs ``deficit`` under the pitch controller's speed reference; a
    controller held there (the lowest design of a schedule) must keep pushing the pitch into
    fine pitch, where it saturates. Its linear, unsaturated answer β = −C·δΩ_g to the step
    δΩ_g = −``deficit`` (β in the workbench sign) over ``duration`` seconds: the largest β is
    the lift. ROSCO's PI answers monotonically (lift 0); a controller whose answer swings up
    lifts the pitch off fine pitch, and ROSCO's torque state machine then goes to rated torque
    (docs/below_rated.md).

    Parameters
    ----------
    controller : control.LTI
        C_β, generator speed (rad/s) → pitch (rad), β = −C_β·Ω_g.
    deficit : float
        Speed deficit below rated, rad/s (> 0), e.g. the pitch controller's reference minus the
        torque law's minimum speed.
    duration : float
        Time span of the answer, s (> 0).
    n : int
        Time samples (≥ 2).

    Returns
    -------
    float
        The largest pitch of the answer, rad (positive: lifted off fine pitch).

    Raises
    ------
    ValueError
        For a non-positive ``deficit`` or ``duration``, fewer than 2 samples, or a controller
        that is not SISO.

    Examples
    --------
    >>> import control
    >>> from specdesign.closedloop import fine_pitch_lift
    >>> pi = control.tf([-0.6, -0.08], [1.0, 0.0])  # ROSCO-like PI, β = −C·Ω_g
    >>> fine_pitch_lift(pi, 0.27) <= 0.0
    True
    """
    import control

    deficit = positive_scalar(deficit, "deficit")
    duration = positive_scalar(duration, "duration")
    if int(n) != n or n < 2:
        raise ValueError(f"n={n!r} must be an integer ≥ 2 (time samples)")
    sys = control.ss(controller)
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"controller must be SISO (generator speed → pitch), got {sys.noutputs}x{sys.ninputs}")
    t = np.linspace(0.0, duration, int(n))
    _, y = control.step_response(sys, t)
    return float(np.max(deficit * np.squeeze(y)))
