"""Every figure function, called on small fast inputs: axis labels carry units, the legend has
the entries a reader needs, no two legend entries share a style, and Nichols charts wrap the
loop's phase into the chart's window (issue 18's figure defects).

Expected legend texts and units are written here from what each figure shows; the phase
wrapping and the Bode verdicts are checked against independent computations (python-control's
frequency response, the specification's own response).
"""
from __future__ import annotations

import re
import warnings

import control as ct
import matplotlib
import numpy as np
import pytest
from matplotlib.colors import to_rgba
from matplotlib.container import ErrorbarContainer
from matplotlib.lines import Line2D

from loopshaping import nichols, qft as lqft

from test_qft_bounds import G_PUBLISHED, manual_cases

matplotlib.use("Agg")
s = ct.tf("s")
UNIT = re.compile(r"[(\[].*\S.*[)\]]")


# ----------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def model():
    from specdesign.turbine import iea15mw

    return iea15mw()


@pytest.fixture(scope="module")
def design(model):
    """A QFT design made small (9 design frequencies, short tuning): a real QFTDesign in ~5 s."""
    from specdesign.qft import design_qft, spec_notch

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a short tuning may miss a spec; figures still apply
        return design_qft(model, 19.0, spec=spec_notch(speed_relax_db=6.0), refine=0, maxfev=150,
                          design_omega=[0.01, 0.05, 0.1, 0.3, 0.6, 1.0, 1.06, 1.5, 3.0],
                          dense_omega=np.logspace(-2, 1, 100))


@pytest.fixture(scope="module")
def campaign(model):
    """Two controllers, one speed, two 60 s seeds, with the linear twin and a Volterra model."""
    from specdesign import validate as va
    from specdesign.rosco import rosco_baseline
    from specdesign.simulate import scheduled

    rosco = rosco_baseline(model, 19.0)
    atd = ct.tf([-0.014187, -0.014187 * 4.357], [1, 0.3276])  # the paper's C_ATD (as in test_validate)
    ctrls = {"ROSCO": rosco, "ATD": scheduled(model, {19.0: rosco}, atd={19.0: atd}, name="ATD")}
    return va.run_campaign(ctrls, [19.0], [1, 2], model=model, duration=60.0, transient=10.0, keep_series=True,
                           linear_twin=True, volterra=2, progress=False)


@pytest.fixture(scope="module")
def baseline(model):
    from specdesign.spec import baseline_analysis

    return baseline_analysis(model, 19.0)


@pytest.fixture(scope="module")
def template():
    cases, nom = manual_cases()
    # 0.0464159 = logspace(-2, 1, 37)[10], the frequency issue 18 saw printed as 0.04642
    return lqft.Template.from_systems(cases, [0.0464159, 1.0, 5.0, 100.0], nominal=nom), cases, nom


@pytest.fixture(scope="module")
def bounds(template):
    t, _, _ = template
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", lqft.BoundsWarning)
        return lqft.intersect(lqft.bounds(t, "stability", 1.2), lqft.bounds(t, "input_disturbance", 0.01, band=(0, 10)))


# ----------------------------------------------------------------------------- helpers
def _axes(result):
    """The axes with something drawn, from whatever a figure function returns."""
    if hasattr(result, "get_axes"):
        axes = result.get_axes()
    else:
        axes = list(np.ravel(np.asarray(result, dtype=object)))
    return [a for a in axes if a.has_data()]


def _style(handle):
    if isinstance(handle, ErrorbarContainer):
        handle = handle.lines[0]
    if isinstance(handle, Line2D):
        return ("line", to_rgba(handle.get_color()), handle.get_linestyle(), handle.get_marker(),
                to_rgba(handle.get_markerfacecolor()) if handle.get_marker() not in ("None", "", " ") else None)
    patch = handle.patches[0] if hasattr(handle, "patches") else handle
    return ("patch", to_rgba(patch.get_facecolor()), getattr(patch, "get_hatch", lambda: None)())


