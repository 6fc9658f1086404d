"""The certified whole-band tower specification for a target, from a baseline: :func:`shape_whole_band`.

The specification-side counterpart of :func:`specdesign.spec.shape_to_target` (the seed
paper's notches above a protected band, no feasibility guarantee): the same baseline in, the
same :class:`~specdesign.spec.ShapingResult` out, but shaped over the whole band with
:func:`~specdesign.feasibility.element_specification` and certified at every plant case.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .. import spectral
from .elements import MAX_NOTCHES, element_specification

if TYPE_CHECKING:  # pragma: no cover
    from ..spec import Baseline, ShapingResult

__all__ = ["shape_whole_band"]


def shape_whole_band(base: Baseline, target_reduction: float, *, quantity: str = "del", max_notches: int = MAX_NOTCHES,
                     **certify_options: Any) -> ShapingResult:
    """Shape the certified whole-band tower specification that promises a target reduction.

    The specification-driven design (use it when the specification is to be handed to
    a design): the whole band where ΔD% pays, below the tower mode too, with the
    generator-speed specification as the constraint that protects power regulation and
    Bode's cost inside the specification, as ROSCO's map × a gain, a lag, a lead and
    notches/bumps whose number and places are chosen with exact Dirlik in the constraint,
    certified at every plant case: :func:`~specdesign.feasibility.element_specification` on
    the baseline's model and wind speed (the baseline must come from
    :func:`specdesign.spec.baseline_analysis` of ``tower_base_my`` with ROSCO and the default
    wind). The promise reported is that of the specification handed to the design;
    ``certified`` is the pair to give
    ``design_qft(model, v, spec=qft.spec_from_certified(res.certified))``, or to edit by hand
    (``res.certified.tower.add(Notch(...))``) and re-check with :func:`~specdesign.feasibility.recertify`.

    Parameters
    ----------
    base : specdesign.spec.Baseline
        From :func:`specdesign.spec.baseline_analysis` (it carries its model).
    target_reduction : float
        Requested reduction in percent (0 < target < 100) of ``quantity``.
    quantity : {"del", "damage"}
        Whether the target is a reduction of DEL at 1 Hz or of damage (certified as the DEL
        reduction equivalent to it).
    max_notches : int
        Most notches and bumps among the elements.
    **certify_options
        Passed to :func:`~specdesign.feasibility.element_specification` (``headroom_pp``, and
        the certificate's ``slack_db``, ``case_offsets``, ``max_sensitivity``, ...).

    Returns
    -------
    specdesign.spec.ShapingResult
        The Notch elements among the others, the promise (evaluated on
        :data:`specdesign.feasibility.elements.FIT_OMEGA`, 0.005-20 rad/s, whatever the
        baseline's grid: the elements are free outside the baseline's band), the specification
        (baseline × elements) and the certified pair.

    Raises
    ------
    TypeError
        If ``base`` is not a :class:`~specdesign.spec.Baseline`, or an option is not one of
        :func:`~specdesign.feasibility.element_specification`'s.
    ValueError
        If ``quantity`` is unknown, ``target_reduction`` is not in (0, 100), the baseline does
        not carry its model (or was not made on ROSCO's tower-base map with the default wind),
        or no certified element specification reaches the target (the message says which
        constraint binds).

    Examples
    --------
    >>> from specdesign.feasibility import shape_whole_band
    >>> from specdesign.spec import baseline_analysis
    >>> from specdesign.turbine import iea15mw
    >>> res = shape_whole_band(baseline_analysis(iea15mw(), 25.0), 25.0)        # doctest: +SKIP
    >>> bool(res.promise.exact_del >= 25.0), res.certified.case_speeds      # doctest: +SKIP
    (True, (24.0, 24.5, 25.0))
    """
    from ..spec import (  # heavy: python-control (feasibility loads without it)
        Notch,
        ShapingResult,
        check_shaping_request,
    )

    t = check_shaping_request(base, target_reduction, quantity)
    why = ["it carries no model (make it with baseline_analysis(model, v))" if base.model is None else "",
           f"its output is {base.output!r}, not 'tower_base_my'" if base.output != "tower_base_my" else "",
           "it was made with another controller than ROSCO's" if base.extras.get("controller") is not None else "",
           f"its wind is turbulence class {base.extras.get('turbulence_class')!r}, not 'B'"
           if base.extras.get("turbulence_class", "B") != "B" else "",
           f"its damage method is {base.method!r}, not 'dirlik'" if base.method != "dirlik" else ""]
    why = [w for w in why if w]
    if why:
        raise ValueError("shape_whole_band certifies a specification against ROSCO's tower-base map on the baseline's "
                         f"model (baseline_analysis(model, v)); this baseline cannot be used: {'; '.join(why)}")
    target_del = t if quantity == "del" else float(spectral.del_reduction(t, base.m))
    ts = element_specification(base.model, base.wind_speed, target_del, m=base.m, max_notches=max_notches,
                               **certify_options)
    promise = ts.promise  # on the fit's wider grid, which sees the elements outside the baseline's
    reached = promise.exact_del if quantity == "del" else promise.exact_damage
    notches = tuple(e for e in ts.tower.elements if isinstance(e, Notch))
    message = (f"certified {reached:.2f} % {quantity} reduction (target {t:.2f} %) over the whole band with "
               f"{len(ts.tower.elements)} elements, the speed map relaxed by {ts.speed_relax_db:.2f} dB, at the "
               f"plant cases {ts.case_speeds} m/s")
    return ShapingResult(notches, promise, t, quantity, True, message, ts.tower, ts)
