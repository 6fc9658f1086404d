"""Gain-scheduled controllers: local controllers scheduled on the filtered pitch command.

:class:`ScheduledController` in its two forms (output blending of designed locals, ROSCO's
gain-scheduled PI) and :func:`controller_bank`, its discrete arrays for the compiled loop.
:func:`specdesign.turbine.plant.scheduled` builds one from controllers designed per wind
speed. See :mod:`specdesign.simulate` for how the simulator runs them and
:func:`specdesign.rosco.rosco_scheduled` for ROSCO's.
"""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from loopshaping.freqresp import is_zero

from .._checks import positive_scalar
from .lti import as_lti, split_integrator, split_slow, tustin_matrices
from .peak_shaving import PeakShaving

__all__ = ["SCHEDULE_FILTER_OMEGA", "FORMS", "ScheduledController", "schedule_filter_coefficients", "controller_bank"]

#: Default low-pass corner of the scheduling pitch filter (rad/s): slow enough that the
#: scheduling variable follows the mean operating point rather than the turbulence
#: (ROSCO filters its scheduling pitch at 0.1 × the 1 rad/s speed-filter corner).
SCHEDULE_FILTER_OMEGA = 0.1



#: The two forms of :class:`ScheduledController`.
FORMS = ("output", "gains")


def _check_peak_shaving(ps, form):
    """ScheduledController's ``peak_shaving``: a PeakShaving, with ROSCO's form of the PI only, or None."""
    if ps is None:
        return
    if not isinstance(ps, PeakShaving):
        raise TypeError(f"peak_shaving must be a PeakShaving (peak_shaving_from_discon) or None, got {type(ps).__name__}")
    if form != "gains":
        raise ValueError("peak_shaving is for form='gains' only (it lifts the lower limit of ROSCO's PI)")