def _check_figure(result, x_unit, y_units, legend_entries):
    axes = _axes(result)
    assert axes, "nothing drawn"
    xlabels = [a.get_xlabel() for a in axes if a.get_xlabel()]
    assert any(x_unit in lab for lab in xlabels), (x_unit, xlabels)
    for lab in xlabels:
        assert UNIT.search(lab), f"x label {lab!r} carries no unit"
    for a, unit in zip(axes, y_units, strict=True):
        assert unit in a.get_ylabel() and UNIT.search(a.get_ylabel()), (unit, a.get_ylabel())
    labels = []
    for a in axes:
        leg = a.get_legend()
        if leg is None:
            continue
        texts = [t.get_text() for t in leg.get_texts()]
        handles, drawn = a.get_legend_handles_labels()  # the artists behind the entries, with their styles
        assert drawn == texts, (drawn, texts)
        labels += texts
        styles = [_style(h) for h in handles]
        dup = [t for t, st in zip(texts, styles) if styles.count(st) > 1]
        assert not dup, f"legend entries sharing one style: {dup}"
    for want in legend_entries:
        assert any(want in lab for lab in labels), (want, labels)
    return axes, labels


# ----------------------------------------------------------------------------- every figure
def _nichols_draw(r):
    b = r.getfixturevalue("bounds")
    _, cases, nom = r.getfixturevalue("template")
    return nichols.draw(b, loop=cases[nom] * G_PUBLISHED, m_contours_db=[1.58])


def _nichols_templates(r):
    return nichols.plot_templates(r.getfixturevalue("template")[0])


def _design_nichols(r):
    from specdesign.plots.qft import plot_design_nichols

    return plot_design_nichols(r.getfixturevalue("design"))


def _design_bode(r):
    from specdesign.plots.qft import plot_design_bode

    return plot_design_bode(r.getfixturevalue("design"), r.getfixturevalue("model"), omega=np.logspace(-2, 1, 300))


def _spectra(r):
    from specdesign.plots.validation import plot_spectra

    return plot_spectra(r.getfixturevalue("campaign"), 19.0, "tower_base_my")


def _time_series(r):
    from specdesign.plots.validation import plot_time_series

    return plot_time_series(r.getfixturevalue("campaign").series, 19.0)


def _reductions(r):
    from specdesign import validate as va
    from specdesign.plots.validation import plot_reductions

    acc = va.acceptance(r.getfixturevalue("campaign"), "ATD", "ROSCO")
    return plot_reductions(acc, promised={19.0: 12.0}, target=25.0)


def _open_vs_baseline(r):
    from specdesign.closedloop import loop_maps
    from specdesign.plots.turbine import plot_open_vs_baseline
    from specdesign.rosco import rosco_baseline

    m = r.getfixturevalue("model")
    return plot_open_vs_baseline(loop_maps(m.linearize(19.0), rosco_baseline(m, 19.0), np.logspace(-2, 1, 100)))


def _fatigue_origin(r):
    from specdesign.plots.turbine import plot_fatigue_origin

    b = r.getfixturevalue("baseline")
    return plot_fatigue_origin(b.omega, b.t_response, b.psd, b.sensitivity, m=b.m)


def _range_histogram(r):
    from specdesign.fatigue import rainflow
    from specdesign.plots.fatigue import plot_range_histogram

    w = np.linspace(0.01, 5.0, 200)
    psd = np.exp(-((w - 1.0) ** 2) / 0.1)
    return plot_range_histogram(rainflow(np.random.default_rng(0).standard_normal(500)), w, psd, unit="kN·m")


def _sensitivity(r):
    from specdesign.plots.fatigue import plot_sensitivity

    b = r.getfixturevalue("baseline")
    return plot_sensitivity(b.omega, np.stack([b.sensitivity * k for k in np.linspace(0.5, 1.0, 12)]))  # > 10 colours


def _specification(r):
    from specdesign.plots.spec import plot_specification
    from specdesign.spec import shape_to_target

    b = r.getfixturevalue("baseline")
    return plot_specification(b, shape_to_target(b, 15.0).specification)


def _frontier(r):
    from specdesign.plots.spec import plot_frontier

    # the dict layout of feasibility.pitch_frontier, two speeds, numbers only for drawing
    f = {v: {"speed_relax_db": np.array([0.0, 3.0, 6.0]), "achievable": np.array([2.0, 8.0, 12.0]) + k,
             "bound": np.array([5.0, 11.0, 15.0]) + k} for k, v in enumerate((17.0, 19.0))}
    return plot_frontier(f)


