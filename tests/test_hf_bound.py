"""Issue 28 item 1: a bound on the pitch controller's high-frequency gain, part of every design.

|C_β(jω)| ≤ κ·|C_ROSCO(jω)| on HF_OMEGA-HF_END (2-10 rad/s, 3P = 2.375 rad/s inside), C_β strictly
proper, κ = feasibility.HF_GAIN_RATIO (benchmarks/hf_bound.py, from ROSCO in OpenFAST). Checked
here independently of each design's own check: C_β's response on another grid than the design's,
3P included, against ROSCO's controller evaluated here.
"""
from __future__ import annotations

import re
from pathlib import Path

import control as ct
import matplotlib
import numpy as np
import pytest

from loopshaping import qft as lqft
from loopshaping.check import check as lcheck
from loopshaping.controller import Controller, gain
from loopshaping.interactive import Designer
from loopshaping.specs import controller_gain
from specdesign import closedloop, spec
from specdesign import feasibility as fz
from specdesign.feasibility import HF_END, HF_GAIN_RATIO, HF_OMEGA, YoulaProblem
from specdesign.feasibility.margin import MARGIN_BUMPS
from specdesign.feasibility.target import SEARCH_MARGIN_PP, TARGET_REDUCTION
from specdesign.turbine import iea15mw

matplotlib.use("Agg")
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def model():
    return iea15mw()


def check_grid(model):
    """2-10 rad/s on 400 points (another grid than any design's) and 3P at rated rotor speed."""
    return np.union1d(np.geomspace(HF_OMEGA, HF_END, 400), [3 * model.rated_rotor_speed])


def gain_ratio(model, v, controller, kappa):
    """max |C_β|/(κ·|C_ROSCO|) on :func:`check_grid`, ROSCO's controller evaluated here."""
    w = check_grid(model)
    c_r = np.abs(closedloop.siso_response(spec.baseline_controller(model, v), w))
    return float(np.max(np.abs(closedloop.siso_response(controller, w)) / (kappa * c_r)))


def direct_term(controller):
    return float(np.asarray(ct.ss(controller).D).ravel()[0])


def test_the_bound_holds_on_the_youla_design_and_the_controller_rolls_off(model):
    kappa = 50.0
    free = YoulaProblem(model, 19.0, max_sensitivity=1.8, max_hf_gain_ratio=None).solve(3.0)
    bounded = YoulaProblem(model, 19.0, max_sensitivity=1.8, max_hf_gain_ratio=kappa).solve(3.0)
    # |C| itself (not Y = C·S) is bounded: |Y| ≤ b/(1 + b|P_Ωβ|) at the grid points, with 2 % of room
    # (HF_GRID_MARGIN) for between them
    assert gain_ratio(model, 19.0, bounded.controller(model), kappa) <= 1.0
    assert direct_term(bounded.controller(model)) == 0.0  # Y(∞) = 0 set exactly: C strictly proper
    # without the bound the gain runs away (the issue: 2 300-8 000× ROSCO's at 10 rad/s)
    assert gain_ratio(model, 19.0, free.controller(model), kappa) > 10
    assert bounded.del_reduction < free.del_reduction  # a constraint costs promise
    with pytest.raises(ValueError, match="hf_omega"):
        YoulaProblem(model, 19.0, max_hf_gain_ratio=kappa, hf_omega=20.0)
    with pytest.raises(ValueError, match="max_hf_gain_ratio"):
        YoulaProblem(model, 19.0, max_hf_gain_ratio=-1.0)


