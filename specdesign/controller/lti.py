"""Controller preparation for the simulator: SISO checks, Tustin discretisation, the integrator
and slow-mode splits, and the bank of discrete local controllers the compiled loop runs.

See :func:`specdesign.simulate.simulate` for the anti-windup these splits serve.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from loopshaping.freqresp import as_siso

from .._checks import positive_scalar

if TYPE_CHECKING:  # pragma: no cover
    import control

__all__ = [
    "is_lti_like",
    "as_lti",
    "tustin_matrices",
    "split_integrator",
    "SLOW_OMEGA",
    "split_slow",
]


def is_lti_like(c: object) -> bool:
    """Whether ``c`` is an LTI controller the simulator takes as one (not a callable).

    Parameters
    ----------
    c : object
        A candidate controller.

    Returns
    -------
    bool
        True for a python-control LTI system or an object with a ``tf()`` method (a
        ``loopshaping.controller.Controller``).
    """
    import control

    return isinstance(c, control.LTI) or (hasattr(c, "tf") and callable(getattr(c, "tf")))

def as_lti(c: object, name: str) -> control.LTI:
    """``c`` as a continuous SISO python-control system, checked.

    Parameters
    ----------
    c : control.LTI or loopshaping.controller.Controller
        The controller (a ``Controller`` is converted by its ``.tf()``).
    name : str
        Name of the argument, for the error messages.

    Returns
    -------
    control.LTI
        The SISO continuous-time system.

    Raises
    ------
    TypeError
        If ``c`` is neither an LTI system nor has a ``tf()`` method.
    ValueError
        If it is not SISO, or is discrete-time.
    """
    import control

    if hasattr(c, "tf") and callable(c.tf) and not isinstance(c, control.LTI):
        c = c.tf()
    if not isinstance(c, control.LTI):  # a number is no controller here: the simulator runs systems
        raise TypeError(f"{name} must be a python-control LTI system or a loopshaping Controller, got {type(c).__name__}")
    return as_siso(c, name, proper=False)


def tustin_matrices(controller: object, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Tustin discretisation of a SISO continuous controller at step ``dt``.

    Parameters
    ----------
    controller : control.LTI or loopshaping.controller.Controller
        The continuous SISO controller.
    dt : float
        Step (s).

    Returns
    -------
    A, B, C, D : numpy.ndarray
        Float arrays of shapes (n, n), (n,), (n,) and (1,) of the discrete state-space form
        x⁺ = A x + B u, y = C x + D u.

    Raises
    ------
    ValueError
        For an improper controller (more zeros than poles), a non-SISO or discrete one, or a
        non-positive ``dt``.

    Examples
    --------
    >>> import control
    >>> A, B, C, D = tustin_matrices(control.tf([1.0], [1.0, 1.0]), 0.1)
    >>> A.shape, D.shape
    ((1, 1), (1,))
    """
    import control

    dt = positive_scalar(dt, "dt")
    c = as_lti(controller, "controller")
    if isinstance(c, control.TransferFunction):
        num, den = np.atleast_1d(np.squeeze(c.num[0][0])), np.atleast_1d(np.squeeze(c.den[0][0]))
        num = np.trim_zeros(num, "f")
        if num.size > np.trim_zeros(den, "f").size:
            raise ValueError("controller is improper (more zeros than poles); add a roll-off pole")
    s = control.ss(c)
    n = s.nstates
    if n == 0:
        return np.zeros((0, 0)), np.zeros(0), np.zeros(0), np.array([float(np.squeeze(s.D))])
    from loopshaping.reduction import discretize

    d = discretize(s, dt, "tustin")  # the workbench's one discretisation
    return (np.asarray(d.A, float), np.asarray(d.B, float).ravel(), np.asarray(d.C, float).ravel(),
            np.array([float(np.squeeze(d.D))]))