FIGURES = {
    # name: (builder, x unit, y unit per drawn axis, legend entries expected)
    "nichols.draw": (_nichols_draw, "[deg]", ["[dB]"],
                     ["nominal loop L0", "ω = 0.0464 rad/s", "ω = 100 rad/s", "solid: lower bound", "dashed: upper bound",
                      "M-contours"]),
    "nichols.plot_templates": (_nichols_templates, "[deg]", ["[dB]"], ["ω = 0.0464 rad/s", "nominal case"]),
    "qft.plot_design_nichols": (_design_nichols, "[deg]", ["[dB]", "[dB]"],
                                ["nominal loop L0", "ω = 0.01 rad/s", "ω = 0.05 rad/s", "ω = 1.5 rad/s",
                                 "solid: lower bound", "dashed: upper bound"]),
    "qft.plot_design_bode": (_design_bode, "(rad/s)", ["dB re 1 (rad/s)/(m/s)", "dB re 1 N·m/(m/s)", "dB re 1 rad/(rad/s)"],
                             ["ROSCO", "generator-speed spec W_Ω", "tower-load spec W_y as shaped", "W_y relaxed",
                              "checked against", "QFT"]),
    "validation.plot_spectra": (_spectra, "(rad/s)", ["(N·m)²/(rad/s)"],
                                ["ROSCO simulation (Welch)", "ROSCO linear", "ATD simulation (Welch)", "ATD linear"]),
    "validation.plot_time_series": (_time_series, "(s)", ["(rpm)", "(MN·m)", "(MW)", "(deg)"], ["ROSCO", "ATD"]),
    "validation.plot_reductions": (_reductions, "(m/s)", ["(%)"],
                                   ["linear prediction", "rainflow, nonlinear model", "rainflow, linearised model",
                                    "Volterra prediction, order 2", "specification's promise", "design target (25 %)"]),
    "turbine.plot_open_vs_baseline": (_open_vs_baseline, "(rad/s)", ["dB", "dB", "dB"], ["open loop", "ROSCO"]),
    "turbine.plot_fatigue_origin": (_fatigue_origin, "(rad/s)", ["(dB", "per rad/s", "(%)"], ["T_MyT,w", "S_MyT", "ΔD%"]),
    "fatigue.plot_range_histogram": (_range_histogram, "[kN·m]", ["[1/kN·m]"], ["rainflow", "Dirlik"]),
    "fatigue.plot_sensitivity": (_sensitivity, "[rad/s]", ["[%]"], ["ΔD%(ω) [0]", "ΔD%(ω) [11]"]),
    "spec.plot_specification": (_specification, "(rad/s)", ["(dB re 1 N·m/(m/s))"], ["baseline", "specification"]),
    "spec.plot_frontier": (_frontier, "[dB]", ["[%]"], ["17 m/s achievable", "19 m/s upper bound"]),
}


@pytest.mark.parametrize("name", list(FIGURES))
def test_figure_units_legend_and_distinct_styles(name, request):
    import matplotlib.pyplot as plt

    build, x_unit, y_units, entries = FIGURES[name]
    try:
        _check_figure(build(request), x_unit, y_units, entries)
    finally:
        plt.close("all")


