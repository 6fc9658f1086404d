"""The interactive loop: the QFT Designer's live stability check and controls, the notch explorer's sliders.

Oracles: the closed-loop poles of 1 + L from python-control's ``feedback`` (an independent
interconnection) and, for a first-order loop, the root in closed form; the promise of the
starting notch by :func:`specdesign.spec.promise_of` on the same notch.
"""
from __future__ import annotations

import control as ct
import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from loopshaping import controller as lc  # noqa: E402
from loopshaping import qft  # noqa: E402
from loopshaping.interactive import Designer, closed_loop_poles  # noqa: E402


@pytest.fixture
def loop():
    plt.close("all")  # figure counts in the tests are theirs
    P = [ct.tf([k], [1, 31, 30]) for k in (1.0, 5.0, 10.0)]
    tmpl = qft.Template.from_systems(P, np.array([0.1, 5.0, 100.0]))
    yield P, tmpl, qft.bounds(tmpl, "stability", 1.2, name="margins |S| ≤ 1.2")
    plt.close("all")


def test_bounds_met_but_unstable_is_shown_red_naming_the_case_and_the_pole():
    # L = −100/(s + 1): |S| = |(s+1)/(s−99)| < 1.2 at every design frequency, yet 1 + L = 0 at
    # s = +99 (the sign error behind "all bounds met" with a pole at +322 in issue 18)
    plt.close("all")  # the figure count below is this test's
    P = ct.tf([1.0], [1.0, 1.0])
    tmpl = qft.Template.from_systems([P, 2 * P], np.array([0.1, 1.0, 5.0]))
    b = qft.bounds(tmpl, "stability", 1.2)
    d = Designer(b, tmpl, lc.Controller((lc.gain(-100.0),)))
    fig = d.draw(live=False)
    st = d.state()
    assert st.bounds_met and not st.all_stable
    np.testing.assert_allclose(st.rightmost_pole, [99.0, 199.0], rtol=1e-12)  # s + 1 − 100k = 0
    title = d._artists["title"]
    assert title.get_text().startswith("UNSTABLE: plant case 1 of 2: closed-loop pole at +199")
    assert "all bounds met" not in title.get_text() and matplotlib.colors.same_color(title.get_color(), "tab:red")
    st = d.set_param(0, k=100.0)
    assert st.all_stable and title.get_text().startswith("all bounds met, all 2 plant case(s) stable")
    assert matplotlib.colors.same_color(title.get_color(), "black")
    assert len(plt.get_fignums()) == 1 and fig is d.figure


def test_closed_loop_poles_match_python_control_for_every_case(loop):
    P, tmpl, b = loop
    G = lc.Controller((lc.gain(379.0), lc.integrator(1), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5)))
    d = Designer(b, tmpl, G)
    st = d.state()
    for c, p in enumerate(P):
        want = ct.feedback(G.tf() * p).poles()
        got = closed_loop_poles(tuple(np.asarray(m) for m in (ct.ss(p).A, ct.ss(p).B, ct.ss(p).C, ct.ss(p).D)),
                                *G.polys())
        np.testing.assert_allclose(np.sort_complex(got), np.sort_complex(want), rtol=1e-8)
        assert st.rightmost_pole[c] == pytest.approx(want[np.argmax(want.real)], rel=1e-8)
        assert st.stable[c] == (want.real.max() < 0)
    # an improper controller: stability undecided, said so, never "stable"
    st = d.set_controller(lc.Controller((lc.gain(1.0), lc.differentiator(1))))
    assert not st.stable.any() and np.isnan(st.rightmost_pole).all()
    with pytest.raises(ValueError, match="proper"):
        closed_loop_poles((np.zeros((1, 1)),) * 4, [1.0, 0.0], [1.0])


