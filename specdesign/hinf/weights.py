"""Weights of the H∞ design: W⁻¹ of a fatigue-based specification as a stable, proper, minimum-phase
system (:func:`inverse_weight`), and the one conversion of a specification or weight to a SISO LTI.

Units: frequencies in rad/s; a specification W is in output units per m/s of rotor-effective
wind (N·m per m/s for the tower-base moment, rad/s per m/s for the generator speed), W⁻¹ in
m/s per output unit.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import control as ct
import numpy as np

from loopshaping.freqresp import as_siso

if TYPE_CHECKING:
    from ..spec import Specification

__all__ = ['DEFAULT_MIN_DAMPING', 'siso_weight', 'inverse_weight']

#: Damping floor (ratio) of the specifications' zeros in the weights, see :func:`inverse_weight`.
DEFAULT_MIN_DAMPING = 0.05


def siso_weight(sys: Specification | ct.LTI | float, name: str) -> ct.TransferFunction:
    """A specification or weight as a SISO continuous-time transfer function.

    ``sys`` (a :class:`specdesign.spec.Specification` or a SISO continuous-time LTI) as a
    TransferFunction; TypeError/ValueError name ``name``.

    Parameters
    ----------
    sys : specdesign.spec.Specification, control.LTI or float
        The specification (its :meth:`~specdesign.spec.Specification.tf`), a SISO
        continuous-time system or a constant gain (output units per input unit).
    name : str
        Name of the argument, used in the error messages.

    Returns
    -------
    control.TransferFunction
        ``sys`` as a SISO transfer function (proper or not).

    Raises
    ------
    TypeError
        If ``sys`` is neither a specification, an LTI system nor a number.
    ValueError
        If ``sys`` is not SISO or is discrete-time.

    Examples
    --------
    >>> import control as ct
    >>> from specdesign.hinf import siso_weight
    >>> siso_weight(ct.ss(-1.0, 1.0, 1.0, 0.0), "w_pitch").den[0][0]
    array([1., 1.])
    """
    from ..spec import Specification

    if isinstance(sys, Specification):
        sys = sys.tf()
    return ct.tf(as_siso(sys, name, proper=False))


def _cascade(zeros, poles, gain):
    """Biproper zpk → StateSpace as a cascade of second-order sections (better conditioned
    than one high-degree polynomial when the roots span decades)."""

    def sections(roots):
        roots = np.asarray(roots, dtype=complex)
        tol = 1e-9 * np.maximum(1.0, np.abs(roots))
        upper = roots[roots.imag > tol]
        real = np.sort(roots[np.abs(roots.imag) <= tol].real)
        out = [np.array([1.0, -2 * r.real, abs(r) ** 2]) for r in upper]
        out += [np.poly(real[i:i + 2]) for i in range(0, real.size, 2)]
        return sorted(out, key=len, reverse=True)

    num, den = sections(zeros), sections(poles)
    if [len(q) for q in num] != [len(q) for q in den]:
        raise ValueError("zeros and poles must pair into sections of equal degree (biproper)")
    sys = ct.ss([], [], [], [[float(gain)]])
    for nm, d in zip(num, den):
        sys = ct.series(sys, ct.ss(ct.tf(nm, d)))
    return sys


def inverse_weight(specification: Specification | ct.LTI, *, rolloff: float = 10.0, shift: float = 1e-3,
                   min_damping: float = 0.0, name: str = "specification") -> tuple[ct.StateSpace, tuple[str, ...]]:
    """A stable, proper, minimum-phase W⁻¹ with |W⁻¹(jω)| = 1/|W(jω)| below ``rolloff``.

    Zeros of W in the right half-plane are reflected (same magnitude on the jω axis), zeros
    on the axis (e.g. the zero at s = 0 of a T_{Ω,w} with integral action) are moved to
    Re = −``shift`` rad/s, and the relative degree r of W is compensated by r poles at
    −``rolloff`` rad/s, so the weight gives up the specification above ``rolloff``.

    Parameters
    ----------
    specification : specdesign.spec.Specification or SISO LTI
        W(s), stable and proper (output units per m/s of wind).
    rolloff : float
        Frequency of the poles that compensate W's relative degree, rad/s (> 0).
    shift : float
        Distance the zeros of W on the imaginary axis are moved into the left half-plane,
        rad/s (> 0).
    min_damping : float
        Zeros of W with damping ratio below this (a narrow dip of the specification, such
        as the one ROSCO's T_{Ω,w} has at the tower mode) are given this damping at the same
        |z|: W⁻¹ then caps its resonant peak there (relaxes the weight in that narrow band)
        instead of asking the synthesis to track a 40 dB spike, which it does by copying the
        dip into a lightly damped closed-loop pole pair. 0 keeps every zero.
    name : str
        Name of the specification in the notes and the error messages.

    Returns
    -------
    inverse : control.StateSpace
        W⁻¹ (m/s of wind per output unit), a cascade of second-order sections.
    notes : tuple of str
        Notes on what was modified (reflected, shifted or damped zeros, roll-off).

    Raises
    ------
    TypeError
        If ``specification`` is neither a specification nor an LTI system.
    ValueError
        If W is not SISO, is discrete-time, identically zero, unstable (a pole with
        Re ≥ 0) or improper; if ``rolloff`` or ``shift`` is not a positive frequency; or if
        ``min_damping`` is not in [0, 1).

    Examples
    --------
    >>> import control as ct
    >>> from specdesign.hinf import inverse_weight
    >>> inv, notes = inverse_weight(ct.tf([2.0, 0.0], [1.0, 1.0]), name="w_speed")  # W = 2s/(s + 1)
    >>> notes
    ('w_speed: 1 zero(s) on the imaginary axis moved to Re = −0.001 rad/s',)
    >>> round(abs(complex(inv(1j))), 4)  # 1/|W(j·1)| = 0.7071
    0.7071
    """
    W = siso_weight(specification, name)
    for k, v in (("rolloff", rolloff), ("shift", shift)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"{k}={v!r} must be a positive frequency in rad/s")
    num = np.trim_zeros(np.asarray(W.num[0][0], dtype=float), "f")
    den = np.trim_zeros(np.asarray(W.den[0][0], dtype=float), "f")
    if num.size == 0:
        raise ValueError(f"{name} is identically zero: it cannot be inverted into a weight")
    poles, zeros = np.roots(den), np.roots(num)
    if np.any(poles.real >= 0):
        raise ValueError(
            f"{name} has poles with Re ≥ 0 ({poles[poles.real >= 0]}): a specification must be "
            "stable (build it from a stabilising baseline)"
        )
    r = poles.size - zeros.size
    if r < 0:
        raise ValueError(f"{name} is improper (more zeros than poles); specifications must be proper")
    notes = []
    rhp = zeros.real > 1e-9 * np.maximum(1.0, np.abs(zeros))
    axis = np.abs(zeros.real) <= 1e-9 * np.maximum(1.0, np.abs(zeros))
    if rhp.any():
        notes.append(f"{name}: {rhp.sum()} right-half-plane zero(s) reflected (magnitude kept)")
    if axis.any():
        notes.append(
            f"{name}: {axis.sum()} zero(s) on the imaginary axis moved to Re = −{shift:g} rad/s"
        )
    z = np.where(rhp, -zeros.conj(), zeros)
    z = np.where(axis, z - shift, z)
    if not (np.isfinite(min_damping) and 0 <= min_damping < 1):
        raise ValueError(f"min_damping={min_damping!r} must be in [0, 1)")
    osc = np.abs(z.imag) > 1e-9 * np.maximum(1.0, np.abs(z))
    light = osc & (-z.real < min_damping * np.abs(z))
    if light.any():
        mag = np.abs(z[light])
        z = z.copy()
        z[light] = mag * (-min_damping + 1j * np.sign(z[light].imag) * np.sqrt(1 - min_damping**2))
        notes.append(
            f"{name}: {light.sum()} lightly damped zero(s) near "
            f"{', '.join(f'{w:.3g}' for w in np.unique(np.round(mag, 4)))} rad/s given damping "
            f"{min_damping:g} (the weight is capped there; the check uses the true specification)"
        )
    if r:
        notes.append(f"{name}: relative degree {r} rolled off by poles at −{rolloff:g} rad/s")
    gain = rolloff**r * den[0] / num[0]
    inv = _cascade(poles, np.concatenate([z, np.full(r, -float(rolloff))]), gain)
    return inv, tuple(notes)