# ----------------------------------------------------------------------------- Nichols phase
def test_wrap_phase_keeps_every_point_and_breaks_at_the_edges():
    ph = np.linspace(-100.5, -900.5, 801)  # 2.2 turns down: two wraps in the default window
    mag = np.linspace(10.0, -30.0, 801)
    wph, wmag = nichols.wrap_phase(ph, mag)
    ok = np.isfinite(wph)
    assert np.all((wph[ok] >= -360.0) & (wph[ok] <= 0.0))
    # the wrapped points are the original ones, 360° apart (same complex direction)
    near_break = np.zeros(wph.size, bool)
    near_break[:-1] |= ~ok[1:]
    near_break[1:] |= ~ok[:-1]
    orig = ok & ~near_break  # the grid avoids the edges, so only the inserted edge points touch a break
    np.testing.assert_allclose(np.exp(1j * np.deg2rad(wph[orig])), np.exp(1j * np.deg2rad(ph)), atol=1e-12)
    # one NaN break per crossing of −360° and −720°, the line reaching both edges at each
    breaks = np.flatnonzero(~ok)
    assert breaks.size == 2
    for b in breaks:
        assert wph[b - 1] == -360.0 and wph[b + 1] == 0.0
        assert wmag[b - 1] == wmag[b + 1]  # one crossing point, drawn on both edges
    assert np.max(np.abs(np.diff(wph[ok][:breaks[0] - 1]))) < 2.0  # no line across the chart
    with pytest.raises(ValueError, match="window"):
        nichols.wrap_phase(ph, mag, (0.0, -360.0))
    with pytest.raises(ValueError, match="shape"):
        nichols.wrap_phase(ph, mag[:-1])


def test_nichols_draw_shows_points_beyond_minus_360(template, bounds):
    import matplotlib.pyplot as plt

    _, cases, nom = template
    L = cases[nom] * G_PUBLISHED / (s / 2 + 1) ** 3  # three extra poles: the phase ends near −540°
    design_w = bounds.omega
    # independent phases: python-control's response, unwrapped from the low-frequency end
    grid = np.unique(np.r_[np.logspace(-3, 3, 3000), design_w])
    Lw = np.squeeze(ct.frequency_response(L, grid).complex)
    ph = np.degrees(np.unwrap(np.angle(Lw)))
    ph -= 360.0 * np.floor((ph[0] + 360.0) / 360.0)
    at_design = ph[np.searchsorted(grid, design_w)]
    assert np.any(at_design < -360.0), at_design  # the case issue 18 saw: beyond the chart
    ax = nichols.draw(bounds, loop=L, omega=grid)
    loop = next(ln for ln in ax.get_lines() if ln.get_label() == "nominal loop L0")
    x = np.asarray(loop.get_xdata(), float)
    assert np.all((x[np.isfinite(x)] >= -360.0) & (x[np.isfinite(x)] <= 0.0))
    assert np.isnan(x).any()  # broken where it wraps
    seg = np.split(x, np.flatnonzero(np.isnan(x)))
    assert max(np.max(np.abs(np.diff(p[np.isfinite(p)])), initial=0) for p in seg) < 20.0  # no jump across
    # every design-frequency marker is on the chart, at its phase modulo 360°
    markers = [ln for ln in ax.get_lines() if ln.get_marker() == "o" and len(ln.get_xdata()) == 1]
    got = np.array([ln.get_xdata()[0] for ln in markers])
    np.testing.assert_allclose(got, -360.0 + np.mod(at_design + 360.0, 360.0), atol=1e-9)
    assert np.all((got >= -360.0) & (got <= 0.0))
    # a window shifted by −180°: same wrapping, bounds repeated into it
    ax2 = nichols.draw(bounds, loop=L, omega=grid, xlim=(-540.0, -180.0), m_contours_db=[1.58])
    mc = next(ln for ln in ax2.get_lines() if ln.get_linestyle() == ":" and len(ln.get_xdata()) > 1)
    mx, my = np.asarray(mc.get_xdata(), float), np.asarray(mc.get_ydata(), float)
    ok = np.isfinite(mx) & np.isfinite(my)
    assert mx[ok].min() < -400.0 and mx[ok].max() > -250.0  # the contour fills the shifted window
    Lm = 10 ** (my[ok] / 20) * np.exp(1j * np.deg2rad(mx[ok]))
    np.testing.assert_allclose(20 * np.log10(np.abs(Lm / (1 + Lm))), 1.58, atol=1e-9)
    x2 = np.asarray(next(ln for ln in ax2.get_lines() if ln.get_label() == "nominal loop L0").get_xdata(), float)
    assert np.nanmin(x2) >= -540.0 and np.nanmax(x2) <= -180.0
    bound_x = np.concatenate([ln.get_xdata() for ln in ax2.get_lines() if ln.get_color() != "k" and len(ln.get_xdata()) > 1
                              and ln.get_linestyle() in ("-", "--") and ln.get_label() != "nominal loop L0"])
    assert np.nanmin(bound_x) < -360.0 < np.nanmax(bound_x)  # bounds drawn on both sides of −360°
    with pytest.raises(ValueError, match="window"):
        nichols.draw(bounds, xlim=(0.0, -360.0))
    plt.close("all")