@dataclass(frozen=True, eq=False)  # array fields: compare by identity
class ScheduledController:
    """Local pitch (and optional ATD) controllers scheduled on filtered pitch.

    The weights are piecewise linear in β_f between the scheduling pitches, clamped at the
    ends (see :mod:`specdesign.simulate`).

    Parameters
    ----------
    schedule_pitch : array_like
        (K,) strictly increasing scheduling pitches β_k (rad), one per local controller.
    pitch : tuple
        K continuous SISO controllers C_β,k on the generator speed (β = −C·Ω_g, rad per
        rad/s): the local controllers (in ``form="gains"``, the frozen-gain PIs
        (K_p,k + K_i,k/s)·F).
    atd : tuple or None, optional
        K continuous SISO controllers on tower-top velocity (β −= C_atd·ẋ_top, rad per m/s),
        or None; output-blended in both forms.
    filter_omega : float, optional
        Corner (rad/s) of the first-order low-pass on the pitch command that gives the
        scheduling variable β_f.
    name : str, optional
        Label used in tables and figures.
    form : {"output", "gains"}, optional
        ``"output"`` blends the local controllers' outputs; ``"gains"`` runs ROSCO's form,
        u = K_p(β_f)·e_f + ∫K_i(β_f)·e_f dt with e_f = error_filter·(Ω_rated − Ω_g), the gains
        interpolated linearly in β_f. Build it with :meth:`gain_scheduled_pi`.
    kp, ki : numpy.ndarray or None, optional
        (K,) PI gains at the scheduling pitches (``form="gains"`` only; in the workbench's
        convention C = (K_p + K_i/s)·F, i.e. ROSCO's negative gains), rad/(rad/s) and rad/rad.
    error_filter : control.LTI or None, optional
        SISO LTI filter F on the speed error (``form="gains"`` only).
    pitch_limits : tuple of float or None, optional
        (min, max) absolute pitch (rad) at which ``form="gains"`` saturates its integrator
        (the trim pitch plus ∫K_i·e_f) and its PI output, as ROSCO's PI does (anti-windup).
        :func:`specdesign.simulate.simulate` narrows them to the plant's pitch limits, and uses
        the plant's alone when this is None (default): the integrator never winds up beyond
        what the actuator can reach; on a plant without limits, None means no saturation.
    filter_damping : float or None, optional
        None (default): the scheduling filter is first order, ω_f/(s + ω_f), ω_f =
        ``filter_omega``, discretised exactly. A damping ratio ζ: second order,
        ω_f²/(s² + 2ζω_f s + ω_f²), discretised by Tustin, as ROSCO filters its scheduling
        pitch (``Filters.f90``: ω_f = 0.25·F_LPFCornerFreq, ζ = 0.7).
    peak_shaving : PeakShaving or None, optional
        ROSCO's peak shaving (``form="gains"`` only): the PI's lower limit lifted every step
        to the minimum pitch at ROSCO's filtered wind-speed estimate (see
        :mod:`specdesign.controller.peak_shaving`). None (default): the limits alone.

    Raises
    ------
    ValueError
        For scheduling pitches that are not strictly increasing, a number of locals that
        does not match them, an unknown ``form``, ``form="gains"`` arguments with
        ``form="output"``, or locals that are not the frozen-gain PIs of ``kp``, ``ki``.
    """

    schedule_pitch: np.ndarray
    pitch: tuple
    atd: tuple | None = None
    filter_omega: float = SCHEDULE_FILTER_OMEGA
    name: str = "controller"
    form: str = "output"
    kp: np.ndarray | None = field(default=None, repr=False)
    ki: np.ndarray | None = field(default=None, repr=False)
    error_filter: object = field(default=None, repr=False)
    pitch_limits: tuple | None = None
    filter_damping: float | None = None
    peak_shaving: PeakShaving | None = None

    def __post_init__(self):
        b = np.atleast_1d(np.asarray(self.schedule_pitch, dtype=float))
        if b.ndim != 1 or b.size < 1 or np.any(np.diff(b) <= 0) or not np.all(np.isfinite(b)):
            raise ValueError(f"schedule_pitch must be a 1-D strictly increasing array of pitches in rad, got {b}")
        object.__setattr__(self, "schedule_pitch", b)
        if len(self.pitch) != b.size:
            raise ValueError(f"pitch needs one controller per scheduling pitch ({b.size}), got {len(self.pitch)}")
        if self.atd is not None and len(self.atd) != b.size:
            raise ValueError(f"atd needs one controller per scheduling pitch ({b.size}), got {len(self.atd)}")
        positive_scalar(self.filter_omega, "filter_omega")
        if self.filter_damping is not None:
            object.__setattr__(self, "filter_damping", positive_scalar(self.filter_damping, "filter_damping"))
        if self.form not in FORMS:
            raise ValueError(f"form must be one of {FORMS}, got {self.form!r}")
        _check_peak_shaving(self.peak_shaving, self.form)
        if self.form == "output":
            if self.kp is not None or self.ki is not None or self.error_filter is not None or self.pitch_limits is not None:
                raise ValueError("kp, ki, error_filter and pitch_limits are for form='gains' only")
            return
        if self.pitch_limits is not None:
            lim = tuple(float(x) for x in self.pitch_limits)
            if len(lim) != 2 or not lim[0] < lim[1] or any(math.isnan(x) for x in lim):
                raise ValueError(f"pitch_limits must be (min, max) pitch in rad with min < max, got {self.pitch_limits!r}")
            object.__setattr__(self, "pitch_limits", lim)
        gains = []
        for g, nm in ((self.kp, "kp"), (self.ki, "ki")):
            a = np.atleast_1d(np.asarray(g, dtype=float)) if g is not None else None
            if a is None or a.shape != b.shape or not np.all(np.isfinite(a)):
                raise ValueError(f"form='gains' needs {nm} as {b.size} finite gains, one per scheduling pitch, got {g!r}")
            gains.append(a)
        object.__setattr__(self, "kp", gains[0])
        object.__setattr__(self, "ki", gains[1])
        f = as_lti(self.error_filter, "error_filter")
        object.__setattr__(self, "error_filter", f)
        # The local controllers must be the frozen-gain PIs, or the linear prediction (which
        # blends them) would describe another controller than the one simulated.
        jw = 1j * np.array([0.03, 0.3, 1.0, 3.0])
        fj = np.asarray(f(jw), complex)
        for k in range(b.size):
            ref = (gains[0][k] + gains[1][k] / jw) * fj
            got = np.asarray(as_lti(self.pitch[k], f"pitch[{k}]")(jw), complex)
            if not np.allclose(got, ref, rtol=1e-8, atol=0):
                raise ValueError(f"pitch[{k}] is not (kp[{k}] + ki[{k}]/s)·error_filter; build form='gains' "
                                 "with ScheduledController.gain_scheduled_pi")

    def local(self, k: int) -> tuple:
        """The k-th local controller.

        Parameters
        ----------
        k : int
            Index of the scheduling pitch.

        Returns
        -------
        tuple
            (C_β, C_atd or None).
        """
        return self.pitch[k], (None if self.atd is None else self.atd[k])

    @classmethod
    def fixed(cls, pitch: object, atd: object | None = None, *, name: str = "controller") -> ScheduledController:
        """One pitch controller and, optionally, its tower damper, not scheduled.

        A single local controller: every pitch blends it with weight 1, so the simulator, the
        linear predictions and the exported library run ``pitch`` and ``atd`` as they are.

        Parameters
        ----------
        pitch : control.LTI or loopshaping Controller
            C_β on the generator speed (β = −C_β·Ω_g, rad per rad/s).
        atd : control.LTI, loopshaping Controller or None, optional
            C_atd on the tower-top velocity (β −= C_atd·ẋ_top, rad per m/s); None, or a zero
            system (a design without a tower damper), for none.
        name : str, optional
            Label used in tables and figures.

        Returns
        -------
        ScheduledController
            The controller, ``form="output"``.

        Examples
        --------
        A design's pitch loop and tower damper as one controller (``d = qft.design_qft(...)``):

        >>> import control as ct
        >>> c = ScheduledController.fixed(ct.tf([-1.0, -0.1], [1.0, 0.0]), ct.tf([0.02], [1.0, 1.0]))
        >>> c.local(0)[1] is not None
        True
        """
        atd = None if atd is None or is_zero(atd) else (as_lti(atd, "atd"),)
        return cls(np.zeros(1), (as_lti(pitch, "pitch"),), atd, name=name)

    @classmethod
    def gain_scheduled_pi(cls, schedule_pitch: ArrayLike, kp: ArrayLike, ki: ArrayLike, error_filter: object, *,
                          atd: Sequence | None = None, filter_omega: float = SCHEDULE_FILTER_OMEGA, name: str = "PI",
                          pitch_limits: tuple[float, float] | None = None,
                          filter_damping: float | None = None) -> ScheduledController:
        """ROSCO-form gain-scheduled PI: u = K_p(β_f)·e_f + ∫K_i(β_f)·e_f dt, e_f = F·(Ω_ref − Ω_g).

        Parameters
        ----------
        schedule_pitch : array_like
            (K,) strictly increasing scheduling pitches (rad).
        kp : array_like
            (K,) proportional gains at the scheduling pitches (rad per rad/s), in the
            workbench's convention C = (K_p + K_i/s)·F (ROSCO's negative gains).
        ki : array_like
            (K,) integral gains (rad per rad), same convention.
        error_filter : control.LTI
            SISO LTI F on the speed error (e.g. :func:`specdesign.rosco.speed_filter`).
        atd : sequence or None, optional
            K ATD controllers (output-blended) or None.
        filter_omega : float, optional
            Corner of the scheduling filter (rad/s).
        name : str, optional
            Label used in tables and figures.
        pitch_limits : tuple of float or None, optional
            (min, max) pitch (rad) saturating the integrator and the PI output (ROSCO's
            anti-windup), or None (the simulated plant's limits, see the class).
        filter_damping : float or None, optional
            None: first-order scheduling filter; a damping ratio: second order (see the class).

        Returns
        -------
        ScheduledController
            The controller in ``form="gains"``.

        Raises
        ------
        ValueError
            For gains of different lengths or a length that does not match ``schedule_pitch``.

        Examples
        --------
        >>> import control
        >>> f = control.tf([1.0], [0.1, 1.0])
        >>> sc = ScheduledController.gain_scheduled_pi([0.1, 0.2], [-0.5, -0.4], [-0.05, -0.04], f)
        >>> sc.form
        'gains'
        """
        import control

        f = as_lti(error_filter, "error_filter")
        kp = np.atleast_1d(np.asarray(kp, dtype=float))
        ki = np.atleast_1d(np.asarray(ki, dtype=float))
        if kp.shape != ki.shape or kp.ndim != 1:
            raise ValueError(f"kp and ki must be 1-D arrays of the same length, got shapes {kp.shape} and {ki.shape}")
        pitch = tuple(control.tf([a, c], [1.0, 0.0]) * f for a, c in zip(kp, ki))
        return cls(schedule_pitch, pitch, None if atd is None else tuple(atd), filter_omega, name,
                   form="gains", kp=kp, ki=ki, error_filter=f, pitch_limits=pitch_limits,
                   filter_damping=filter_damping)