def test_one_default_for_the_bound_in_every_entry_point():
    import inspect

    from specdesign.hinf import design_hinf, spec_for_target
    from specdesign.qft.design import _design_single

    assert HF_GAIN_RATIO is not None and HF_GAIN_RATIO > 0
    # one name, one default (feasibility.MAX_HF_GAIN_RATIO: the measured κ, on), in every entry point
    for fn in (fz.YoulaProblem.__init__, fz.achievable_pitch, fz.pitch_frontier, fz.specification_for_target,
               fz.CertificateSearch.__init__, design_hinf, spec_for_target, _design_single):
        assert inspect.signature(fn).parameters["max_hf_gain_ratio"].default is fz.MAX_HF_GAIN_RATIO, fn.__qualname__
    assert fz.MAX_HF_GAIN_RATIO == HF_GAIN_RATIO  # issue 28 item 1: the bound is part of every design by default


def test_the_constant_is_the_documented_measurement(benchmark_script):
    """HF_GAIN_RATIO is what benchmarks/hf_bound.py printed into docs/feasibility.md, and, where
    its OpenFAST runs are cached on this machine, what the rule gives from them again."""
    doc = (ROOT / "docs" / "feasibility.md").read_text()
    found = re.search(r"Measured: κ = \*\*([0-9.]+)\*\*", doc)
    assert found, "docs/feasibility.md has no section written by benchmarks/hf_bound.py"
    assert float(found.group(1)) == HF_GAIN_RATIO
    block = doc[doc.index("<!-- hf_bound.py: start -->"):doc.index("<!-- hf_bound.py: end -->")]
    rows = {float(v): float(k) for v, k in re.findall(r"^\| ([0-9.]+) m/s \|.*\| ([0-9.]+) \|$", block, re.M)}
    assert 19.0 in rows and HF_GAIN_RATIO <= min(rows.values()) < 1.1 * HF_GAIN_RATIO  # the tightest, rounded down
    cached = Path.home() / ".cache" / "specdesign" / "hf_bound" / "rosco_19mps_seed1_120s.npz"
    if not cached.exists():
        pytest.skip("benchmarks/hf_bound.py's OpenFAST run at 19 m/s is not cached on this machine")
    hf = benchmark_script("hf_bound")  # it imports its neighbour comparison.py
    row = hf.measure(iea15mw(), 19.0, 1, 120.0)  # from the cached run: the rule again, independently of the doc
    assert round(row["kappa"]) == rows[19.0]



def test_the_bounds_check_points_are_refined_around_the_controllers_own_resonances(model):
    # a lightly damped pole pair of C midway between the check grid's points near 4 rad/s (ζ =
    # 0.002, half-power width 0.4 %, points 1.1 % apart): the base points miss its peak by dB,
    # the points refined around the controller's poles (what design_hinf and the multi-model
    # step's check use) reach it; the peak's height is the second-order one, 1/(2ζ√(1−ζ²))
    base = np.geomspace(0.005, 10.0, 700)
    i = int(np.searchsorted(base, 4.0))
    wn, z = float(np.sqrt(base[i] * base[i + 1])), 0.002
    c = ct.tf([wn**2], [1.0, 2 * z * wn, wn**2])
    coarse, fine = fz.hf_check_omega(model, base), fz.hf_check_omega(model, base, c.poles())
    peak = 20 * np.log10(1 / (2 * z * np.sqrt(1 - z**2)))
    assert peak - 20 * np.log10(np.max(np.abs(c(1j * coarse)))) > 3.0
    assert 20 * np.log10(np.max(np.abs(c(1j * fine)))) == pytest.approx(peak, abs=0.01)
    # refinement only adds points: the base check's points are all still there
    assert np.all(np.isin(coarse, fine))

def test_a_target_the_bound_makes_infeasible_is_refused_naming_it(model):
    with pytest.raises(ValueError, match=r"high-frequency gain bound .*max_hf_gain_ratio="):
        fz.specification_for_target(model, 19.0, 60.0, max_relax_db=3.0, max_hf_gain_ratio=HF_GAIN_RATIO)