def test_the_title_names_each_spec_checked_and_where_it_fails(loop):
    P, tmpl, b = loop
    both = qft.intersect(b, qft.bounds(tmpl, "sensitivity", 0.5, name="|S| ≤ 0.5"))
    d = Designer(both, tmpl, lc.Controller((lc.gain(379.0), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5))))
    st = d.state()
    # per spec, from the bounds of that spec alone (Bounds.is_allowed: the oracle)
    for bs, name in ((b, "margins |S| ≤ 1.2"), (qft.bounds(tmpl, "sensitivity", 0.5, name="|S| ≤ 0.5"), "|S| ≤ 0.5")):
        L0 = P[0](1j * bs.omega) * d.controller.response(bs.omega)
        ok = bs.is_allowed(bs.omega, np.degrees(np.angle(L0)), 20 * np.log10(np.abs(L0)))
        np.testing.assert_array_equal(st.spec_violations[name], bs.omega[~ok])
    assert "specs checked: margins |S| ≤ 1.2: " in d._title(st) and "|S| ≤ 0.5: " in d._title(st)


def test_gain_and_frequency_controls_move_in_log_steps_and_keep_typed_values(loop):
    P, tmpl, b = loop
    d = Designer(b, tmpl, lc.Controller((lc.gain(-379.0), lc.real_zero(42.0), lc.notch(5.0, 0.05, 0.5))))
    ui = d.widget()
    select, _, rows, json_box, msg = ui.children[0].children
    assert len(ui.children) == 2 and len(plt.get_fignums()) == 1  # one figure
    slider, text = rows.children[0].children
    # ±1 decade around |k|, steps of 0.005 decade (1.2 %); the sign of a negative gain is kept
    assert (slider.min, slider.max, slider.step) == pytest.approx((np.log10(379) - 1, np.log10(379) + 1, 0.005))
    one_step = 10 ** (np.log10(379.0) + 0.005)
    slider.value = one_step
    assert d.controller.elements[0].params["k"] == -one_step and text.value == -one_step
    text.value = -1234.5678901  # typed: kept exactly, beyond the slider's range (it re-centres)
    assert d.controller.elements[0].params["k"] == -1234.5678901
    assert 10 ** slider.min <= 1234.5678901 <= 10 ** slider.max and slider.value == 1234.5678901
    slider.value = 10 ** (0.005 * round(np.log10(1234.5678901) / 0.005))  # the browser's rounded echo
    assert d.controller.elements[0].params["k"] == -1234.5678901
    assert '"k": -1234.5678901' in json_box.value
    text.value = 0.0  # refused with a message, the gain unchanged
    assert "rejected" in msg.value and d.controller.elements[0].params["k"] == -1234.5678901
    select.value = 2  # the notch: a linear slider on ζ, an invalid typed ζ refused
    zeta_zero = rows.children[1].children[1]
    zeta_zero.value = -0.1  # a negative damping ratio
    assert "rejected" in msg.value and d.controller.elements[2].params["zeta_zero"] == 0.05


def test_the_notch_explorer_keeps_its_starting_notch_and_has_no_redraw_box():
    from specdesign import spec
    from specdesign.plots.spec import NotchExplorer
    from specdesign.turbine import iea15mw

    plt.close("all")
    base = spec.baseline_analysis(iea15mw(), 19.0)
    start = spec.Notch(1.0712345678, 7.8312345, 0.23456789)
    ex = NotchExplorer(base, start)
    want = spec.promise_of(start.response(base.omega), base)
    ui = ex.widget()
    sliders = ui.children[0].children
    assert [s.description for s in sliders] == ["ω_n (rad/s)", "depth (dB)", "width ζ_p"]  # no "redraw" checkbox
    assert len(plt.get_fignums()) == 1
    assert ex.promise == want and ex.notch == start
    # the browser rounds each slider to its step and echoes it: the starting notch stays exact
    sliders[0].value = 10 ** (0.005 * round(np.log10(start.omega_n) / 0.005))
    sliders[1].value = round(start.depth_db, 1)
    sliders[2].value = round(start.width, 2)
    assert ex.notch == start and ex.promise == want
    sliders[1].value = 12.0  # a real move
    assert ex.notch == spec.Notch(1.0712345678, 12.0, 0.23456789)
    assert ex.promise == spec.promise_of(ex.notch.response(base.omega), base)
    assert "12 dB" in ex.line.get_label() and f"{ex.promise.exact_damage:.1f} %" in ex.ax_mag.get_title()
    # update() from code (a later cell) moves the sliders; a late echo of the first rounding,
    # arriving after it, is not a move either (it was: notebook 03 showed 15.3 % for 15.0 %)
    ex.update(1.05, 9.0, 0.2)
    assert [s.value for s in sliders] == [1.05, 9.0, 0.2]
    sliders[1].value = round(12.0 + 0.04, 1)  # the echo of 12.0, from before the update
    sliders[2].value = round(start.width, 2)
    assert ex.notch == spec.Notch(1.05, 9.0, 0.2)
    # and the sliders show what the figure draws, not the late echo (notebook 03 after Run All
    # showed a 2.80 dB slider over a 12 dB notch, and the first touch jumped from there)
    assert [s.value for s in sliders] == [1.05, 9.0, 0.2]
    sliders[1].value = 15.0  # a move again
    assert ex.notch == spec.Notch(1.05, 15.0, 0.2)
    plt.close("all")


