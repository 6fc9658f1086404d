"""The one kind of specification :func:`specdesign.qft.design_qft` takes, and the named functions
that make it from a certified pair, a pair of transfer functions, or QFT's notch rules and a DEL
target.

Without a specification :func:`~specdesign.qft.design_qft` makes the certified pair for its
``target_reduction`` itself (:func:`specdesign.feasibility.specification_for_target`), as
:func:`specdesign.hinf.design_hinf` does; these functions mirror :mod:`specdesign.hinf.specs`.

Units: wind speed in m/s, reductions in %, relaxations in dB. W_MyT is in N·m per m/s (wind →
tower-base fore-aft moment), W_Ω in rad/s per m/s (wind → generator speed).
"""
from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._checks import del_target
from ..feasibility import TargetSpecification
from ..feasibility.target import TARGET_REDUCTION

if TYPE_CHECKING:
    from ..spec import Specification

__all__ = ["QFTSpecification", "SPEED_RELAX_DB", "spec_from_certified", "spec_from_pair", "spec_notch"]

#: Relaxations (dB) of the generator-speed spec the notch design (:func:`spec_notch`) tries in turn,
#: smallest first: ROSCO's T_{Ω,w} dips at the tower mode where a well-damped loop cannot follow
#: it, and 3 dB is the least that the IEA 15 MW designs met; hinf.spec_like_qft uses the same.
SPEED_RELAX_DB = (3.0, 4.5, 6.0, 8.0)

#: The kinds of :class:`QFTSpecification`, one per function that makes one.
KINDS = ("certified", "pair", "notch")


@dataclass(frozen=True)
class QFTSpecification:
    """The specification a QFT design meets.

    Made by :func:`spec_from_certified` (a certified pair), :func:`spec_from_pair` (a pair of
    transfer functions) or :func:`spec_notch` (QFT's notch rules and a DEL target); without one
    :func:`specdesign.qft.design_qft` makes the certified pair for its ``target_reduction``.

    Parameters
    ----------
    kind : {"certified", "pair", "notch"}
        Where the specification comes from: a certified pair (its certificate, reduced, is the
        default controller), a pair handed over (met by the fixed structures, no DEL penalty),
        or the notch rules (the fixed structures tuned against the notch specification made at
        the design speed, with a DEL-target penalty, for each speed relaxation in turn).
    tower, speed : specdesign.spec.Specification or None
        W_MyT (N·m per m/s) and W_Ω (rad/s per m/s); None for "notch" (made at the design's
        speed, one W_Ω per relaxation).
    target : specdesign.feasibility.TargetSpecification or None
        The certified pair ("certified" only): its promise, certificate and plant cases.
    target_reduction : float
        "notch" only: the predicted tower-base DEL reduction (1 Hz, m = 4) vs ROSCO the tuner
        must reach, % (nan otherwise: a pair carries its own promise).
    speed_relax_db : tuple of float
        "notch" only: the relaxations of ROSCO's T_{Ω,w} tried in turn, dB, increasing (empty
        otherwise).
    wind_speed : float
        The operating point the pair was made at, m/s (nan when it does not say):
        :func:`specdesign.qft.design_qft` refuses it at another speed.
    """

    kind: str
    tower: Any = None
    speed: Any = None
    target: TargetSpecification | None = None
    target_reduction: float = float("nan")
    speed_relax_db: tuple[float, ...] = ()
    wind_speed: float = float("nan")

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} must be one of {KINDS}")
        if (self.kind == "notch") != (self.tower is None):
            raise ValueError("a 'notch' specification has no pair (it is made at the design speed); the others have one")


def spec_from_certified(target: TargetSpecification) -> QFTSpecification:
    """The QFT specification of a certified pair (made beforehand by
    :func:`specdesign.feasibility.specification_for_target`, or a shaper's ``certified``).

    The design then meets the pair at every plant case it was certified on: by default the
    certificate reduced to the lowest order that does (``structure="certificate"``).

    Parameters
    ----------
    target : specdesign.feasibility.TargetSpecification
        The pair, its promise and the plant cases it is certified on.

    Returns
    -------
    QFTSpecification
        Kind "certified", made at ``target.wind_speed``.

    Raises
    ------
    TypeError
        For anything but a TargetSpecification (a bare pair is :func:`spec_from_pair`'s).

    Examples
    --------
    >>> from specdesign import feasibility, qft, turbine
    >>> model = turbine.iea15mw()
    >>> s = qft.spec_from_certified(feasibility.specification_for_target(model, 19.0, 25.0))  # doctest: +SKIP
    >>> d = qft.design_qft(model, 19.0, spec=s)  # the certificate, reduced  # doctest: +SKIP
    """
    if not isinstance(target, TargetSpecification):
        raise TypeError(f"target must be a feasibility.TargetSpecification, got {type(target).__name__}; "
                        "a pair of transfer functions is qft.spec_from_pair(tower, speed)")
    return QFTSpecification("certified", target.tower, target.speed, target=target, wind_speed=float(target.wind_speed))


