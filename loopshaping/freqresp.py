"""Frequency-response helpers shared by every loopshaping module.

- :func:`is_lti`: is this a python-control LTI system?
- :func:`as_siso`: THE "make it a SISO LTI" helper (a number or a SISO continuous-time
  transfer function / state space → a python-control LTI; clear errors otherwise).
- :func:`evaluate`: complex response of a number, a SISO LTI or a callable at s = jω.
- :func:`check_grid`: validate a frequency grid (rad/s, > 0, strictly increasing).
- :func:`check_phases`: validate a phase grid in degrees (default −360…0 in 1° steps).
- :func:`grid_indices`: indices of given frequencies in a grid (exact up to rounding).

Frequencies in rad/s, phases in degrees.
"""
from __future__ import annotations

import numbers
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

if TYPE_CHECKING:  # annotations only
    import control


__all__ = ["DEFAULT_PHASES_DEG", "as_siso", "check_grid", "check_phases", "evaluate", "grid_indices", "is_lti",
           "is_zero"]

#: Default phase grid of QFT bounds, degrees: −360…0 in 1° steps (361 points).
DEFAULT_PHASES_DEG = np.linspace(-360.0, 0.0, 361)


def is_lti(obj: object) -> bool:
    """True if ``obj`` is a python-control LTI system (TransferFunction, StateSpace, FRD, ...).

    Parameters
    ----------
    obj : object
        Anything.

    Returns
    -------
    bool
        ``isinstance(obj, control.LTI)``; python-control is imported on first use.

    Examples
    --------
    >>> import control as ct
    >>> is_lti(ct.tf([1], [1, 1])), is_lti(2.0)
    (True, False)
    """
    import control as ct

    return isinstance(obj, ct.LTI)


def is_zero(sys: object) -> bool:
    """True if ``sys`` is the zero system: no states and a zero feedthrough (an absent loop).

    Parameters
    ----------
    sys : control.LTI
        A python-control LTI system.

    Returns
    -------
    bool
        Whether every response of ``sys`` is identically 0.

    Examples
    --------
    >>> import control as ct
    >>> is_zero(ct.tf([0.0], [1.0])), is_zero(ct.tf([1.0], [1.0, 1.0]))
    (True, False)
    """
    import control as ct

    s = ct.ss(sys)
    return s.nstates == 0 and not np.any(np.asarray(s.D))


def as_siso(sys: object, name: str = "system", *, proper: bool = True) -> "control.TransferFunction | control.StateSpace":
    """Make ``sys`` a SISO continuous-time python-control LTI, or raise naming ``name``.

    The one helper for "this argument must be a SISO LTI" checks. Contract:

    - a real finite number k (int, float, NumPy scalar; not bool) → ``control.tf(k, 1)``;
    - a SISO continuous-time ``control.TransferFunction`` or ``control.StateSpace`` is
      returned unchanged (the same object: no conversion, so no numerical change);
    - anything else is a ``TypeError`` naming ``name`` (e.g. a string, an array, a callable,
      a complex number, an FRD model);
    - a MIMO system, a discrete-time system (dt ≠ 0), a non-finite number or (with
      ``proper=True``) an improper transfer function (more zeros than poles) is a
      ``ValueError`` naming ``name``.

    Parameters
    ----------
    sys : float or control.TransferFunction or control.StateSpace
        The system (or static gain) to check.
    name : str
        Name of the argument in error messages.
    proper : bool
        Require a proper transfer function (a state space is always proper).

    Returns
    -------
    control.TransferFunction or control.StateSpace
        ``sys`` itself, or a static transfer function for a number.

    Raises
    ------
    TypeError
        If ``sys`` is neither a real number nor a python-control transfer function or state
        space.
    ValueError
        If ``sys`` is MIMO, discrete-time, improper (with ``proper``) or a non-finite number.

    Examples
    --------
    >>> import control as ct
    >>> as_siso(2.0).num[0][0]
    array([2.])
    >>> as_siso(ct.tf([1, 0, 0], [1, 1]), "controller")
    Traceback (most recent call last):
    ...
    ValueError: controller is improper (numerator degree 2 > denominator degree 1); add poles
    """
    import control as ct

    if isinstance(sys, (numbers.Real, np.integer, np.floating)) and not isinstance(sys, (bool, np.bool_)):
        k = float(sys)
        if not np.isfinite(k):
            raise ValueError(f"{name}={sys!r} must be a finite gain")
        return ct.tf([k], [1.0])
    if not isinstance(sys, (ct.TransferFunction, ct.StateSpace)):
        raise TypeError(f"{name} must be a number or a SISO python-control TransferFunction/StateSpace; "
                        f"got {type(sys).__name__}")
    if sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"{name} must be SISO, got {sys.noutputs}×{sys.ninputs}; select a channel, e.g. sys[out, in]")
    if sys.isdtime(strict=True):
        raise ValueError(f"{name} is discrete-time; loopshaping works with continuous-time models")
    if proper and isinstance(sys, ct.TransferFunction):
        num, den = np.trim_zeros(sys.num[0][0], "f"), np.trim_zeros(sys.den[0][0], "f")
        if len(num) > len(den):
            raise ValueError(f"{name} is improper (numerator degree {len(num) - 1} > denominator degree "
                             f"{len(den) - 1}); add poles")
    return sys