def test_design_nichols_wraps_the_designed_loops(design):
    import matplotlib.pyplot as plt

    from specdesign.plots.qft import plot_design_nichols

    fig = plot_design_nichols(design)
    for ax, c, tpl in zip(fig.axes, (design.pitch_controller, design.atd_controller), (design.pitch_template, design.atd_template)):
        ph, _ = nichols.loop_nichols(c * tpl.systems[tpl.nominal], np.logspace(-3, 1.5, 3000))
        x = np.asarray(next(ln for ln in ax.get_lines() if ln.get_label() == "nominal loop L0").get_xdata(), float)
        assert np.all((x[np.isfinite(x)] >= -360.0) & (x[np.isfinite(x)] <= 0.0))
        if ph.min() < -360.0:  # this design's loops do run past −360° (both, at 19 m/s)
            assert np.isnan(x).any()
    plt.close("all")


# ----------------------------------------------------------------------------- Bode verdicts
def test_design_bode_says_which_spec_the_design_meets(design, model):
    import matplotlib.pyplot as plt

    from specdesign import closedloop
    from specdesign.plots.qft import plot_design_bode

    w = np.logspace(-2, 1, 300)
    fig = plot_design_bode(design, model, omega=w)
    tower_labels = fig.axes[1].get_legend_handles_labels()[1]
    qft_label = next(lab for lab in tower_labels if lab.startswith("QFT"))
    # independent verdict: the design's nominal |T_MyT,w| against each tower spec on the same grid
    t = np.abs(closedloop.frequency_response(design.closed_loop, w, "tower_base_my"))
    for name, spec in (("relaxed W_y", design.tower_spec), ("shaped W_y", design.shaping.specification)):
        excess = np.max(20 * np.log10(t / np.abs(spec.response(w))))
        word = "meets" if excess <= 0 else "above"
        assert f"{word} {name}" in qft_label, (name, excess, qft_label)
    checked = [lab for lab in tower_labels if "checked against" in lab]
    assert len(checked) == 1 and "relaxed" in checked[0]
    assert f"{design.options['tower_relax_omega']:g} rad/s" in checked[0]
    speed_labels = fig.axes[0].get_legend_handles_labels()[1]
    assert any(f"ROSCO + {design.options['speed_relax_db']:g} dB" in lab for lab in speed_labels)
    assert design.message in fig.axes[0].get_title()
    plt.close("all")


def test_fig10_as_notebook_06_draws_it_has_no_shared_style(campaign):
    """Notebook 06 adds the promise ("^:", C2) and the target to plot_reductions' axes: the issue's
    'two series share one style in Fig. 10' was that promise taking the linearised rainflow's look."""
    import matplotlib.pyplot as plt

    from specdesign import validate as va
    from specdesign.plots.validation import plot_reductions

    acc = va.acceptance(campaign, "ATD", "ROSCO")
    ax = plot_reductions(acc)
    ax.plot([19.0], [12.0], "^:", color="C2", label="notch specification's promise")  # the notebook's own lines
    ax.axhline(25.0, color="0.5", lw=0.8, ls="-.", label="design target (25 %)")
    ax.legend(fontsize="small")
    _check_figure(ax, "(m/s)", ["(%)"], ["rainflow, linearised model", "Volterra prediction", "notch specification's promise",
                                        "design target"])
    plt.close("all")