def test_notebooks_with_live_controls_enable_the_widget_backend():
    # every notebook with a live control turns the ipympl backend on itself, before the control
    # (tests/test_notebook_outputs.py checks that they are committed without outputs)
    import json
    from pathlib import Path

    notebooks = sorted((Path(__file__).resolve().parents[1] / "notebooks").glob("*.ipynb"))
    interactive = []
    for path in notebooks:
        nb = json.loads(path.read_text())
        code = ["".join(c["source"]) for c in nb["cells"] if c["cell_type"] == "code"]
        if any(".widget()" in s for s in code):
            interactive.append(path.stem)
            first = next(i for i, s in enumerate(code) if ".widget()" in s)
            assert any('run_line_magic("matplotlib", "widget")' in s for s in code[:first]), path.name
    assert {"00_qft_toolbox_example", "03_specification", "04_qft_design"} <= set(interactive)


def test_design_points_past_minus_360_degrees_stay_on_the_chart():
    # P = 1/(s+1)^5: at 10 rad/s the loop phase is −5·atan(10) = −420.5°, drawn at −60.5° (the
    # bounds repeat every 360°); the numbers in the state keep the unwrapped phase
    P = ct.tf([1.0], np.poly([-1.0] * 5))
    w = np.array([0.1, 1.0, 10.0])
    tmpl = qft.Template.from_systems([P], w)
    d = Designer(qft.bounds(tmpl, "stability", 2.0), tmpl, lc.Controller((lc.gain(0.5),)))
    d.draw()
    st = d.state()
    want = -5 * np.degrees(np.arctan(w))
    np.testing.assert_allclose(st.phase_deg[d._design_idx], want, atol=1e-9)
    x = d._artists["marks"].get_offsets()[:, 0]
    np.testing.assert_allclose(x, np.where(want < -360, want + 360, want), atol=1e-9)
    lo, hi = d.figure.axes[0].get_xlim()
    loop_x = d._artists["loop"].get_xdata()
    assert np.all((loop_x[np.isfinite(loop_x)] >= lo) & (loop_x[np.isfinite(loop_x)] <= hi))
    plt.close("all")