def schedule_filter_coefficients(omega: float, damping: float | None, dt: float) -> np.ndarray:
    """Coefficients of the discrete scheduling filter the simulator runs on the pitch command.

    Parameters
    ----------
    omega : float
        Corner ω_f (rad/s).
    damping : float or None
        None for the first-order filter ω_f/(s + ω_f) (exact discretisation), or the damping
        ratio ζ of the second-order ω_f²/(s² + 2ζω_f s + ω_f²) (Tustin, as ROSCO's
        ``SecLPFilter``).
    dt : float
        Step (s).

    Returns
    -------
    numpy.ndarray
        ``[1 − exp(−ω_f·dt)]`` (first order: β_f += c·(β − β_f)), or ``[b0, b1, b2, a1, a2]``
        of y_k = b0·u_k + b1·u_{k−1} + b2·u_{k−2} − a1·y_{k−1} − a2·y_{k−2}.

    Raises
    ------
    ValueError
        For a non-positive ``omega``, ``damping`` or ``dt``.

    Examples
    --------
    >>> c = schedule_filter_coefficients(0.25, 0.7, 0.02)
    >>> round(float((c[0] + c[1] + c[2]) / (1 + c[3] + c[4])), 9)  # unit gain at s = 0
    1.0
    """
    w = positive_scalar(omega, "omega")
    dt = positive_scalar(dt, "dt")
    if damping is None:
        return np.array([1.0 - math.exp(-w * dt)])
    z = positive_scalar(damping, "damping")
    wt2 = (w * dt) ** 2
    a0 = wt2 + 4.0 + 4.0 * z * w * dt
    return np.array([wt2, 2.0 * wt2, wt2, 2.0 * wt2 - 8.0, wt2 + 4.0 - 4.0 * z * w * dt]) / a0