def test_controller_gain_spec_and_the_designers_verdict():
    """loopshaping's generic check |G(jω)| ≤ W(ω) on a band, in the dense check and the Designer."""
    plant, w = ct.tf([1.0], [1.0, 1.0]), np.geomspace(0.1, 20.0, 200)
    g = ct.tf([10.0], [1.0, 1.0])  # |G| = 10/√(1 + ω²): 4.47 at 2 rad/s, 1.0 at 10 rad/s
    met, missed = controller_gain(5.0, band=(2.0, 10.0)), controller_gain(4.0, band=(2.0, 10.0))
    assert lcheck([plant], g, met, w).passed
    res = lcheck([plant], g, missed, w)
    assert not res.passed
    lo, hi = res.violated_ranges("controller_gain")[0]
    assert lo == pytest.approx(2.0, rel=0.03) and hi == pytest.approx(np.sqrt(10.0 ** 2 / 16 - 1), rel=0.03)
    tmpl = lqft.Template.from_systems([plant], [0.1, 1.0])
    bounds = lqft.bounds(tmpl, "stability", 1.2)
    st = Designer(bounds, tmpl, Controller((gain(10.0),)), gain_bound=missed).state()
    assert not st.gain_met and st.spec_violations["controller_gain"].size > 0
    ok = Designer(bounds, tmpl, Controller((gain(1.0),)), gain_bound=missed)
    assert ok.state().gain_met and "the controller's gain bound is not" not in ok.summary()
    with pytest.raises(TypeError, match="gain_bound"):
        Designer(bounds, tmpl, gain_bound=5.0)


#: The wind speeds of the paper's Table 3: issue 28's "Done when" asks the designs there to meet
#: the bound and still promise the target (TARGET_REDUCTION, 25 %).
SPEEDS = (15.0, 17.0, 19.0, 21.0, 23.0, 25.0)


@pytest.fixture(scope="module")
def qft_designs(model):
    from specdesign.qft import design_qft

    return {v: design_qft(model, v) for v in SPEEDS}  # the default: 25 % under κ = HF_GAIN_RATIO


@pytest.mark.slow
@pytest.mark.parametrize("v", SPEEDS)
def test_design_qft_meets_the_bound_and_promises_the_target(model, qft_designs, v):
    d = qft_designs[v]
    assert d.success, d.message
    assert d.options["max_hf_gain_ratio"] == HF_GAIN_RATIO
    assert gain_ratio(model, v, d.pitch_controller, HF_GAIN_RATIO) <= 1.0
    assert direct_term(d.pitch_controller) == 0.0
    assert "hf_gain" in d.pitch_check.names and d.pitch_check.spec_passed[d.pitch_check.names.index("hf_gain")]
    assert d.promise.exact_del >= TARGET_REDUCTION + SEARCH_MARGIN_PP


@pytest.mark.slow
@pytest.mark.parametrize("v", [15.0, 19.0, 25.0])
def test_design_hinf_meets_the_bound_and_is_strictly_proper(model, v):
    from specdesign.hinf import design_hinf

    d = design_hinf(model, v)  # the default: 25 % under κ = HF_GAIN_RATIO
    assert d.case_check.met and d.case_check.proper
    assert d.case_check.hf_excess_db <= 0.0
    assert gain_ratio(model, v, d.pitch_controller, HF_GAIN_RATIO) <= 1.0
    # the design's own measure at the nominal plant, and a controller a turbine can carry
    assert d.hf_excess_db <= 0.0
    assert d.controller_unstable_poles.size == 0 and d.speed_integral_sign == 1
    assert direct_term(d.pitch_controller) == 0.0
    assert d.promised_del_reduction >= TARGET_REDUCTION