def test_the_designer_views_cover_the_design_and_key_many_bound_colours():
    # the issue "Layers without cycles ... widgets that tell the truth": the Designer's Nichols
    # panel spanned −250 to +60 dB (the loop's roll-off ×100 above the band), its closed-loop
    # panel 1e-4 to 1e3 rad/s, and 77 bound colours had no key
    P = ct.tf([1.0], [1.0, 1.4, 1.0])
    w = np.geomspace(0.05, 5.0, 24)
    tmpl = qft.Template.from_systems([0.8 * P, P, 1.25 * P], w)
    d = Designer(qft.bounds(tmpl, "stability", 1.3), tmpl, lc.Controller((lc.gain(2.0), lc.integrator())))
    fig = d.draw()
    ax_n, ax_b = fig.axes[0], fig.axes[1]
    assert ax_b.get_xlim() == pytest.approx((w.min() / 3, w.max() * 3))
    st = d.state()
    band = (d.omega >= w.min() / 3) & (d.omega <= w.max() * 3)
    lo, hi = ax_n.get_ylim()
    # every loop magnitude in the band is in view, with the 10 dB margin, and no more than that
    # beyond the bounds (the roll-off far above it is not what the view is sized for)
    assert lo <= st.magnitude_db[band].min() - 10 + 1e-9 and hi >= st.magnitude_db[band].max() + 10 - 1e-9
    assert lo > st.magnitude_db.min()
    keys = [a for a in fig.axes if a.get_ylabel() == "bound frequency ω (rad/s)"]
    assert len(keys) == 1  # 24 frequencies on a continuous colour map: a colour key says which is which
    lo_k, hi_k = keys[0].get_ylim()
    assert (lo_k, hi_k) == pytest.approx((w.min(), w.max()))
    plt.close("all")


def test_the_designer_controls_follow_an_edit_made_from_code(loop):
    # a later cell's ``designer.set_param`` (notebook 04 sets the gain 20 dB high and back): the
    # controls show the controller the figure draws, not the one they were built with
    P, tmpl, b = loop
    d = Designer(b, tmpl, lc.Controller((lc.gain(-379.0), lc.real_zero(42.0))))
    ui = d.widget()
    select, _, rows, json_box, _ = ui.children[0].children
    d.set_param(0, k=-4321.0)
    slider, text = rows.children[0].children
    assert slider.value == 4321.0 and text.value == -4321.0 and slider.description == "k (−)"
    assert json_box.value == d.controller.to_json()
    select.value = 1
    d.set_param(1, omega=7.5)  # the element shown is the one edited
    slider, text = rows.children[0].children
    assert slider.value == 7.5 and text.value == 7.5 and select.value == 1
    assert select.options[1][0] == f"1: {d.controller.elements[1]}"
    d.remove(1)  # from code: the list shrinks, the selection stays on an element
    assert len(select.options) == 1 and select.value == 0 and rows.children[0].children[1].value == -4321.0


def test_live_redraw_blits_the_changing_artists_and_full_renders_keep_them(loop):
    # the Designer's redraw on a live canvas: the bounds are a cached background, an edit
    # redraws the loop alone; a full render (a resize, a toolbar zoom) still draws every artist,
    # on top as the blit does, and savefig as a figure drawn without blitting (live=False)
    import io

    from loopshaping.interactive import LiveArtists

    P, tmpl, b = loop
    G = lc.Controller((lc.gain(379.0), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5)))

    def pixels(fig):
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba()).copy()

    live, still = Designer(b, tmpl, G), Designer(b, tmpl, G)
    fig_live, fig_still = live.draw(live=True), still.draw(live=False)
    assert isinstance(live._redraw, LiveArtists) and live._redraw.live and not still._redraw.live
    assert all(a.get_animated() for a in live._artists.values())
    before = pixels(fig_live)  # the first full render caches the background
    for d in (live, still):
        d.set_param(0, k=150.0)
    blitted = np.asarray(fig_live.canvas.buffer_rgba()).copy()  # the blit, no full render since
    assert not np.array_equal(blitted, before)
    np.testing.assert_array_equal(blitted, pixels(fig_live))
    # the same pixels as the still figure's but where the changing artists overlap others
    assert np.mean(np.any(blitted != pixels(fig_still), axis=-1)) < 0.005
    saved = [io.BytesIO(), io.BytesIO()]
    fig_live.savefig(saved[0], format="png")
    fig_still.savefig(saved[1], format="png")
    for f in saved:
        f.seek(0)
    np.testing.assert_array_equal(plt.imread(saved[0]), plt.imread(saved[1]))
    assert np.isfinite(live.update_ms) and live.update_ms > 0


