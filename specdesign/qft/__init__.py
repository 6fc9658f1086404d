"""QFT design of the pitch controller C_β and an active tower damping (ATD) controller.

Modules: :mod:`~specdesign.qft.design` (the design at one operating point and over a schedule),
:mod:`~specdesign.qft.specs` (:class:`QFTSpecification`, the one kind of specification
:func:`design_qft` takes, and the functions that make it),
:mod:`~specdesign.qft.result` (its record, :class:`QFTDesign`), :mod:`~specdesign.qft.structure`
(the fixed controller structures and their parameter vector), :mod:`~specdesign.qft.tuner`
(objective, constraints, the tuner); the loop
algebra they use (general form, sequential closure) is :mod:`specdesign.closedloop`'s.

The seed paper's Sect. 4 on the embedded turbine model, as a deterministic automatic
procedure, in two forms. :func:`design_qft`'s default is specification-driven: the certified
specification pair for a DEL target (:func:`specdesign.feasibility.specification_for_target`),
then its certificate reduced to the lowest order that meets the pair at every plant case
(:mod:`~specdesign.qft.certificate`), checked as below. ``design_qft(spec=spec_notch(target))`` is
the fixed-structure design of the sections below (notch specification, DEL target, tuner).
Sign convention (:mod:`specdesign.closedloop`):

    β_cmd = −C_β·Ω_g − C_atd·z,    z = tower-top fore-aft velocity (m/s),

both negative feedback; ω in rad/s; transfer functions are python-control objects.

Sequential loop closure and the general form
--------------------------------------------
With one loop closed (controller K on measurement m: β_cmd = u − K·m) the plant seen from
the free pitch input u is, with Δ_K = 1 + K·P_{m,β},

    P'_{y,w} = P_{y,w} − P_{y,β}·K·P_{m,w}/Δ_K,        P'_{y,β} = P_{y,β}/Δ_K.

Closing the second loop u = −G·n (G the controller designed now, n its measurement) gives
every wind map in QFT's general form |(A + B·G)/(C + D·G)| with, per plant case,

    A = P'_{y,w},  B = P'_{y,w}P'_{n,β} − P'_{y,β}P'_{n,w},  C = 1,  D = P'_{n,β}

(B = 0 when y = n). For the pitch controller (G = C_β, n = Ω_g, ATD closed) and y = MyT this
is the tower-load form of :mod:`specdesign.closedloop` with the primed plant; for the ATD (G = C_atd, n = z,
pitch loop closed) the roles swap. :func:`specdesign.closedloop.general_form` computes A..D; the tests check
(A + B·G)/(C + D·G) against ``control.interconnect`` to 1e-9.

Specifications (per plant case i, at the design frequencies)
-----------------------------------------------------------
- tower load ``tower``: |T_{MyT,w}| ≤ |W_MyT,i| = |T^ROSCO_{MyT,w,i}|·|notches|·|relaxation|,
  the notches from :func:`specdesign.spec.shape_to_target` at the nominal speed, the
  relaxation two lead elements (+``tower_relax_db`` above ``tower_relax_omega``) where the
  damage sensitivity ΔD%(ω) is negligible (the waterbed of a higher-gain loop goes there;
  the paper's Fig. 7 shows the same excess at 2-5 rad/s). Both promises are reported: the
  notch specification's (``QFTDesign.shaping.promise``, what the paper's Table 3 lists) and
  the relaxed one's (``QFTDesign.promise``, smaller: the relaxation gives some back).
- generator speed ``speed``: |T_{Ω,w}| ≤ |T^ROSCO_{Ω,w,i}|·10^(speed_relax_db/20); by Bode's
  sensitivity integral a loop reshaped for fatigue cannot stay below ROSCO's everywhere, so
  :func:`design_qft` tries 3, 4.5, 6, 8 dB in turn and keeps the smallest that works.
- stability margins ``margin``: |1/(1 + L)| ≤ ``max_sensitivity`` on each loop with the other
  closed (1.9 guarantees GM ≥ 6.5 dB and PM ≥ 30.5°), and ``actuator_margin``: the same at
  the pitch actuator, |1/(1 + C_β P_{Ω,β} + C_atd P_{z,β})|, in general form for C_β.

Templates: linear models at neighbouring operating points v + ``template_offsets`` (m/s,
clipped to the model's above-rated range), nominal v.

Automatic design
----------------
Fixed structures (6 states in all):

    C_β(s)   = k·(s + z)/s · (s² + 2ζ_n ω_n s + ω_n²)/ω_n² · ω_d²/(s² + 2ζ_d ω_d s + ω_d²)
                           · ω_f²/(s² + 2ζ_f ω_f s + ω_f²),      k < 0
    C_atd(s) = k_a·(s/z_a + 1)/(s/p_a + 1),                        k_a < 0

started from ROSCO's PI and filter (the complex pair cancelled) and a weak ATD, tuned to:
minimise (σ_β̇/σ_β̇,ROSCO)² + 0.1·(σ_Ω/σ_Ω,ROSCO)² subject to a predicted tower-base DEL
reduction ≥ ``target_reduction`` (Dirlik on |T|²S_W, nominal case), every bound at every
design frequency for every case with a safety margin (0.1 dB on the stability specs, 0.02 dB
on the performance specs), and every closed loop (full interconnection, every case) with
poles left of −``min_decay`` 1/s. A phase one (SLSQP on the least uniform violation) reaches a
feasible point from ROSCO's infeasible start, SLSQP polishes it and Newton's method refines it
to the KKT point (:mod:`specdesign.qft.tuner`): local methods from a start that moves
continuously with the data, so the design does not jump when the wind speed moves by round-off
(the earlier Powell exploration's end point did). The two loops' bounds are then computed exactly with
:func:`loopshaping.qft.bounds` for the final controllers and the design is checked on a dense
grid over all cases with :func:`loopshaping.check.check`; frequencies where the dense check
fails are added to the design set and the tuning repeated (up to ``refine`` times).
With ``measurement_filter`` (e.g. :func:`three_p_notch`) both structures are multiplied by a fixed
filter on the measurements, which the tuner sees.
"""
from __future__ import annotations

from ..closedloop import general_form, partial_loop
from .checks import fine_pitch_lift
from .design import (
    check_design_speed,
    design_qft,
    design_schedule,
    design_table,
    format_table,
    held_lift,
)
from .result import DEFAULT_DESIGN_OMEGA, QFTDesign
from .specs import SPEED_RELAX_DB, QFTSpecification, spec_from_certified, spec_from_pair, spec_notch
from .structure import rolloff, three_p_notch
from .torque_design import TorqueDesign, design_torque, torque_general_form

__all__ = [
    "QFTDesign",
    "general_form",
    "partial_loop",
    "design_qft",
    "QFTSpecification",
    "spec_from_certified",
    "spec_from_pair",
    "spec_notch",
    "three_p_notch",
    "rolloff",
    "design_schedule",
    "held_lift",
    "check_design_speed",
    "design_table",
    "format_table",
    "DEFAULT_DESIGN_OMEGA",
    "SPEED_RELAX_DB",
    "fine_pitch_lift",
    "TorqueDesign",
    "design_torque",
    "torque_general_form",
]