def evaluate(obj: object, omega: ArrayLike, name: str = "system") -> np.ndarray:
    """Complex response of ``obj`` at s = jω.

    Parameters
    ----------
    obj : float or control LTI or callable
        A number (a constant response), a SISO continuous-time python-control LTI, or a
        callable ``fn(omega)`` returning an array whose first axis runs over ``omega``.
    omega : array_like
        Frequencies, rad/s.
    name : str
        Name of ``obj`` in error messages.

    Returns
    -------
    numpy.ndarray
        Complex, shape (n_omega,) (a callable may return more axes after the first).
        A pole on the jω axis gives inf/nan without a warning (callers report it).

    Raises
    ------
    TypeError
        If ``obj`` is neither a number, an LTI nor a callable.
    ValueError
        If the LTI is MIMO or discrete-time, or a callable returns the wrong shape.

    Examples
    --------
    >>> import control as ct
    >>> evaluate(ct.tf([1], [1, 1]), [1.0])
    array([0.5-0.5j])
    """
    omega = np.asarray(omega, float)
    if isinstance(obj, numbers.Number):
        return np.full(omega.shape, complex(obj))
    if is_lti(obj):
        if obj.ninputs != 1 or obj.noutputs != 1:
            raise ValueError(f"{name} must be SISO; select a channel first, e.g. sys[out, in]")
        if obj.isdtime(strict=True):
            raise ValueError(f"{name} is discrete-time; loopshaping works with continuous-time models")
        import control as ct

        if isinstance(obj, ct.TransferFunction):
            num, den = obj.num[0][0], obj.den[0][0]
            s = 1j * omega
            with np.errstate(divide="ignore", invalid="ignore"):  # a pole on jω is reported by callers
                return np.polyval(num, s) / np.polyval(den, s)
        return np.asarray(obj(1j * omega), complex).reshape(omega.shape)
    if callable(obj):
        out = np.asarray(obj(omega), complex)
        if out.shape[:1] != omega.shape:
            raise ValueError(f"{name}(omega) must return an array whose first axis has length {omega.size}")
        return out
    raise TypeError(f"{name} must be a number, a SISO LTI system or a callable of ω; got {type(obj).__name__}")


def check_grid(omega: ArrayLike, name: str = "omega") -> np.ndarray:
    """Validate a frequency grid: non-empty, 1-D, finite, > 0 and strictly increasing.

    Parameters
    ----------
    omega : array_like
        Frequencies, rad/s (a scalar counts as a grid of one).
    name : str
        Name of the argument in error messages.

    Returns
    -------
    numpy.ndarray
        The grid as a 1-D float array.

    Raises
    ------
    ValueError
        Naming ``name`` and what is wrong (empty, not 1-D, non-finite, ≤ 0, unsorted).

    Examples
    --------
    >>> check_grid([0.1, 1.0, 10.0])
    array([ 0.1,  1. , 10. ])
    """
    w = np.atleast_1d(np.asarray(omega, float))
    if w.ndim != 1 or w.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D array of frequencies in rad/s")
    if not np.all(np.isfinite(w)) or np.any(w <= 0):
        raise ValueError(f"{name} must be finite and > 0 (rad/s)")
    if np.any(np.diff(w) <= 0):
        raise ValueError(f"{name} must be strictly increasing; sort it (np.unique)")
    return w


def check_phases(phases_deg: ArrayLike | None = None, name: str = "phases_deg") -> np.ndarray:
    """Validate a phase grid in degrees; None gives :data:`DEFAULT_PHASES_DEG`.

    Parameters
    ----------
    phases_deg : array_like or None
        Phases of the open loop, degrees, strictly increasing, at least two.
    name : str
        Name of the argument in error messages.

    Returns
    -------
    numpy.ndarray
        The phases as a 1-D float array (a copy of the default for None).

    Raises
    ------
    ValueError
        If the grid is not a strictly increasing 1-D array of ≥ 2 finite phases.

    Examples
    --------
    >>> check_phases().shape
    (361,)
    """
    if phases_deg is None:
        return DEFAULT_PHASES_DEG.copy()
    p = np.atleast_1d(np.asarray(phases_deg, float))
    if p.ndim != 1 or p.size < 2 or not np.all(np.isfinite(p)) or np.any(np.diff(p) <= 0):
        raise ValueError(f"{name} must be a strictly increasing 1-D array of ≥ 2 finite phases in degrees")
    return p


def grid_indices(grid: np.ndarray, values: ArrayLike, name: str = "omega") -> np.ndarray:
    """Indices of ``values`` in the sorted frequency grid ``grid`` (equal up to 1e-9 relative).

    Parameters
    ----------
    grid : numpy.ndarray
        Sorted frequencies, rad/s.
    values : array_like
        Frequencies to look up, rad/s; each must be in ``grid``.
    name : str
        Name of ``values`` in error messages.

    Returns
    -------
    numpy.ndarray
        Integer indices, shape of ``np.atleast_1d(values)``.

    Raises
    ------
    ValueError
        If a value is not (within 1e-9 relative) a frequency of ``grid``.

    Examples
    --------
    >>> grid_indices(np.array([0.1, 1.0, 10.0]), [10.0, 0.1])
    array([2, 0])
    """
    values = np.atleast_1d(np.asarray(values, float))
    idx = np.searchsorted(grid, values)
    idx = np.clip(idx, 0, len(grid) - 1)
    lower = np.clip(idx - 1, 0, len(grid) - 1)
    idx = np.where(np.abs(grid[lower] - values) < np.abs(grid[idx] - values), lower, idx)
    bad = ~np.isclose(grid[idx], values, rtol=1e-9, atol=0)
    if np.any(bad):
        raise ValueError(f"{name}={values[bad].tolist()} rad/s are not design frequencies {grid.tolist()}")
    return idx