def test_the_designer_colour_key_leaves_the_closed_loop_panel_its_labels():
    # notebook 04 in the browser: the key's label "bound frequency ω (rad/s)" was written over
    # the closed-loop panel's "closed-loop magnitude (dB)"
    P = ct.tf([1.0], [1.0, 1.4, 1.0])
    tmpl = qft.Template.from_systems([0.8 * P, P, 1.25 * P], np.geomspace(0.05, 5.0, 24))
    d = Designer(qft.bounds(tmpl, "stability", 1.3), tmpl, lc.Controller((lc.gain(2.0), lc.integrator())))
    fig = d.draw()
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    key = next(ax for ax in fig.axes if ax.get_ylabel() == "bound frequency ω (rad/s)")
    ax_b = fig.axes[1]
    assert key.get_tightbbox(renderer).x1 < ax_b.get_tightbbox(renderer).x0
    plt.close(fig)


def test_a_live_figure_asks_for_no_full_render_when_an_edit_blits(monkeypatch):
    # in JupyterLab notebook 03's kernel rendered the explorer without end (busy for minutes):
    # drawing the legend on top left the figure "stale", and pyplot redraws every stale figure
    # after each message the kernel handles, the browser's render request included; and
    # pyplot's interactive mode asked for a full render on every change of the legend's text
    from specdesign import spec
    from specdesign.plots.spec import NotchExplorer
    from specdesign.turbine import iea15mw

    plt.close("all")
    base = spec.baseline_analysis(iea15mw(), 19.0)
    with plt.ion():
        ex = NotchExplorer(base, live=True)
        ex.fig.canvas.draw()
        assert not ex.fig.stale  # a render leaves nothing for pyplot's post-execute redraw
        requests = []
        monkeypatch.setattr(ex.fig.canvas, "draw_idle", lambda *a, **k: requests.append(1))
        ex.update(1.1, 9.0, 0.3)  # the line, marker, title and legend text change: one blit
        assert ex._redraw.ready and requests == [] and not ex.fig.stale
        assert "9 dB" in ex._legend_text.get_text()
        ex.fig.axes[0].set_xlim(0.01, 10.0)  # a change from code: drawn after the cell, as pyplot does
        assert requests == [] and ex.fig.stale
    plt.close("all")


@pytest.fixture
def ipympl_canvas():
    """Figures on ipympl's canvas as in JupyterLab, the browser's end a no-op; Agg again after."""
    plt.switch_backend("module://ipympl.backend_nbagg")  # closes every figure

    def as_in_the_browser(fig):
        canvas = fig.canvas
        canvas.syncing_data_url = False  # the browser's view said it is initialised
        canvas.send = lambda *args, **kwargs: None
        canvas.draw()
        return canvas

    yield as_in_the_browser
    plt.switch_backend("Agg")


def _ink_in(rgba, text, renderer):
    """Whether an image (RGBA, 0-255 or 0-1) has a non-white pixel inside a text's box."""
    box = text.get_window_extent(renderer)
    h = rgba.shape[0]
    part = np.asarray(rgba)[max(int(h - box.y1), 0):int(np.ceil(h - box.y0)), int(box.x0):int(np.ceil(box.x1)), :3]
    return bool(np.any(part < (250 if part.dtype == np.uint8 else 250 / 255)))


def _saved(fig):
    import io

    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    buf.seek(0)
    return plt.imread(buf)


