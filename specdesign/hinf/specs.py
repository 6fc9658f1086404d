"""The one kind of specification :func:`specdesign.hinf.design_hinf` takes, and the named
functions that make it from a DEL target, a certified pair, a QFT design, a pair of transfer
functions, QFT's notch rules or ROSCO's closed loop.

Units: ω in rad/s, wind speed in m/s, reductions in %, relaxations in dB. W_MyT is in N·m per
m/s (wind → tower-base fore-aft moment), W_Ω in rad/s per m/s (wind → generator speed).
"""
from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import control as ct
import numpy as np
from numpy.typing import ArrayLike

from .. import spec as sp
from ..fatigue import TOWER_M
from ..feasibility import MAX_HF_GAIN_RATIO, TargetSpecification, specification_for_target
from ..feasibility.target import TARGET_REDUCTION
from ..qft.specs import SPEED_RELAX_DB

if TYPE_CHECKING:
    from ..spec import Specification
    from ..turbine import TurbineModel

__all__ = ["HinfSpecification", "spec_for_target", "spec_from_certified", "spec_from_pair", "spec_from_qft",
           "spec_like_qft", "spec_from_rosco"]

#: The kinds of :class:`HinfSpecification`, one per function that makes one.
KINDS = ("target", "given", "qft_design", "qft", "rosco")


@dataclass(frozen=True)
class HinfSpecification:
    """The specifications an H∞ design is weighted with and assessed against.

    Made by :func:`spec_for_target` (the default of :func:`specdesign.hinf.design_hinf`),
    :func:`spec_from_certified`, :func:`spec_from_pair`, :func:`spec_from_qft`,
    :func:`spec_like_qft` or :func:`spec_from_rosco`.

    Parameters
    ----------
    kind : str
        Where the pair comes from: "target" (made for a DEL target), "given" (a certified pair
        or a pair of transfer functions handed over), "qft_design" (the pair a QFT design met),
        "qft" (QFT's notch rules, a ladder of speed relaxations) or "rosco" (the unrelaxed notch
        spec and ROSCO's T_{Ω,w}). ``HinfDesign.specs`` reports it.
    pairs : tuple of (W_MyT, W_Ω)
        The pairs tried in turn, smallest speed relaxation first (one pair except for a ladder):
        each a :class:`specdesign.spec.Specification` or SISO LTI; the first whose reduced
        design meets both on the refined grid is kept, else the last.
    speed_relax_db : tuple of float
        The relaxation of ROSCO's T_{Ω,w} in each pair's W_Ω, dB (nan when unknown).
    notch : specdesign.spec.Specification or None
        The unrelaxed notch specification whose promise is reported beside the relaxed one
        (None: the tower specification itself).
    target : specdesign.feasibility.TargetSpecification or None
        The certified pair, when the specification is one: with pitch only the design then
        meets it at every plant case it was certified on (:func:`specdesign.hinf.refine_on_cases`).
    wind_speed : float
        The operating point the pair was made at, m/s (nan for a pair that does not say):
        :func:`specdesign.hinf.design_hinf` refuses it at another speed.
    """

    kind: str
    pairs: tuple[tuple[Any, Any], ...]
    speed_relax_db: tuple[float, ...]
    notch: Specification | None = None
    target: TargetSpecification | None = None
    wind_speed: float = float("nan")

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"kind={self.kind!r} must be one of {KINDS}")
        if not self.pairs or len(self.pairs) != len(self.speed_relax_db):
            raise ValueError(f"pairs ({len(self.pairs)}) and speed_relax_db ({len(self.speed_relax_db)}) must have "
                             "the same number (≥ 1) of entries")

    @property
    def tower(self):
        """W_MyT of the first pair, N·m per m/s."""
        return self.pairs[0][0]

    @property
    def speed(self):
        """W_Ω of the first pair, rad/s per m/s."""
        return self.pairs[0][1]


def _checked_pair(tower, speed):
    """(W_MyT, W_Ω), each a specification with ``response(omega)`` or a SISO LTI."""
    for name, w in (("tower", tower), ("speed", speed)):
        if not (hasattr(w, "response") or isinstance(w, ct.LTI)):
            raise TypeError(f"{name} must be a specdesign.spec.Specification or a SISO control.LTI, "
                            f"got {type(w).__name__}")
    return tower, speed