# ----------------------------------------------------------------------------- one set of conventions
def test_transfer_function_figures_share_one_db_reference(design, model):
    # the issue "Layers without cycles ... figures that say the truth": the tower transfer
    # function was in dB re 1 kN·m/(m/s) in the specification figure and dB re 1 N·m/(m/s) in
    # the design's Bode figure, 60 dB apart; both are SI now, and the same |T| reads the same
    import matplotlib.pyplot as plt

    from specdesign.plots.conventions import tf_magnitude_label
    from specdesign.plots.qft import plot_design_bode
    from specdesign.plots.spec import plot_specification
    from specdesign.spec import baseline_analysis

    base = baseline_analysis(model, 19.0)
    ax = plot_specification(base)
    assert ax.get_ylabel() == tf_magnitude_label("tower_base_my") == "magnitude (dB re 1 N·m/(m/s))"
    y_spec = ax.get_lines()[0].get_ydata()
    assert np.allclose(y_spec, 20 * np.log10(np.abs(base.t_response)))  # no display factor
    fig = plot_design_bode(design, model)
    assert "dB re 1 N·m/(m/s)" in fig.axes[1].get_ylabel()
    plt.close("all")


def test_spectra_show_the_band_of_the_loads(campaign):
    # Fig. 8 drew up to the record's Nyquist frequency, where the Welch estimate rolls off to
    # 1e-18 and squeezed the 0.1-2 rad/s band; now ω ≤ SPECTRA_MAX_OMEGA and the magnitude axis
    # spans the drawn curves (a factor 3 margin each side)
    import matplotlib.pyplot as plt

    from specdesign.plots.validation import SPECTRA_MAX_OMEGA, plot_spectra

    ax = plot_spectra(campaign, 19.0, "gen_speed")
    xs = np.concatenate([ln.get_xdata() for ln in ax.get_lines()])
    ys = np.concatenate([ln.get_ydata() for ln in ax.get_lines()])
    assert xs.max() <= SPECTRA_MAX_OMEGA
    lo, hi = ax.get_ylim()
    assert lo == pytest.approx(ys[ys > 0].min() / 3) and hi == pytest.approx(ys.max() * 3)
    plt.close("all")


def test_fig10_reads_reductions_against_zero(campaign):
    # fig10 cut its axis to 33.5-37 %: a 2 pp spread looked like a factor of two
    import matplotlib.pyplot as plt

    from specdesign import validate as va
    from specdesign.plots.conventions import show_se
    from specdesign.plots.validation import plot_reductions

    acc = va.acceptance(campaign, "ATD", "ROSCO")
    ax = plot_reductions(acc)
    assert ax.get_ylim()[0] <= 0.0 <= ax.get_ylim()[1]
    assert "(%), positive: lower" in ax.get_ylabel()
    label = next(t for t in ax.get_legend_handles_labels()[1] if t.startswith("rainflow, nonlinear"))
    assert ("±1 SE" in label) == show_se(acc.n_seeds)
    plt.close("all")


def test_the_validation_figures_are_one_file_each_with_the_promise(campaign, tmp_path, monkeypatch):
    # fig9 duplicated the demo's 4_time_series (and fig8 its 4_spectra) when a validation was
    # written into the demo's folder: both now write through save_validation_figures, under
    # one name per figure, so a second writer replaces the first's files
    from pathlib import Path

    import matplotlib.image

    from specdesign import validate as va
    from specdesign.plots import validation as pv

    drawn = []
    plot_reductions = pv.plot_reductions
    monkeypatch.setattr(pv, "plot_reductions", lambda acc, **kw: drawn.append(kw) or plot_reductions(acc, **kw))
    acc = va.acceptance(campaign, "ATD", "ROSCO")
    first = pv.save_validation_figures(campaign, tmp_path, acc, promised={19.0: 12.0})  # the demo
    again = pv.save_validation_figures(campaign, tmp_path, acc, promised={19.0: 12.0})  # validate --out there
    assert [f.name for f in first] == [f.name for f in again] == ["fig8_19mps.png", "fig9_19mps.png", "fig10.png"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f.name for f in first)
    assert matplotlib.image.imread(first[1]).shape[:2] == (960, 960)  # fig9: the 8 × 8 in time series at 120 dpi
    assert drawn[0]["promised"] == {19.0: 12.0}  # fig10 with the promise
    # the demo and the command line draw these figures through it, never a second time
    root = Path(pv.__file__).parents[1]
    for name in ("demo.py", "cli.py"):
        src = (root / name).read_text()
        assert "save_validation_figures(" in src and "plot_time_series(" not in src and "plot_spectra(" not in src, name