def test_the_25_percent_target_needs_the_cases_margin_where_their_excess_lies(model):
    # 19 m/s under the measured κ: raising the certificate's map by the plant cases' largest
    # excess everywhere (margin_bumps=0, the search before) promises at most 24.8 % over the
    # ladder (docs/feasibility.md's table before the shaped margin), so 25 % is refused; the
    # margin that follows the cases' excess certifies it, and the pair is met at every plant case
    # on recertify's own dense grid (refined around the bumps' roots)
    search = fz.CertificateSearch(model, 19.0, margin_bumps=0)
    with pytest.raises(ValueError, match=rf"high-frequency gain bound \|C\| ≤ {HF_GAIN_RATIO:g}"):
        search.for_target(TARGET_REDUCTION)
    ts = fz.specification_for_target(model, 19.0)
    assert ts.max_hf_gain_ratio == HF_GAIN_RATIO and ts.promise.exact_del >= TARGET_REDUCTION + SEARCH_MARGIN_PP
    bumps = [e for e in ts.tower.elements if isinstance(e, spec.Notch)]
    assert bumps and all(e.depth_db < 0 for e in bumps)  # bumps: W_MyT only rises above the certificate's map
    again = fz.recertify(model, ts)
    assert again.promise.exact_del == pytest.approx(ts.promise.exact_del, abs=1e-9)
    with pytest.raises(ValueError, match="margin_bumps"):
        fz.CertificateSearch(model, 19.0, margin_bumps=MARGIN_BUMPS + 1)


def test_the_cases_margin_lies_above_their_excess_and_promises_no_less_than_a_uniform_one():
    from specdesign.feasibility.margin import case_margin, shaping_db

    w = np.geomspace(0.005, 20.0, 900)
    # an excess like the IEA 15 MW's: a hump in the wind band, a peak at the tower mode
    p = 0.6 * np.exp(-(np.log(w / 0.12) / 0.6) ** 2) + 2.0 * np.exp(-(np.log(w / 1.13) / 0.04) ** 2) + 0.1
    weight_omega = np.geomspace(0.01, 10.0, 400)
    weight = np.exp(-(np.log(weight_omega / 1.1) / 0.3) ** 2) + 0.2 * np.exp(-(np.log(weight_omega / 0.15) / 0.8) ** 2)

    def promise(elements):  # a stand-in promise: it falls with the margin where the weight lies
        return -float(np.sum(np.interp(w, weight_omega, weight) * shaping_db(elements, w)))

    uniform = case_margin(w, p, weight_omega, weight, promise, max_bumps=0)
    assert len(uniform) == 1 and uniform[0].gain_db == pytest.approx(p.max())
    shaped = case_margin(w, p, weight_omega, weight, promise)
    assert np.all(shaping_db(shaped, w) >= p - 1e-9)  # on or above the excess at every point
    assert promise(shaped) > promise(uniform)
    for e in shaped[1:]:  # bumps centred where the promise is evaluated
        assert weight_omega[0] <= e.omega_n <= weight_omega[-1] and e.depth_db <= 0


def test_the_bode_and_nichols_figures_draw_the_bound(model, qft_designs):
    import matplotlib.pyplot as plt

    from specdesign.plots.qft import plot_design_bode, plot_design_nichols

    d = qft_designs[19.0]
    fig = plot_design_bode(d, model)
    assert len(fig.axes) == 3  # the pitch controller's gain under the two maps
    labels = [line.get_label() for line in fig.axes[2].get_lines()]
    bound = [line for line in fig.axes[2].get_lines() if "high-frequency gain bound" in line.get_label()]
    assert len(bound) == 1, labels
    w, y = bound[0].get_data()
    # the line is κ·|C_ROSCO| in dB on 2-10 rad/s, ROSCO's controller evaluated here
    c_r = np.abs(closedloop.siso_response(spec.baseline_controller(model, 19.0), w))
    np.testing.assert_allclose(y, 20 * np.log10(HF_GAIN_RATIO * c_r), rtol=1e-9)
    assert w.min() >= HF_OMEGA and w.max() <= HF_END
    nic = plot_design_nichols(d, model=model)
    assert any("high-frequency gain bound" in line.get_label() for line in nic.axes[0].get_lines())
    plt.close("all")