def spec_from_certified(target: TargetSpecification, *, kind: str = "given") -> HinfSpecification:
    """The H∞ specification of a certified pair (made beforehand by
    :func:`specdesign.feasibility.specification_for_target`).

    Parameters
    ----------
    target : specdesign.feasibility.TargetSpecification
        The pair, its promise and the plant cases it is certified on.
    kind : {"given", "target"}
        The label: "given" for a pair handed over, "target" when made for the design
        (:func:`spec_for_target`).

    Returns
    -------
    HinfSpecification
        One pair, ``target`` set (with pitch only the design meets it at every plant case).

    Raises
    ------
    TypeError
        If ``target`` is not a TargetSpecification.

    Examples
    --------
    >>> from specdesign import feasibility, hinf, turbine
    >>> ts = feasibility.specification_for_target(turbine.iea15mw(), 19.0, 25.0)  # doctest: +SKIP
    >>> hinf.spec_from_certified(ts).kind  # doctest: +SKIP
    'given'
    """
    if not isinstance(target, TargetSpecification):
        raise TypeError(f"target must be a feasibility.TargetSpecification, got {type(target).__name__}; "
                        "a pair of transfer functions is hinf.spec_from_pair(tower, speed)")
    # speed_relax_db nan: the certificate sets the pair's relaxation (target.speed_relax_db), not a ladder
    return HinfSpecification(kind, ((target.tower, target.speed),), (float("nan"),),
                             target=target, wind_speed=float(target.wind_speed))


def spec_for_target(model: TurbineModel, wind_speed: float, target_reduction: float = TARGET_REDUCTION, *,
                    m: float = TOWER_M, max_hf_gain_ratio: float | None = MAX_HF_GAIN_RATIO) -> HinfSpecification:
    """The certified pair for a tower-base DEL target, as :func:`specdesign.qft.design_qft` makes it.

    :func:`specdesign.feasibility.specification_for_target` (certified over the plant cases
    around ``wind_speed``), labelled "target".

    Parameters
    ----------
    model, wind_speed : specdesign.turbine.TurbineModel, float
        The turbine and the operating point (m/s) the pair is made and certified at.
    target_reduction : float
        The DEL target: tower-base DEL reduction (1 Hz, m = ``m``) vs ROSCO, % (0-100).
    m : float
        Wöhler exponent of the tower-base S-N curve on ranges (-).
    max_hf_gain_ratio : float or None
        κ of the certificate's high-frequency gain bound (:func:`specification_for_target`;
        default the measured κ, on); None: no bound.

    Returns
    -------
    HinfSpecification
        Kind "target".

    Raises
    ------
    ValueError
        If ``target_reduction`` is not in (0, 100) %, or no certified pair reaches it.

    Examples
    --------
    >>> from specdesign import hinf, turbine
    >>> hinf.spec_for_target(turbine.iea15mw(), 19.0).kind  # doctest: +SKIP
    'target'
    """
    try:
        reduction = float(target_reduction)
    except (TypeError, ValueError):
        reduction = float("nan")
    if not 0 < reduction < 100:
        raise ValueError(f"target_reduction={target_reduction!r} must be a DEL reduction in % (0-100)")
    return spec_from_certified(specification_for_target(model, wind_speed, reduction, m=m,
                                                        max_hf_gain_ratio=max_hf_gain_ratio), kind="target")


def spec_from_pair(tower: Specification | ct.LTI, speed: Specification | ct.LTI, *,
                   wind_speed: float | None = None) -> HinfSpecification:
    """The H∞ specification of a given pair (W_MyT, W_Ω), labelled "given".

    The design is assessed against the pair as given (a warning says where it is not met);
    no plant case is checked (:func:`spec_from_certified` does, for a certified pair).

    Parameters
    ----------
    tower : specdesign.spec.Specification or SISO control.LTI
        W_MyT, N·m per m/s.
    speed : specdesign.spec.Specification or SISO control.LTI
        W_Ω, rad/s per m/s.
    wind_speed : float, optional
        The operating point the pair was made at, m/s (the design refuses it at another one).

    Returns
    -------
    HinfSpecification
        Kind "given", one pair.

    Raises
    ------
    TypeError
        If either is neither a specification nor an LTI system.

    Examples
    --------
    >>> from specdesign import hinf, spec, turbine
    >>> ds = spec.design_specifications(turbine.iea15mw(), 19.0)
    >>> hinf.spec_from_pair(ds.tower, ds.speed, wind_speed=19.0).kind
    'given'
    """
    return HinfSpecification("given", (_checked_pair(tower, speed),), (float("nan"),),
                             wind_speed=float("nan") if wind_speed is None else float(wind_speed))


