"""The live figures' fast paths draw what the slow paths draw (issue 30: a slider step in ≤ 150 ms).

Three shortcuts make a slider step cheap, and each is checked against the path it replaces on a
sweep of slider values: the QFT bounds checker's precomputed brackets (the oracle: the same
checker without them, one exact bound computation per check), the blit's cache of rendered
text lines (the oracle: the same artists drawn on the same background without the cache, pixel
for pixel) and the live canvas's PNG encoder of the changed pixels (the oracle: matplotlib's
own image of them, decoded). Their speed is measured in benchmarks/bench_redraw.py, never
asserted here.
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
from loopshaping.interactive import Designer  # noqa: E402
from specdesign import spec  # noqa: E402
from specdesign.plots.spec import NotchExplorer  # noqa: E402
from specdesign.qft import boundscheck  # noqa: E402
from specdesign.turbine import iea15mw  # noqa: E402

#: notch explorer slider values (ω_n rad/s, depth dB, width ζ_p): across the tower mode and the
#: low frequencies where integral action makes bounds empty, shallow to deep, narrow to wide
SWEEP = [(w, depth, z) for w in (0.05, 0.3, 1.0, 1.05, 1.08, 2.0) for depth in (0.0, 0.1, 3.0, 12.0, 30.0)
         for z in (0.02, 0.2, 1.0)]


@pytest.fixture(scope="module")
def model():
    return iea15mw()


@pytest.fixture(scope="module")
def base(model):
    return spec.baseline_analysis(model, 19.0)


@pytest.fixture(scope="module")
def checkers(model):
    """(precomputed, exact): the same checker twice, one of them bracketed."""
    return boundscheck.bounds_checker(model, 19.0).precompute(), boundscheck.bounds_checker(model, 19.0)


def test_precomputed_bounds_checks_give_the_exact_verdicts_without_computing_bounds(checkers, monkeypatch):
    fast, exact = checkers
    verdicts = [exact.check(exact.rosco_nominal * spec.Notch(*n).response(exact.template.omega)) for n in SWEEP]
    assert any(v.feasible for v in verdicts) and not all(v.feasible for v in verdicts)  # the sweep crosses
    assert len({tuple(v.empty) for v in verdicts}) > 3  # ... at different frequencies
    computed = []
    monkeypatch.setattr(boundscheck.lqft, "bounds", lambda *a, **k: computed.append(1))  # any call is counted
    for n, want in zip(SWEEP, verdicts):
        got = fast.check(fast.rosco_nominal * spec.Notch(*n).response(fast.template.omega))
        np.testing.assert_array_equal(got.empty, want.empty, err_msg=str(n))
        assert got.feasible == want.feasible and np.array_equal(got.omega, want.omega)
    assert not computed  # every ratio of the sweep lay outside its bracket: comparisons only


def test_a_ratio_inside_a_bracket_or_outside_the_seeds_is_computed_exactly(checkers):
    fast, exact = checkers
    i = int(np.argmax(np.isfinite(fast._empty_up_to) & np.isfinite(fast._feasible_from)))
    for scale in (np.sqrt(fast._empty_up_to[i] * fast._feasible_from[i]), 1e-5, 50.0):  # in a bracket; below; above
        vals = exact.rosco_nominal * scale
        np.testing.assert_array_equal(fast.check(vals).empty, exact.check(vals).empty)
    with pytest.raises(ValueError, match="lowest"):
        exact.precompute(lowest=1.0, highest=0.5)
    with pytest.raises(ValueError, match="halvings"):
        exact.precompute(halvings=-1)


def test_the_explorer_draws_and_says_what_the_exact_checks_give(base, model):
    # the explorer precomputes its checker; the reference explorer keeps an exact one (its
    # precompute a no-op): verdicts, line, marker, title and legend equal along the sweep
    exact_only = boundscheck.bounds_checker(model, 19.0)
    exact_only.precompute = lambda: exact_only
    fast_ex = NotchExplorer(base, bounds_checker=boundscheck.bounds_checker(model, 19.0), live=False)
    slow_ex = NotchExplorer(base, bounds_checker=exact_only, live=False)
    try:
        for n in SWEEP:
            a, b = fast_ex.update(*n, redraw=False), slow_ex.update(*n, redraw=False)
            assert a == b
            np.testing.assert_array_equal(fast_ex.bounds_verdict.empty, slow_ex.bounds_verdict.empty)
            np.testing.assert_array_equal(fast_ex.line.get_ydata(), slow_ex.line.get_ydata())
            np.testing.assert_array_equal(fast_ex.marker.get_xdata(), slow_ex.marker.get_xdata())
            assert fast_ex.ax_mag.get_title() == slow_ex.ax_mag.get_title()
            assert fast_ex._legend_text.get_text() == slow_ex._legend_text.get_text()
    finally:
        plt.close(fast_ex.fig)
        plt.close(slow_ex.fig)


def _uncached_blit(live):
    """The blit as before the text cache: the background, then every artist drawn in full."""
    canvas = live.figure.canvas
    canvas.restore_region(live._background)
    for a in live.artists:
        live.figure.draw_artist(a)
    return np.asarray(canvas.buffer_rgba()).copy()


@pytest.mark.parametrize("dpi", [100, 163])  # matplotlib's default; a high-density screen's (ipympl scales)
def test_cached_text_lines_blit_the_same_pixels_as_drawing_them(base, dpi):
    # the explorer's title (three lines, the first changing) and legend (plain text and
    # mathtext), blitted with the text cache, pixel for pixel the same as drawn without it;
    # revisited values come from the cache
    ex = NotchExplorer(base, live=True)
    try:
        ex.fig.set_dpi(dpi)
        ex.fig.canvas.draw()
        moves = [(1.05, d, 0.2) for d in (3.0, 6.0, 3.0, 9.0, 6.0, 17.3, 29.9)] + [(w, 6.0, z) for w in (0.5, 1.0, 0.5)
                                                                                  for z in (0.02, 0.47)]
        for n in moves:
            ex.update(*n)
            cached = np.asarray(ex.fig.canvas.buffer_rgba()).copy()
            np.testing.assert_array_equal(cached, _uncached_blit(ex._redraw), err_msg=str(n))
        assert ex._redraw._text.hits > 0 and ex._redraw._text.misses > 0
    finally:
        plt.close(ex.fig)


def test_the_designers_title_lines_blit_the_same_pixels_as_drawing_them():
    # a gain step changes one line of the Designer's title (G = ...), an unstable gain its
    # verdict too: every blit equals the uncached drawing of the same artists
    P = [ct.tf([k], [1, 31, 30]) for k in (1.0, 5.0, 10.0)]
    tmpl = qft.Template.from_systems(P, np.array([0.1, 5.0, 100.0]))
    b = qft.intersect(qft.bounds(tmpl, "stability", 1.2), qft.bounds(tmpl, "sensitivity", 2.0))
    G = lc.Controller((lc.gain(379.0), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5), lc.real_pole(300.0)))
    d = Designer(b, tmpl, G)
    fig = d.draw(live=True)
    try:
        fig.canvas.draw()
        for k in (379.0, 400.0, -50.0, 400.0, 379.0, 1e5, 379.0):
            d.set_param(0, k=k)
            cached = np.asarray(fig.canvas.buffer_rgba()).copy()
            np.testing.assert_array_equal(cached, _uncached_blit(d._redraw), err_msg=f"k={k}")
        text = d._redraw._text
        assert text.hits >= 7 and text.misses > 0  # the unchanged lines of every step came from the cache
    finally:
        plt.close(fig)


@pytest.mark.filterwarnings("ignore:Passing unrecognized arguments:DeprecationWarning")  # ipympl's toolbar, in traitlets
def test_the_live_canvas_sends_the_images_matplotlib_would_encoded_faster():
    # after each blit ipympl's canvas sends the changed pixels as a PNG; LiveArtists gives it a
    # faster encoder (loopshaping._diffpng). The oracle: matplotlib's own get_diff_image from
    # the same pixels and the same last image, decoded by Pillow: the same pixels, the same
    # mode (the first image full, a gain step's a difference)
    import io

    from matplotlib.backends.backend_webagg_core import FigureCanvasWebAggCore
    from PIL import Image

    from loopshaping import _diffpng

    def decoded(png):
        return np.asarray(Image.open(io.BytesIO(png)).convert("RGBA"))

    P = [ct.tf([k], [1, 31, 30]) for k in (1.0, 5.0, 10.0)]
    tmpl = qft.Template.from_systems(P, np.array([0.1, 5.0, 100.0]))
    b = qft.intersect(qft.bounds(tmpl, "stability", 1.2), qft.bounds(tmpl, "sensitivity", 2.0))
    G = lc.Controller((lc.gain(379.0), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5), lc.real_pole(300.0)))
    plt.switch_backend("module://ipympl.backend_nbagg")  # closes every figure
    try:
        d = Designer(b, tmpl, G)
        d.widget()
        canvas = d.figure.canvas
        assert canvas.get_diff_image.__func__ is _diffpng._diff_image
        canvas.syncing_data_url = False  # the browser's view said it is initialised
        sent = []
        canvas.send = lambda content, buffers=None: sent.extend(buffers or [])  # the comm to the browser
        modes = []
        for k in (None, 379.0, 400.0, -50.0, 1e5, 379.0):
            last, full = canvas._last_buff.copy(), canvas._force_full
            if k is None:
                canvas.draw()  # the first render: a full image
            else:
                d.set_param(0, k=k)  # a blit: the changed pixels
            assert d._redraw.ready and len(sent) == 1  # one image an edit
            modes.append(canvas._current_image_mode)
            canvas._last_buff, canvas._force_full, canvas._png_is_old = last, full, True
            want = FigureCanvasWebAggCore.get_diff_image(canvas)
            assert canvas._current_image_mode == modes[-1]
            np.testing.assert_array_equal(decoded(sent.pop()), decoded(want), err_msg=f"k={k}")
        assert modes == ["full"] + ["diff"] * 5
    finally:
        plt.switch_backend("Agg")
    assert not _diffpng.install_encoder(plt.figure().canvas)  # Agg's canvas sends nothing: left as it is
    plt.close("all")
    with pytest.raises(ValueError, match="pixels"):
        _diffpng.png_rgba(np.zeros((4, 3, 3), np.uint8))  # RGB, not RGBA