_BANKS: dict = {}


def controller_bank(controller: object, dt: float) -> tuple:
    """Discrete arrays of one controller (K local 2-input controllers) and its filter corner.

    Memoised per (controller object, dt): a campaign simulates the same controllers at
    every wind speed, and discretising a 15-point ROSCO schedule costs more than a run.

    Parameters
    ----------
    controller : control.LTI, loopshaping.controller.Controller or ScheduledController
        The controller (an LTI is one local controller at scheduling pitch 0).
    dt : float
        Simulation step (s).

    Returns
    -------
    tuple
        ``(schedule_pitch, mats, filter_omega, pi)``: the (K,) scheduling pitches (rad); per
        local controller ``(A, B, C, D, r, ns)`` of its output-blended part, discrete at ``dt``
        (inputs speed error and negated tower-top velocity; ``r`` the pitch controller's
        integrator gain, run apart, see :func:`split_integrator`; its first ``ns`` states the
        modes of the rest under :data:`~specdesign.controller.lti.SLOW_OMEGA`, :func:`split_slow`); the scheduling filter
        corner (rad/s); and the scheduled-PI arrays ``(kp, ki, Af, Bf, Cf, Df, limits)`` of
        ``form="gains"`` or None (limits (2,) in rad, ±inf for none).

    Raises
    ------
    TypeError, ValueError
        For a controller that is not a continuous SISO LTI or a ScheduledController, or an
        improper one.
    """
    key = (id(controller), float(dt))
    hit = _BANKS.get(key)
    if hit is not None and hit[0] is controller:
        return hit[1]
    out = _make_bank(controller, dt)
    if len(_BANKS) > 64:
        _BANKS.clear()
    _BANKS[key] = (controller, out)
    return out