def spec_from_pair(tower: Specification, speed: Specification, *, wind_speed: float | None = None) -> QFTSpecification:
    """The QFT specification of a given pair (W_MyT, W_Ω), met by the fixed structures.

    Each plant case gets ROSCO's map at its speed times the nominal ratio W/T^ROSCO; no DEL
    penalty is used (the pair carries the target: its promise).

    Parameters
    ----------
    tower : specdesign.spec.Specification
        W_MyT, N·m per m/s: any object with ``response(omega)`` (ω in rad/s).
    speed : specdesign.spec.Specification
        W_Ω, rad/s per m/s, the same.
    wind_speed : float, optional
        The operating point the pair was made at, m/s (the design refuses it at another one).

    Returns
    -------
    QFTSpecification
        Kind "pair".

    Raises
    ------
    TypeError
        If either has no ``response(omega)``.

    Examples
    --------
    A tower specification 3 dB above ROSCO's map everywhere, with the notch design's speed spec:

    >>> from specdesign import qft, spec, turbine
    >>> ds = spec.design_specifications(turbine.iea15mw(), 19.0)
    >>> s = qft.spec_from_pair(spec.Specification(ds.base.system, (spec.Gain(3.0),)), ds.speed, wind_speed=19.0)
    >>> s.kind, s.tower.elements
    ('pair', (Gain(gain_db=3.0),))
    """
    for name, w in (("tower", tower), ("speed", speed)):
        if not hasattr(w, "response"):
            raise TypeError(f"{name} must be a specification with response(omega) (e.g. specdesign.spec.Specification), "
                            f"got {type(w).__name__}")
    return QFTSpecification("pair", tower, speed, wind_speed=float("nan") if wind_speed is None else float(wind_speed))


def spec_notch(target_reduction: float = TARGET_REDUCTION, *,
               speed_relax_db: float | Sequence[float] = SPEED_RELAX_DB) -> QFTSpecification:
    """QFT's notch specification and a DEL target: the fixed-structure design of the seed paper.

    At the design speed the tower spec is ROSCO's T_{MyT,w} × the notches of
    :func:`specdesign.spec.shape_to_target` × two leads relaxing it at high frequency, and the
    speed spec ROSCO's T_{Ω,w} relaxed by each of ``speed_relax_db`` in turn
    (:func:`specdesign.spec.design_specifications`; the design options ``spec_reduction``,
    ``tower_relax_db``, ``tower_relax_omega`` and ``keep_below`` of
    :func:`specdesign.qft.design_qft` shape them); the fixed structures are tuned against them
    with a penalty on a predicted DEL reduction below ``target_reduction``. The design with the
    smallest relaxation that meets every spec is kept (else the last, with a warning).
    :func:`specdesign.hinf.spec_like_qft` builds the same pairs for H∞.

    Parameters
    ----------
    target_reduction : float
        Predicted tower-base DEL reduction (1 Hz, m = 4) vs ROSCO the tuner must reach, %
        (strictly between 0 and 100).
    speed_relax_db : float or sequence of float
        Relaxation of the generator-speed spec, dB (≥ 0), or an increasing sequence tried in turn.

    Returns
    -------
    QFTSpecification
        Kind "notch".

    Raises
    ------
    ValueError
        If ``target_reduction`` is not strictly between 0 and 100 %, or a relaxation is
        negative or not finite, or the sequence does not increase.

    Examples
    --------
    >>> from specdesign import qft
    >>> s = qft.spec_notch(25.0)
    >>> s.kind, s.speed_relax_db
    ('notch', (3.0, 4.5, 6.0, 8.0))
    """
    target = del_target(target_reduction)
    ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
    if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
    if np.any(np.diff(ladder) <= 0):  # the first that works is kept: a ladder out of order would skip a smaller one
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must increase (dB): the smallest relaxation that works is kept")
    return QFTSpecification("notch", target_reduction=target, speed_relax_db=tuple(float(x) for x in ladder))