def spec_from_qft(design: Any) -> HinfSpecification:
    """Exactly the specifications a QFT design met, for a comparison on the same pair.

    Parameters
    ----------
    design : specdesign.qft.QFTDesign
        A design of :func:`specdesign.qft.design_qft`: its ``tower_spec``, ``speed_spec``,
        ``shaping.specification`` (the unrelaxed notch spec) and ``options["speed_relax_db"]``.

    Returns
    -------
    HinfSpecification
        Kind "qft_design", one pair.

    Raises
    ------
    TypeError
        If ``design`` is not a design record carrying its specifications.

    Examples
    --------
    >>> from specdesign import hinf, qft, turbine
    >>> q = qft.design_qft(turbine.iea15mw(), 19.0, spec=qft.spec_notch(25.0))  # doctest: +SKIP
    >>> hinf.spec_from_qft(q).kind  # doctest: +SKIP
    'qft_design'
    """
    if not all(hasattr(design, k) for k in ("tower_spec", "speed_spec", "shaping", "options", "wind_speed")):
        raise TypeError(f"design must be a specdesign.qft.QFTDesign (its tower_spec, speed_spec, shaping, options), "
                        f"got {type(design).__name__}")
    return HinfSpecification("qft_design", ((design.tower_spec, design.speed_spec),),
                             (float(design.options.get("speed_relax_db", np.nan)),),
                             notch=design.shaping.specification, wind_speed=float(design.wind_speed))


def spec_like_qft(model: TurbineModel, wind_speed: float, *, speed_relax_db: float | Sequence[float] = SPEED_RELAX_DB,
                  spec_reduction: float = sp.SPEC_REDUCTION, tower_relax_db: float = sp.TOWER_RELAX_DB,
                  tower_relax_omega: float = sp.TOWER_RELAX_OMEGA,
                  m: float = TOWER_M, omega: ArrayLike | None = None) -> HinfSpecification:
    """QFT's notch specifications (those of ``design_qft(spec=qft.spec_notch(...))``), one pair per relaxation.

    Built as :func:`specdesign.spec.design_specifications` builds them for QFT: W_MyT is ROSCO's
    T_{MyT,w} × the notches of :func:`specdesign.spec.shape_to_target` × two leads relaxing it by
    ``tower_relax_db`` above ≈ ``tower_relax_omega`` (where ΔD% is negligible; they already lift
    it by ≈ 1.9 dB at the tower mode, 1.06 rad/s, with the defaults), and W_Ω is ROSCO's T_{Ω,w}
    relaxed by each of ``speed_relax_db`` (its ζ = 0.01 dip at the tower mode kept). The design
    tries the pairs in turn and keeps the smallest relaxation whose reduced design meets both
    specs on the refined grid (speed everywhere, tower over the tower-mode band), as QFT does.

    Parameters
    ----------
    model, wind_speed : specdesign.turbine.TurbineModel, float
        The turbine and its operating point (m/s).
    speed_relax_db : float or sequence of float
        Relaxation(s) of ROSCO's T_{Ω,w}, dB (≥ 0), tried in the order given (default
        :data:`specdesign.qft.SPEED_RELAX_DB`, QFT's ladder).
    spec_reduction, tower_relax_db, tower_relax_omega : float
        The notch specification's promise (% of tower-base damage), the tower spec's
        high-frequency relaxation (dB) and its corner (rad/s).
    m : float
        Wöhler exponent of the tower-base S-N curve on ranges (-).
    omega : array_like, optional
        Frequency grid of the baseline analysis, rad/s (default :func:`specdesign.spec.default_omega`).

    Returns
    -------
    HinfSpecification
        Kind "qft", one pair per relaxation; ``notch`` the unrelaxed notch spec (whose promise
        ``shape_to_target`` reports).

    Raises
    ------
    ValueError
        If ``speed_relax_db`` is not a relaxation ≥ 0 dB or a sequence of them, a relaxation or
        corner is invalid, ``wind_speed`` is outside ``model.wind_range``, or no notch
        specification reaches ``spec_reduction`` at this wind speed.

    Examples
    --------
    >>> from specdesign import hinf, turbine
    >>> s = hinf.spec_like_qft(turbine.iea15mw(), 19.0)  # doctest: +SKIP
    >>> s.kind, s.speed_relax_db, s.speed.elements  # doctest: +SKIP
    ('qft', (3.0, 4.5, 6.0, 8.0), (Gain(gain_db=3.0),))
    """
    ladder = np.atleast_1d(np.asarray(speed_relax_db, float))
    if ladder.ndim != 1 or ladder.size == 0 or not np.all(np.isfinite(ladder)) or np.any(ladder < 0):
        raise ValueError(f"speed_relax_db={speed_relax_db!r} must be a relaxation ≥ 0 dB or a sequence of them")
    relax = tuple(float(x) for x in ladder)
    ds = sp.design_specifications(model, wind_speed, speed_relax_db=relax[0], spec_reduction=spec_reduction,
                                  tower_relax_db=tower_relax_db, tower_relax_omega=tower_relax_omega, m=m, omega=omega)
    if not ds.shaping.success:
        raise ValueError(f"no tower specification at {float(wind_speed):g} m/s: {ds.shaping.message}")
    tower, notch = ds.tower, ds.shaping.specification
    # the tower spec does not depend on the speed relaxation: one per rung, as design_specifications builds it
    pairs = tuple((tower, sp.speed_specification(model, float(wind_speed), margin_db=r)) for r in relax)
    return HinfSpecification("qft", pairs, relax, notch=notch, wind_speed=float(wind_speed))