def split_integrator(controller: object) -> tuple[float, control.LTI]:
    """(r, C_r): C(s) = r/s + C_r(s) for a SISO controller with one pole at s = 0.

    The simulator runs r/s as a separate integrator (trapezoid rule = Tustin, so the sum is
    the Tustin discretisation of C exactly) and clamps it at the pitch limits as ROSCO clamps
    its integrator (anti-windup); C_r has no pole at 0 and cannot wind up. A controller
    without a pole at 0 gives (0, C); one with several is returned whole, unclamped.

    Parameters
    ----------
    controller : control.LTI or loopshaping.controller.Controller
        The continuous SISO controller C.

    Returns
    -------
    r : float
        Residue of the pole at s = 0 (units of C per second), 0.0 without one.
    rest : control.LTI
        C_r (C itself when r is 0).

    Raises
    ------
    TypeError, ValueError
        For a controller that is not a continuous SISO LTI (:func:`as_lti`).

    Examples
    --------
    >>> import control
    >>> r, rest = split_integrator(control.tf([2.0, 3.0], [1.0, 0.0]))
    >>> r
    3.0
    """
    import control

    c = as_lti(controller, "controller")
    tf = control.tf(c)
    num = np.trim_zeros(np.atleast_1d(np.squeeze(tf.num[0][0])).astype(float), "f")
    den = np.trim_zeros(np.atleast_1d(np.squeeze(tf.den[0][0])).astype(float), "f")
    tiny = 1e-12 * np.max(np.abs(den))
    if den.size < 2 or abs(den[-1]) > tiny or (den.size > 2 and abs(den[-2]) <= tiny):
        return 0.0, c
    d1 = den[:-1]
    r = float(num[-1] / d1[-1]) if num.size else 0.0
    rest = np.polysub(num, r * d1)[:-1]  # (num − r·d1)/s: its constant term is zero
    return r, control.tf(rest if rest.size else [0.0], d1)


#: Corner (rad/s) under which a pole of a pitch controller (besides its integrator) belongs to
#: its slow part (:func:`split_slow`): a time constant above 10 s, longer than an excursion to
#: the pitch floor, over which such a mode integrates the speed error as the integrator does.
#: A controller with a slow part gets conditional integration, one without (PI-like, ROSCO's:
#: its speed filter is at 1 rad/s) ROSCO's integrator clamp; see :func:`specdesign.simulate.simulate`.
SLOW_OMEGA = 0.1


def split_slow(controller: object, omega: float = SLOW_OMEGA) -> tuple[control.StateSpace | None, control.LTI]:
    """(C_s or None, C_f): C = C_s + C_f, C_s the modes of ``controller`` slower than ``omega``.

    C_s holds the modes of ``controller`` (no pole at 0, e.g. C_r of :func:`split_integrator`)
    with |pole| < ``omega``, strictly proper, and C_f the others plus the feedthrough.
    Block-diagonalised from the ordered real Schur form (a Sylvester equation decouples the
    blocks), so C_s + C_f equals C to rounding.

    Parameters
    ----------
    controller : control.LTI or loopshaping.controller.Controller
        The continuous SISO controller C.
    omega : float, optional
        Corner (rad/s) under which a pole is slow (default :data:`SLOW_OMEGA`).

    Returns
    -------
    slow : control.StateSpace or None
        C_s, or None without slow poles.
    fast : control.LTI
        C_f (``controller`` itself, unchanged, without slow poles).

    Raises
    ------
    TypeError, ValueError
        For a controller that is not a continuous SISO LTI (:func:`as_lti`).
    """
    import control
    import scipy.linalg

    c = control.ss(as_lti(controller, "controller"))
    A, B, C, D = (np.asarray(x, dtype=float) for x in (c.A, c.B, c.C, c.D))
    n = A.shape[0]
    if n == 0 or not np.any(np.abs(np.linalg.eigvals(A)) < omega):
        return None, controller
    T, Z, k = scipy.linalg.schur(A, output="real", sort=lambda x, y: math.hypot(x, y) < omega)
    X = scipy.linalg.solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:])
    V = Z @ np.block([[np.eye(k), X], [np.zeros((n - k, k)), np.eye(n - k)]])
    Bt, Ct = np.linalg.solve(V, B), C @ V
    slow = control.ss(T[:k, :k], Bt[:k], Ct[:, :k], np.zeros_like(D))
    fast = control.ss(T[k:, k:], Bt[k:], Ct[:, k:], D) if k < n else control.ss([], [], [], D)
    return slow, fast
