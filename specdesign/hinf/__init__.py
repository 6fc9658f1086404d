"""H∞ pitch control with the fatigue-based specifications as weights.

Modules: :mod:`~specdesign.hinf.weights` (W⁻¹ of a specification), :mod:`~specdesign.hinf.plant`
(the generalized plant), :mod:`~specdesign.hinf.specs` (:class:`HinfSpecification`, the one kind of
specification :func:`design_hinf` takes, and the functions that make it),
:mod:`~specdesign.hinf.design` (:func:`design_hinf` and its result),
:mod:`~specdesign.hinf.cases` (a certified pair at every plant case: :func:`check_pair` and the
multi-model H∞ step :func:`refine_on_cases`), :mod:`~specdesign.hinf.modal` (a controller's
modal parameters and their analytic derivatives); the
synthesis, well-posedness checks and reduction are :mod:`loopshaping.hinf`'s.

The specifications of :mod:`specdesign.spec` are upper bounds on closed-loop maps from the
rotor-effective wind: |T_{MyT,w}(jω)| ≤ |W_MyT(jω)| (tower-base load, the baseline reshaped by
notches) and |T_{Ω,w}(jω)| ≤ |W_Ω(jω)| (generator speed, the baseline's T_{Ω,w}). By default
:func:`design_hinf` takes the feasible pair of a DEL target, as ``specdesign.qft.design_qft`` does
(:func:`specdesign.feasibility.specification_for_target`, 25 %, certified over plant cases), and
meets it at every case (pitch only); ``spec=spec_like_qft(model, v)`` takes the specifications of
``design_qft(spec=spec_notch(...))`` (the tower spec relaxed above ≈ 1.3
rad/s, the speed spec relaxed by QFT's dB ladder). Either way H∞ and QFT are compared on the same
specifications. Dividing each
output by its specification gives performance outputs whose H∞ norm is ≤ 1 exactly when
the specification is met, so the generalized plant at one operating point is

    inputs  [wind (m/s); noise on each measurement; pitch_cmd (rad)]
    outputs [z_tower = W_MyT⁻¹·MyT; z_speed = W_Ω⁻¹·Ω_g; z_pitch = w_pitch·β; y = measurements]

with W⁻¹ made a stable, proper weight (:func:`inverse_weight`). The performance outputs form
one column (one wind input), so γ bounds the root-sum-square of the ratios: γ ≤ 1 means
every specification is met, and γ ≈ √2 is what two specifications met with equality give.

Sign convention of the workbench: β = −C_β·Ω_g − C_atd·v_tt. SLICOT closes u = K·y, so
[C_β, C_atd] = −K.
"""
from __future__ import annotations

from .cases import CHECK_OMEGA, CONTINUATION_DB, CaseCheck, check_pair, refine_on_cases
from .design import DEFAULT_DECAY_RATE, ORDER_ROOM_DB, ORDERS, TOWER_BAND, HinfDesign, design_hinf
from .plant import DEFAULT_INTEGRAL_CORNER, DEFAULT_NOISE, GeneralizedPlant, generalized_plant
from .specs import (
    HinfSpecification,
    spec_for_target,
    spec_from_certified,
    spec_from_pair,
    spec_from_qft,
    spec_from_rosco,
    spec_like_qft,
)
from .weights import DEFAULT_MIN_DAMPING, inverse_weight, siso_weight

__all__ = [
    "CaseCheck",
    "CHECK_OMEGA",
    "CONTINUATION_DB",
    "check_pair",
    "refine_on_cases",
    "GeneralizedPlant",
    "HinfDesign",
    "HinfSpecification",
    "ORDER_ROOM_DB",
    "ORDERS",
    "design_hinf",
    "generalized_plant",
    "inverse_weight",
    "siso_weight",
    "spec_for_target",
    "spec_from_certified",
    "spec_from_pair",
    "spec_from_qft",
    "spec_from_rosco",
    "spec_like_qft",
    "DEFAULT_NOISE",
    "DEFAULT_MIN_DAMPING",
    "DEFAULT_DECAY_RATE",
    "DEFAULT_INTEGRAL_CORNER",
    "TOWER_BAND",
]
