"""Can a specification pair be met by pitch control at all? Checked before any loop shaping.

With the collective pitch as the only actuator, every closed-loop wind map of *any* linear
controller (on the generator speed, with an active tower damping loop, of any order) is
T_{y,w} = P_{y,w} + P_{y,β}·T_{β,w}: one complex number per frequency is free. Written with
S = T_{Ω,w}/P_{Ω,w} (the sensitivity 1/(1 + C·P_{Ω,β}) of a controller C on Ω_g alone):

    T_{Ω,w}   = P_{Ω,w}·S
    T_{MyT,w} = K∞ + (P_{MyT,w} − K∞)·S,     K∞ = P_{MyT,w} − P_{MyT,β}·P_{Ω,w}/P_{Ω,β}

(K∞ is T_{MyT,w} for C → ∞, S = 1 the open loop). So each specification is a disk for S:

    speed   |T_{Ω,w}| ≤ |W_Ω|      ⇔  |S| ≤ r_Ω = |W_Ω|/|P_{Ω,w}|
    margin  |S| ≤ M_s               (the pitch loop's robustness; None: not imposed)
    tower   |T_{MyT,w}| ≤ |W_MyT|  ⇔  |S − c| ≤ ρ,  c = −K∞/(P_{MyT,w} − K∞),  ρ = |W_MyT|/|P_{MyT,w} − K∞|

Two necessary conditions follow, for every plant case:

1. **Pointwise**: at each ω the disks intersect, |c| − ρ ≤ min(r_Ω, M_s). Where they do
   not, no controller acting through the pitch meets the specifications at that frequency,
   whatever its measurements; the check says which specification binds against the tower's.
2. **Interpolation** (the right-half-plane zeros z of P_{Ω,β}; the IEA 15 MW has a lightly
   damped pair at the tower mode): T_{Ω,w}(z) = P_{Ω,w}(z), i.e. S(z) = 1, for every
   controller, and for a stable plant the Poisson integral gives
   (1/π)∫ ln|S(jω)|·Re z/((Re z)² + (ω − Im z)²) dω ≥ ln|S(z)| = 0 over ω ∈ ℝ. With
   |S| ≤ s_max(ω) = min(r_Ω, M_s, |c| + ρ) pointwise, the same mean of ln s_max must be
   ≥ 0: the specifications may not ask for |S| < 1 around Im z.

Both are necessary, not sufficient: a design can still fail on causality elsewhere (Bode's
integral spreads the cost over a band), on robustness between plant cases, or on the
structure it is given (design_qft's sixth-order pitch controller and first-order ATD).

What *can* be promised is found by design, not by check: :func:`achievable_pitch` optimises
over every stabilising pitch controller at once (the Youla parametrisation of the stable
plant, C = Y/(1 − P_{Ω,β}Y) with Y stable, in which every closed-loop map is affine in Y) the
tower-base damage predicted by the paper's Eq. (10), subject to the generator-speed
specification and |S| ≤ M_s on the grid: a convex problem (cvxpy). Its |T_{MyT,w}| is a
specification that is feasible by construction, with the exact (Dirlik) promise.
:func:`pitch_frontier` tabulates, per speed relaxation, that achievable promise beside the
pointwise upper bound of condition 1 (the smallest |T_{MyT,w}| inside the speed and margin
disks at every frequency): the true frontier lies between the two.
:func:`specification_for_target` inverts the frontier: the smallest speed relaxation whose
design promises a requested DEL reduction, and the specification pair it certifies; the plant
cases' margin in its W_MyT follows their excess where it lies (a gain and bumps,
:func:`~specdesign.feasibility.margin.case_margin`).
:func:`element_specification` writes such a certified tower specification as ROSCO's map times
a few shaping elements (gain, lag, lead, notches and bumps) over the whole band, editable by hand:
the elements follow a certificate's envelope, and :meth:`CertificateSearch.for_tower` certifies
them with a Youla design made to meet them (the tower bound, |T_{MyT,w}| ≤ |W_MyT|, is convex too).

Modules: :mod:`~specdesign.feasibility.conditions` (the necessary conditions, the frontier),
:mod:`~specdesign.feasibility.achievable` (the convex Youla design),
:mod:`~specdesign.feasibility.target` (the specification for a target),
:mod:`~specdesign.feasibility.margin` (the plant cases' margin in it),
:mod:`~specdesign.feasibility.elements` (the same in shaping elements),
:mod:`~specdesign.feasibility.shaping` (:func:`shape_whole_band`: the same from a
:func:`specdesign.spec.baseline_analysis` baseline, as :func:`specdesign.spec.shape_to_target`
shapes the paper's notches).

Units: ω in rad/s, magnitudes linear (dB only in messages), DEL reductions in %.
"""
from .achievable import (
                         HF_END,
                         HF_GAIN_RATIO,
                         MAX_HF_GAIN_RATIO,
                         HF_OMEGA,
                         YOULA_PAIRS,
                         YOULA_REAL_POLES,
                         AchievablePitch,
                         YoulaProblem,
                         achievable_pitch,
                         hf_check_omega,
                         hf_gain_bound,
)
from .conditions import (
                         PitchChecker,
                         PitchFeasibility,
                         combine,
                         pitch_checkers,
                         pitch_feasibility,
                         pitch_frontier,
                         sensitivity_disks,
)
from .elements import element_specification
from .shaping import shape_whole_band
from .target import (
                         CertificateSearch,
                         TargetSpecification,
                         recertify,
                         specification_for_target,
)

__all__ = ["PitchFeasibility", "pitch_feasibility", "PitchChecker", "pitch_checkers", "combine", "AchievablePitch",
           "achievable_pitch", "pitch_frontier", "TargetSpecification", "specification_for_target", "sensitivity_disks",
           "YOULA_REAL_POLES", "YOULA_PAIRS", "YoulaProblem", "recertify", "element_specification", "CertificateSearch",
           "shape_whole_band", "HF_GAIN_RATIO", "MAX_HF_GAIN_RATIO", "HF_OMEGA", "HF_END", "hf_check_omega", "hf_gain_bound"]