@pytest.mark.filterwarnings("ignore:Passing unrecognized arguments:DeprecationWarning")  # ipympl's toolbar, in traitlets
def test_the_designers_verdict_moves_to_a_readout_beside_a_live_figure_and_stays_in_saved_ones(loop, ipympl_canvas):
    # in a notebook with widgets the verdict lines (the figure's title before) are an HTML
    # readout above the live canvas, word for word summary()'s (the oracle: the title a figure on
    # its own draws); the canvas no longer draws them, at an edit or a full render, and a saved
    # figure still does, pixel for pixel as a figure drawn without blitting (live=False)
    from loopshaping.interactive import readout_html

    P, tmpl, b = loop
    G = lc.Controller((lc.gain(379.0), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5)))
    d = Designer(b, tmpl, G)
    ui = d.widget()
    controls, readout, fig_box = ui.children
    assert fig_box is d.figure.canvas and d._redraw.live
    canvas = ipympl_canvas(d.figure)
    title = d._artists["title"]
    assert title not in d._redraw.artists  # the blit draws the loop, markers and closed-loop lines only
    for k in (379.0, -100.0, 1e5):
        st = d.set_param(0, k=k)
        colour = "black" if st.all_stable and st.bounds_met else "tab:red"
        assert d.readout == d.summary() == title.get_text()
        assert readout.value == readout_html(d.summary(), colour)
        assert not _ink_in(canvas.buffer_rgba(), title, canvas.get_renderer())  # not on the canvas
    assert d.readout.startswith("UNSTABLE") and "#d62728" in readout.value  # k = 1e5, red as the title was
    canvas.draw()  # a full render (a resize, a zoom) leaves it out too
    assert not _ink_in(canvas.buffer_rgba(), title, canvas.get_renderer())
    saved = _saved(d.figure)
    assert _ink_in(saved, title, canvas.get_renderer())
    plt.close(d.figure)
    static = Designer(b, tmpl, G)  # its views set by the same starting controller
    static.draw(live=False)
    static.set_param(0, k=1e5)
    np.testing.assert_array_equal(saved, _saved(static.figure))


@pytest.mark.filterwarnings("ignore:Passing unrecognized arguments:DeprecationWarning")  # ipympl's toolbar, in traitlets
def test_the_explorers_changing_text_moves_to_a_readout_beside_a_live_figure(ipympl_canvas):
    # the notch's parameters (the legend label) and its promise and verdicts (the title) are an
    # HTML readout above the live canvas, word for word those a figure on its own draws (the
    # oracle: an explorer drawn live=False at the same notch); the legend names the
    # specification only and is part of the background; a saved figure's title says it all
    from loopshaping.interactive import readout_html
    from specdesign import feasibility, spec
    from specdesign.plots.spec import NotchExplorer
    from specdesign.turbine import iea15mw

    model = iea15mw()
    base = spec.baseline_analysis(model, 19.0)
    # with the pitch checker: its verdict names where a notch is infeasible (notebook 03's)
    checker = feasibility.pitch_checkers(model, 19.0, spec.speed_specification(model, 19.0, margin_db=3.0),
                                         max_sensitivity=None)[0]
    ex = NotchExplorer(base, checker=checker)
    ui = ex.widget()
    sliders, readout, fig_box = ui.children
    assert fig_box is ex.fig.canvas
    canvas = ipympl_canvas(ex.fig)
    assert ex._redraw.artists == [ex.line, ex.marker]  # the data alone is blitted
    static = NotchExplorer(base, checker=checker, live=False)
    infeasible = []
    for n in ((1.05, 12.0, 0.2), (1.08, 30.0, 0.02), (0.8, 3.3, 0.5)):
        ex.update(*n)
        static.update(*n, redraw=False)
        where, *verdict = ex.readout.split("\n")
        assert static.line.get_label() == f"specification $|W_y|$: {where}"
        assert verdict == static.ax_mag.get_title().split("\n")
        assert readout.value == readout_html(ex.readout)
        infeasible.append("INFEASIBLE" in ex.readout)
        assert ex._legend_text.get_text() == "specification $|W_y|$ with the notch"
    assert any(infeasible) and not all(infeasible)  # the sweep met both verdicts (the deep notches infeasible)
    assert ex.ax_mag.get_title() == ex.readout  # drawn into a saved figure
    renderer = canvas.get_renderer()
    assert not _ink_in(canvas.buffer_rgba(), ex.ax_mag.title, renderer) and _ink_in(_saved(ex.fig), ex.ax_mag.title, renderer)