def _make_bank(controller, dt):
    """(schedule_pitch, per-local (A, B, C, D, r, ns) of the output-blended part (r: the
    pitch controller's integrator gain, run apart, see :func:`split_integrator`; its first ns
    states: the modes of the rest under SLOW_OMEGA, :func:`split_slow`), filter corner,
    scheduled-PI arrays (kp, ki, Af, Bf, Cf, Df, limits) or None; limits (2,) in rad, ±inf
    for none).

    In ``form="gains"`` the local pitch controllers are not in the blended bank (only the ATD
    locals are); the PI runs as one filter, one integrator and interpolated gains."""
    if not isinstance(controller, ScheduledController):
        controller = ScheduledController.fixed(as_lti(controller, "controller"))
    gains = controller.form == "gains"
    none = (np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.zeros(1))
    done = {}  # id → (system, its Tustin matrices): a schedule often holds one ATD at every local

    def tustin(c):
        hit = done.get(id(c))
        if hit is None:
            hit = done[id(c)] = (c, tustin_matrices(c, dt))  # the system held: its id stays its own
        return hit[1]

    mats = []
    for k in range(controller.schedule_pitch.size):
        cb, ca = controller.local(k)
        r, rest = (0.0, None) if gains else split_integrator(cb)
        slow, rest = (None, rest) if gains or r == 0.0 else split_slow(rest)
        As, Bs, Cs, Ds = none if slow is None else tustin_matrices(slow, dt)  # states first: the kernel's ns
        Ab, Bb, Cb, Db = none if gains else tustin_matrices(rest, dt)
        Aa, Ba, Ca, Da = none if ca is None else tustin(ca)
        ns, nb, na = As.shape[0], Ab.shape[0], Aa.shape[0]
        nt = ns + nb + na
        A = np.zeros((nt, nt))
        A[:ns, :ns], A[ns:ns + nb, ns:ns + nb], A[ns + nb:, ns + nb:] = As, Ab, Aa
        B = np.zeros((nt, 2))
        B[:ns, 0], B[ns:ns + nb, 0], B[ns + nb:, 1] = Bs, Bb, Ba
        mats.append((A, B, np.concatenate([Cs, Cb, Ca]), np.array([(Ds[0] if ns else 0.0) + Db[0], Da[0]]), r, ns))
    pi = None
    if gains:
        Af, Bf, Cf, Df = tustin_matrices(controller.error_filter, dt)
        lim = (-np.inf, np.inf) if controller.pitch_limits is None else controller.pitch_limits
        pi = (controller.kp, controller.ki, Af, Bf, Cf, Df, np.array(lim, dtype=float))
    return controller.schedule_pitch, mats, controller.filter_omega, pi