def spec_from_rosco(model: TurbineModel, wind_speed: float, *, spec_reduction: float = sp.SPEC_REDUCTION, m: float = TOWER_M,
                    omega: ArrayLike | None = None) -> HinfSpecification:
    """The unrelaxed notch specification and ROSCO's T_{Ω,w}: design_hinf's default before QFT's.

    ROSCO's T_{Ω,w} dips at the tower mode (ζ ≈ 0.01): a spec no well-damped loop can follow
    (docs/hinf.md), kept for the comparison.

    Parameters
    ----------
    model : specdesign.turbine.TurbineModel
        The turbine, linearised at ``wind_speed`` (m/s, a float).
    wind_speed : float
        See ``model``.
    spec_reduction : float
        What the notches promise, % of tower-base damage (:func:`specdesign.spec.shape_to_target`).
    m : float
        The S-N curve's Wöhler exponent (tower base, ranges).
    omega : array_like, optional
        The baseline analysis' grid (rad/s); default :func:`specdesign.spec.default_omega`.

    Returns
    -------
    HinfSpecification
        Kind "rosco", one pair, speed relaxation 0 dB.

    Raises
    ------
    ValueError
        If no notch specification reaches ``spec_reduction`` at this wind speed.

    Examples
    --------
    >>> from specdesign import hinf, turbine
    >>> hinf.spec_from_rosco(turbine.iea15mw(), 19.0).speed_relax_db  # doctest: +SKIP
    (0.0,)
    """
    v = model.check_wind_speed(wind_speed)
    base = sp.baseline_analysis(model, v, m=m, omega=omega)
    with warnings.catch_warnings():  # the shaper's trial notches (log of 0 at a notch centre)
        warnings.simplefilter("ignore", RuntimeWarning)
        shaped = sp.shape_to_target(base, spec_reduction)
    if not shaped.success:
        raise ValueError(f"no tower specification at {v:g} m/s: {shaped.message}")
    notch = shaped.specification
    return HinfSpecification("rosco", ((notch, sp.speed_specification(model, v)),), (0.0,), notch=notch,
                             wind_speed=v)
