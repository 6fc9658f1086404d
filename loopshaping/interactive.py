"""Interactive loop shaping in Jupyter (ipywidgets for the controls, ipympl for a live figure).

:class:`Designer` keeps a :class:`~loopshaping.controller.Controller`; every edit recomputes
the nominal loop on a dense grid, checks the bounds at the design frequencies exactly
(:meth:`~loopshaping.qft.Bounds.is_allowed`, spec by spec), computes the closed-loop poles of
1 + L for every plant case (stability is checked live, not assumed from the bounds) and updates
the line data of the Nichols chart and of the closed-loop magnitude plot (worst case over the
plant cases) without rebuilding the figure. The numbers live in :meth:`Designer.state`, so the
designer also works headless (tests, benchmarks). ipywidgets is imported only by
:meth:`Designer.widget`; with the ``%matplotlib widget`` backend (ipympl) the figure updates
live in the notebook, otherwise the widget re-displays a static figure after each edit.
"""
from __future__ import annotations

import textwrap
import time
from dataclasses import dataclass

import numpy as np

from ._designer_widget import build_widget, readout_html
from ._diffpng import install_encoder
from ._textcache import CachedTextRenderer
from .bounds import Bounds
from .controller import KINDS, Controller, Element
from .freqresp import check_grid, evaluate
from .nichols import draw, loop_nichols, wrap_phase
from .specs import Spec
from .templates import Template

__all__ = ["DesignState", "Designer", "LiveArtists", "closed_loop_poles", "readout_html"]

_DEFAULTS = {
    "gain": {"k": 1.0},
    "integrator": {"order": 1},
    "differentiator": {"order": 1},
    "real_pole": {"omega": 10.0},
    "real_zero": {"omega": 1.0},
    "complex_pole": {"omega": 10.0, "zeta": 0.5},
    "complex_zero": {"omega": 1.0, "zeta": 0.5},
    "lead_lag": {"zero": 1.0, "pole": 10.0},
    "notch": {"omega": 1.0, "zeta_zero": 0.05, "zeta_pole": 0.5},
}
_STATE_VERSION = 1


@dataclass(frozen=True, eq=False)
class DesignState:
    """Numbers behind one redraw: nominal loop (Nichols), bound check, stability, closed-loop peaks.

    Parameters
    ----------
    phase_deg : numpy.ndarray
        (n,) nominal loop phase on the dense grid, degrees.
    magnitude_db : numpy.ndarray
        (n,) nominal loop magnitude, dB.
    design_allowed : numpy.ndarray
        (n_design,) every bound met at each design frequency.
    worst_T_db : numpy.ndarray
        (n,) max over cases of |L/(1+L)|, dB.
    worst_S_db : numpy.ndarray
        (n,) max over cases of |1/(1+L)|, dB.
    stable : numpy.ndarray
        (n_cases,) True where every closed-loop pole of 1 + L of that plant case has a negative
        real part; False also when it cannot be decided (an improper controller, a plant
        without a state-space realisation: see ``rightmost_pole``).
    rightmost_pole : numpy.ndarray
        (n_cases,) complex closed-loop pole of largest real part per case, rad/s (NaN when
        undecided, complex infinity for an ill-posed loop 1 + D_G·D_P = 0).
    spec_violations : dict
        Spec name (:attr:`loopshaping.qft.Bounds.names`) → design frequencies (rad/s) where it
        fails; an empty array where it is met. A Designer's ``gain_bound`` enters under its
        name with the dense grid's frequencies where |G| exceeds it.
    gain_met : bool
        The controller's gain bound (``gain_bound``) met on the dense grid (True without one).
    """

    phase_deg: np.ndarray
    magnitude_db: np.ndarray
    design_allowed: np.ndarray
    worst_T_db: np.ndarray
    worst_S_db: np.ndarray
    stable: np.ndarray
    rightmost_pole: np.ndarray
    spec_violations: dict
    gain_met: bool = True

    @property
    def all_stable(self) -> bool:
        """True when every plant case's closed loop is stable."""
        return bool(np.all(self.stable))

    @property
    def bounds_met(self) -> bool:
        """True when every bound is met at every design frequency."""
        return bool(np.all(self.design_allowed))


def _state_space(p):
    """(A, B, C, D) float arrays of a SISO LTI, or None when it has no state-space realisation."""
    import control as ct

    try:
        ss = ct.ss(p)
    except (TypeError, ValueError, NotImplementedError):
        return None
    return tuple(np.asarray(m, float) for m in (ss.A, ss.B, ss.C, ss.D))


def closed_loop_poles(plant, num, den) -> np.ndarray:
    """Poles of the loop closed by unity negative feedback around L = G·P (the zeros of 1 + L).

    Internal poles included: a pole cancelled between G and P stays a closed-loop pole.

    Parameters
    ----------
    plant : tuple
        (A, B, C, D) of the SISO plant P (a state-space realisation, arrays).
    num, den : array_like
        Controller G(s) = num/den, descending powers of s; proper.

    Returns
    -------
    numpy.ndarray
        Complex closed-loop poles, rad/s; ``[inf]`` for an ill-posed loop (1 + G(∞)P(∞) = 0).

    Raises
    ------
    ValueError
        If G is improper or ``den`` is zero.

    Examples
    --------
    >>> import numpy as np
    >>> from loopshaping.interactive import closed_loop_poles
    >>> P = (np.array([[-1.0]]), np.array([[1.0]]), np.array([[1.0]]), np.array([[0.0]]))  # 1/(s+1)
    >>> closed_loop_poles(P, [3.0], [1.0])  # 1 + 3/(s+1) = 0 at s = −4
    array([-4.+0.j])
    """
    from scipy.signal import tf2ss

    num, den = np.trim_zeros(np.atleast_1d(np.asarray(num, float)), "f"), np.trim_zeros(np.atleast_1d(np.asarray(den, float)), "f")
    if den.size == 0:
        raise ValueError("den must be a non-zero polynomial")
    if num.size > den.size:
        raise ValueError("the controller must be proper (no more zeros than poles) for its closed-loop poles")
    Ap, Bp, Cp, Dp = (np.atleast_2d(m) for m in plant)
    if den.size == 1:  # a static gain: tf2ss would add a spurious state at s = 0
        Ag, Bg, Cg, Dg = np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), np.array([[num[0] / den[0] if num.size else 0.0]])
    else:
        Ag, Bg, Cg, Dg = tf2ss(num if num.size else [0.0], den)
    r = 1.0 + Dg[0, 0] * Dp[0, 0]
    if r == 0:
        return np.array([complex(np.inf, 0.0)])
    Kx, Kg = -Dg[0, 0] * Cp / r, Cg / r  # u = Kx·x_P + Kg·x_G with e = −y
    A = np.block([[Ap + Bp @ Kx, Bp @ Kg], [-Bg @ (Cp + Dp @ Kx), Ag - Bg @ Dp @ Kg]])
    return np.linalg.eigvals(A).astype(complex)


class LiveArtists:
    """Redraw the few artists an edit changes, blitted on a cached background of the rest.

    On ipympl's canvas a full redraw (``draw_idle``) costs a round trip to the browser and a
    render of every artist: 0.5 s for the Designer's 77 bound contours, where the loop and
    its markers take a few ms. The ``artists`` are made animated: every full render of the
    canvas caches the figure without them as the background and then draws them on top (so a
    full redraw, a toolbar zoom or a resize still shows them, and ``savefig`` too);
    :meth:`redraw` restores the background, draws only them and sends the changed pixels (as a
    PNG made by ``loopshaping._diffpng`` in about half the time matplotlib takes); a line
    of text that meets the pixels it met before is written from a cache instead of rasterised
    again (``loopshaping._textcache.CachedTextRenderer``: pixel-identical, and a multi-line
    title whose one line changed costs that line).
    Until the canvas has rendered once and the browser's view of it is connected it asks for
    a full redraw instead (a blit sent before the browser drew the figure once left it empty).
    A live figure is not "stale" after a blit or a render (pyplot redraws every stale figure
    after each message the kernel handles, a slider's included: drawing the artists on top
    marked it stale again, and notebook 03's kernel rendered without end), and a change of one
    of its artists asks for no render by itself (pyplot's interactive mode would, on every
    change); a change made from code is drawn after the cell, as pyplot draws stale figures.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        The figure.
    artists : sequence of matplotlib.artist.Artist
        The artists the edits change (lines, collections, texts, a legend), drawn in this order.
    live : bool, optional
        Blit (True) or always redraw in full with ``draw_idle`` (False); default: blit on
        ipympl's canvas (``%matplotlib widget``), full redraws elsewhere (inline and static
        figures, where a blit shows nothing).

    Attributes
    ----------
    live : bool
        Whether :meth:`redraw` blits.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from loopshaping.interactive import LiveArtists
    >>> fig, ax = plt.subplots()
    >>> (line,) = ax.plot([0, 1], [0, 1])
    >>> live = LiveArtists(fig, [line], live=True)
    >>> fig.canvas.draw()  # caches the background, draws the line on it
    >>> line.set_ydata([1, 0]); live.redraw()  # the line alone, on the background
    >>> plt.close(fig)
    """

    def __init__(self, figure, artists, live: bool | None = None):
        self.figure = figure
        self.artists = list(artists)
        canvas = figure.canvas
        self.live = hasattr(canvas, "syncing_data_url") if live is None else bool(live)  # ipympl's Canvas
        self._background = None
        self._text = None  # the canvas's renderer drawing unchanged lines of text from a cache
        self._printed = []  # artists drawn into saved files only (print_only)
        if self.live:
            for a in self.artists:
                a.set_animated(True)
            canvas.mpl_connect("draw_event", self._on_draw)
            # no full render requested by each change (pyplot's draw_idle on "stale" in
            # interactive mode): the owner redraws, by a blit
            figure.stale_callback = None
            # the image of the changed pixels sent after each blit, made in about half the
            # time matplotlib takes (its PNG encoding was most of a Designer gain step)
            install_encoder(canvas)

    def _on_draw(self, event):
        canvas, renderer = event.canvas, event.renderer
        if canvas.is_saving():  # savefig: the axes draw their animated children then, the figure not
            for a in (*self.artists, *self._printed):
                if getattr(a, "axes", None) is None:
                    a.draw(renderer)
            return
        self._background = canvas.copy_from_bbox(self.figure.bbox)
        for a in self.artists:
            a.draw(renderer)
        self.figure.stale = False  # drawn: their children's updates while drawing are on screen

    def print_only(self, *artists):
        """Draw ``artists`` into saved files only, no longer on the live canvas (nor in a blit).

        For text a widget beside the live figure shows instead (a verdict, a readout): a line
        of text costs about 0.1 ms a glyph to draw at each edit, and its pixels enlarge the
        image sent to the browser. A saved figure still says what it shows. The next full
        render (asked for here) draws the canvas without them.

        Parameters
        ----------
        *artists : matplotlib.artist.Artist
            Artists of the figure, among :attr:`artists` or not.
        """
        for a in artists:
            if a in self.artists:
                self.artists.remove(a)
            # animated: a render of the canvas skips them; savefig draws an axes' animated
            # children itself, and :meth:`_on_draw` the figure's
            a.set_animated(True)
            if a not in self._printed:
                self._printed.append(a)
        self._background = None  # cached with them drawn: the next render caches it without
        self.figure.canvas.draw_idle()

    def settle(self, *artists):
        """Stop redrawing ``artists`` at each edit: they become part of the cached background.

        For artists that no longer change (a legend whose changing entry moved to a widget).
        The next full render (asked for here) draws them into the background.

        Parameters
        ----------
        *artists : matplotlib.artist.Artist
            Artists among :attr:`artists`.
        """
        for a in artists:
            if a in self.artists:
                self.artists.remove(a)
            a.set_animated(False)
        self._background = None
        self.figure.canvas.draw_idle()

    @property
    def ready(self) -> bool:
        """True when :meth:`redraw` blits: live, a background cached, the browser's view connected."""
        # ipympl syncs the image as a data URL until its browser view says it is initialised
        return self.live and self._background is not None and not getattr(self.figure.canvas, "syncing_data_url", False)

    def redraw(self):
        """Show the artists' new data: blit them when :attr:`ready`, else ask for a full redraw."""
        canvas = self.figure.canvas
        if not self.ready:
            canvas.draw_idle()
            return
        canvas.restore_region(self._background)
        renderer = canvas.get_renderer()
        if self._text is None or self._text.renderer is not renderer:  # a new canvas size or dpi
            self._text = CachedTextRenderer(renderer)
        for a in self.artists:
            a.draw(self._text)
        canvas.blit(self.figure.bbox)
        self.figure.stale = False  # what changed is on screen: no full render after this message


def _where(omega):
    """Design frequencies for a title: a short list, or how many and their range."""
    if omega.size <= 3:
        return "ω = " + ", ".join(f"{x:.3g}" for x in omega) + " rad/s"
    return f"{omega.size} frequencies in {omega.min():.3g}-{omega.max():.3g} rad/s"


class Designer:
    """Loop shaping by elements against ``bounds``, nominal plant taken from ``plant``.

    Parameters
    ----------
    bounds : Bounds
        The bounds to shape against.
    plant : Template or control LTI
        A :class:`~loopshaping.templates.Template` with systems (the nominal case is shaped,
        all cases enter the closed-loop plot and the stability check) or a SISO LTI nominal plant.
    controller : Controller, optional
        Starting controller (default: unit gain).
    omega : array_like, optional
        Dense grid, rad/s (default 600 points, design range ×/÷ 100).
    gain_bound : Spec, optional
        A bound on the controller's own gain, |G(jω)| ≤ W(ω) on a band
        (:func:`loopshaping.specs.controller_gain`): checked on the dense grid, part of the
        verdict (not saved by :meth:`to_state`; give it again to :meth:`from_state`'s Designer).

    Attributes
    ----------
    update_ms : float
        Wall time of the last :meth:`update` (recompute, artist data and the blit or the
        redraw request), ms: what an edit costs in the kernel before the browser shows it.
    readout : str
        The verdict of the figure's last redraw (:meth:`summary`'s lines): the figure's title,
        or, on a live figure shown by :meth:`widget`, the readout above it (the title is then
        drawn into saved files only; :meth:`LiveArtists.print_only`).

    Raises
    ------
    TypeError
        If ``bounds`` is not a Bounds, or ``gain_bound`` not a Spec.
    ValueError
        If the Template has no systems or the grid is bad.

    Examples
    --------
    >>> import control as ct
    >>> from loopshaping import qft
    >>> from loopshaping.controller import Controller, gain
    >>> from loopshaping.interactive import Designer
    >>> tmpl = qft.Template.from_systems([ct.tf([k], [1, 31, 30]) for k in (1.0, 10.0)], [0.1, 5.0])
    >>> d = Designer(qft.bounds(tmpl, "stability", 1.2), tmpl, Controller((gain(-100.0),)))
    >>> st = d.state()
    >>> bool(st.all_stable), f"{st.rightmost_pole[1].real:+.2f}"  # s² + 31 s + 30 − 1000 = 0 at s = +19.29
    (False, '+19.29')
    """

    def __init__(self, bounds: Bounds, plant, controller: Controller | None = None, omega=None, gain_bound: Spec | None = None):
        if not isinstance(bounds, Bounds):
            raise TypeError(f"bounds must be a loopshaping.qft.Bounds; got {type(bounds).__name__}")
        if gain_bound is not None and not isinstance(gain_bound, Spec):
            raise TypeError(f"gain_bound must be a loopshaping Spec (loopshaping.specs.controller_gain); got "
                            f"{type(gain_bound).__name__}")
        if controller is not None and not isinstance(controller, Controller):
            raise TypeError(f"controller must be a loopshaping Controller (Controller.from_tf converts an LTI); "
                            f"got {type(controller).__name__}")
        self.bounds = bounds
        d = bounds.omega
        self._omega_arg = None if omega is None else check_grid(omega, "omega")
        w = np.logspace(np.log10(d.min() / 100), np.log10(d.max() * 100), 600) if omega is None else self._omega_arg
        self.omega = np.unique(np.concatenate([check_grid(w, "omega"), d]))
        self._design_idx = np.searchsorted(self.omega, d)
        if isinstance(plant, Template):
            if plant.systems is None:
                raise ValueError("plant: the Template needs systems to evaluate the plant on the dense grid")
            systems, nominal = plant.systems, plant.nominal
        else:
            systems, nominal = [plant], 0
        self._P = np.stack([evaluate(p, self.omega, "plant") for p in systems], axis=1)
        self._P0 = self._P[:, nominal]
        self._ss = [_state_space(p) for p in systems]
        # the gain bound on the dense grid (inf outside its band): |G| is compared with it at every redraw
        self._gain = None if gain_bound is None else (
            gain_bound.name, np.where(gain_bound.in_band(self.omega), gain_bound.weights(self.omega, 1)[:, 0], np.inf))
        self.controller = controller if controller is not None else Controller((Element("gain", {"k": 1.0}),))
        self.selected = 0
        self.figure = None
        self._artists = {}
        self.update_ms = float("nan")
        self._on_update = None  # the widget's controls following an edit made from code
        self.readout = ""
        self._readout_colour = "black"
        self._readout_widget = None  # the ipywidgets.HTML above a live figure showing the readout

    # -- saved state
    def to_state(self) -> dict:
        """The designer's state as a JSON-ready dict (the controller, the grid, the selected element).

        Returns
        -------
        dict
            ``{"version", "controller"`` (:meth:`Controller.to_dict`), ``"omega"`` (the dense
            grid given, rad/s, or None for the default), ``"selected"}``; read by
            :meth:`from_state`. Floats are kept exactly by JSON's repr.
        """
        w = None if self._omega_arg is None else [float(x) for x in self._omega_arg]
        return {"version": _STATE_VERSION, "controller": self.controller.to_dict(), "omega": w,
                "selected": int(self.selected)}

    @classmethod
    def from_state(cls, state: dict, bounds: Bounds, plant) -> Designer:
        """A designer restored from :meth:`to_state` against ``bounds`` and ``plant``.

        Parameters
        ----------
        state : dict
            As written by :meth:`to_state`.
        bounds : Bounds
            The bounds to shape against (not part of the state: recompute them from their
            settings, e.g. a saved design session's QFT settings).
        plant : Template or control LTI
            The plant cases, as for the constructor.

        Returns
        -------
        Designer
            The designer with the saved controller, grid and selection.

        Raises
        ------
        ValueError
            For unknown keys, a newer state version or an invalid controller.
        """
        if not isinstance(state, dict) or "controller" not in state:
            raise ValueError("state must be a dict with a 'controller' (from Designer.to_state)")
        extra = set(state) - {"version", "controller", "omega", "selected"}
        if extra:
            raise ValueError(f"unknown designer state keys {sorted(extra)}; allowed: version, controller, omega, selected")
        version = state.get("version", _STATE_VERSION)
        if type(version) is not int or version > _STATE_VERSION or version < 1:
            raise ValueError(f"designer state version {version!r} is not supported (this version reads 1 to "
                             f"{_STATE_VERSION}); upgrade loopshaping to read it")
        out = cls(bounds, plant, Controller.from_dict(state["controller"]), omega=state.get("omega"))
        sel = state.get("selected", 0)
        if type(sel) is not int or not 0 <= sel < max(len(out.controller.elements), 1):
            raise ValueError(f"selected={sel!r} must be an element index of the saved controller")
        out.selected = sel
        return out

    @classmethod
    def from_session(cls, session, bounds: Bounds, plant) -> Designer:
        """A designer restored from a saved design session (any object with a ``designer`` state).

        Parameters
        ----------
        session : object or dict
            A record whose ``designer`` attribute (or key) holds :meth:`to_state`, e.g. the
            result of ``specdesign.session.load_session``.
        bounds : Bounds
            The bounds to shape against.
        plant : Template or control LTI
            The plant cases.

        Returns
        -------
        Designer
            As :meth:`from_state`.

        Raises
        ------
        ValueError
            If the session holds no designer state.
        """
        state = session.get("designer") if isinstance(session, dict) else getattr(session, "designer", None)
        if not state:
            raise ValueError("the session holds no designer state; save one with the Designer's to_state()")
        return cls.from_state(state, bounds, plant)

    # -- numbers
    def state(self) -> DesignState:
        """The numbers of the current controller (no drawing).

        Returns
        -------
        DesignState
            Loop on the Nichols chart, bounds met (all and per spec), stability of every plant
            case, worst closed-loop magnitudes.
        """
        G = self.controller.response(self.omega)
        ph, mag = loop_nichols(self._P0 * G, self.omega)
        i = self._design_idx
        L0 = self._P0[i] * G[i]
        # each spec at all its design frequencies at once (a slider step re-checks them all)
        allowed = np.ones(i.size, bool)
        violations = {}
        for part in self.bounds.parts:
            k = np.searchsorted(self.bounds.omega, part.omega)
            met = part.ok_each(L0[k])
            allowed[k] &= met
            name = part.spec.name
            violations[name] = np.union1d(violations.get(name, np.empty(0)), part.omega[~met])
        L = self._P * G[:, None]
        with np.errstate(divide="ignore"):
            T = 20 * np.log10(np.abs(L / (1 + L)).max(axis=1))
            S = 20 * np.log10(np.abs(1 / (1 + L)).max(axis=1))
        stable, rightmost = self._stability()
        gain_met = True
        if self._gain is not None:
            violations[self._gain[0]] = self.omega[np.abs(G) > self._gain[1]]
            gain_met = violations[self._gain[0]].size == 0
        return DesignState(ph, mag, allowed, T, S, stable, rightmost, violations, gain_met)

    def _stability(self):
        n = len(self._ss)
        stable, rightmost = np.zeros(n, bool), np.full(n, complex(np.nan, np.nan))
        num, den = self.controller.polys()  # once: Controller.is_proper would multiply them out again
        if len(np.trim_zeros(num, "f")) > len(np.trim_zeros(den, "f")):  # improper: undecided
            return stable, rightmost
        for c, ss in enumerate(self._ss):
            if ss is None:
                continue
            poles = closed_loop_poles(ss, num, den)
            p = poles[np.argmax(poles.real)]
            rightmost[c] = p
            stable[c] = bool(np.isfinite(p) and p.real < -1e-9 * max(1.0, abs(p)))
        return stable, rightmost

    # -- editing
    def set_controller(self, controller: Controller) -> DesignState:
        """Replace the controller and update.

        Parameters
        ----------
        controller : Controller
            The new controller.

        Returns
        -------
        DesignState
            The new state.
        """
        self.controller = controller
        return self.update()

    def set_param(self, index: int, **params) -> DesignState:
        """Change parameters of element ``index`` and update (values are kept exactly).

        Parameters
        ----------
        index : int
            Element position.
        **params
            New parameter values (rad/s for frequencies).

        Returns
        -------
        DesignState
            The new state.
        """
        return self.set_controller(self.controller.set(index, **params))

    def add(self, kind: str, **params) -> DesignState:
        """Append an element of ``kind`` (default parameters unless given) and update.

        Parameters
        ----------
        kind : str
            One of :data:`loopshaping.controller.KINDS`.
        **params
            Parameters overriding the defaults.

        Returns
        -------
        DesignState
            The new state.

        Raises
        ------
        ValueError
            For an unknown kind.
        """
        if kind not in KINDS:
            raise ValueError(f"kind={kind!r} is not one of {KINDS}")
        return self.set_controller(self.controller.add(Element(kind, {**_DEFAULTS[kind], **params})))

    def remove(self, index: int) -> DesignState:
        """Remove element ``index`` and update.

        Parameters
        ----------
        index : int
            Element position.

        Returns
        -------
        DesignState
            The new state.
        """
        return self.set_controller(self.controller.remove(index))

    # -- drawing
    def draw(self, live: bool | None = None):
        """Build the figure (Nichols chart + closed-loop magnitudes) without displaying it.

        :meth:`widget` displays it (once) with the controls.

        Parameters
        ----------
        live : bool, optional
            Redraw edits by blitting: only the loop, markers, title and closed-loop lines are
            re-rendered on a cached background of the bounds and axes (:class:`LiveArtists`;
            the title not once :meth:`widget` shows the verdict in a readout above the figure).
            Default: on ipympl's canvas (``%matplotlib widget``), where a full redraw of the
            bounds takes about 0.5 s; off elsewhere (an edit then redraws the figure in full).

        Returns
        -------
        matplotlib.figure.Figure
            The designer's figure (also kept as ``self.figure``).
        """
        import matplotlib.pyplot as plt

        # pyplot would also show a figure made with interactive mode on at the end of the cell,
        # beside the one the widget shows: twice
        with plt.ioff():
            fig, (ax_n, ax_b) = plt.subplots(1, 2, figsize=(10, 5.2))
        if hasattr(fig.canvas, "header_visible"):  # ipympl: the title says it all, no "Figure n" label
            fig.canvas.header_visible = False
            # the toolbar beside the figure, not over the panels' labels
            fig.canvas.toolbar_position = "right"
        draw(self.bounds, loop=None, ax=ax_n, legend=False)
        st = self.state()
        # the loop and the markers wrapped into the chart's phase window, as the bounds repeat
        # every 360° (a design point past −360° stays on the chart)
        self._window = tuple(ax_n.get_xlim())
        (loop,) = ax_n.plot(*wrap_phase(st.phase_deg, st.magnitude_db, self._window), "k-", lw=1.5,
                            label="nominal loop $L_0$")
        i = self._design_idx
        marks = ax_n.scatter(self._wrapped(st.phase_deg[i]), st.magnitude_db[i], s=50, zorder=5,
                             c=self._marker_colours(st), edgecolors="k", label="design frequencies (green: met)")
        # the loop, the markers and what solid/dashed bounds mean; not one entry per design
        # frequency (a turbine loop has dozens)
        few = self.bounds.omega.size <= 8
        keep = [(h, lab) for h, lab in zip(*ax_n.get_legend_handles_labels())
                if few or h in (loop, marks) or lab.startswith(("solid", "dashed"))]
        ax_n.legend(*zip(*keep), fontsize=7, loc="lower right")
        (t_line,) = ax_b.semilogx(self.omega, st.worst_T_db, label="max over cases |T| (dB)")
        (s_line,) = ax_b.semilogx(self.omega, st.worst_S_db, label="max over cases |S| (dB)")
        # the views cover the design: the closed-loop band from a third of the lowest design
        # frequency to three times the highest (the dense grid runs ×100 beyond for the checks),
        # and the magnitudes the loop takes there and the finite bounds, with a 10 dB margin
        # (the loop's roll-off far above the band spanned −250 dB)
        d = self.bounds.omega
        band = (self.omega >= d.min() / 3) & (self.omega <= d.max() * 3)
        ax_b.set_xlim(d.min() / 3, d.max() * 3)
        lower, upper = self.bounds.edges()
        edges = np.concatenate([lower[np.isfinite(lower)], upper[np.isfinite(upper)]])
        seen = np.concatenate([st.magnitude_db[band], np.clip(edges, -120.0, 120.0)])
        ax_n.set_ylim(np.floor((seen.min() - 10.0) / 10.0) * 10.0, np.ceil((seen.max() + 10.0) / 10.0) * 10.0)
        curves = np.concatenate([st.worst_T_db[band], st.worst_S_db[band]])
        curves = curves[np.isfinite(curves)]
        if curves.size:
            ax_b.set_ylim(max(curves.min(), -60.0) - 5.0, curves.max() + 5.0)
        ax_b.set_xlabel("frequency ω (rad/s)")
        ax_b.set_ylabel("closed-loop magnitude (dB)")
        ax_b.grid(True, which="both", lw=0.3)
        ax_b.legend(fontsize=8)
        self.readout, self._readout_colour = self._title(st), self._title_colour(st)
        title = fig.suptitle(self.readout, fontsize=9, color=self._readout_colour)
        # fixed margins (no layout engine: it would re-run on every redraw); room for the
        # three-line title above the axes
        fig.subplots_adjust(left=0.08, right=0.98, bottom=0.11, top=0.79, wspace=0.42)
        self.figure = fig
        self._artists = dict(loop=loop, marks=marks, T=t_line, S=s_line, title=title)
        # the bounds and axes are rendered once into a cached background; an edit redraws only
        # the changing artists on top of it
        self._redraw = LiveArtists(fig, self._artists.values(), live)
        return fig

    def update(self, redraw=True) -> DesignState:
        """Recompute and push the new data into the existing artists (no figure rebuild).

        Parameters
        ----------
        redraw : bool
            Ask the canvas to redraw; False skips it (a non-interactive canvas such as Agg
            renders synchronously on request).

        Returns
        -------
        DesignState
            The numbers behind this redraw (nominal loop, bound check, stability, closed-loop peaks).
        """
        t0 = time.perf_counter()
        st = self.state()
        if self.figure is not None:
            a = self._artists
            a["loop"].set_data(*wrap_phase(st.phase_deg, st.magnitude_db, self._window))
            i = self._design_idx
            a["marks"].set_offsets(np.column_stack([self._wrapped(st.phase_deg[i]), st.magnitude_db[i]]))
            a["marks"].set_facecolors(self._marker_colours(st))
            a["T"].set_ydata(st.worst_T_db)
            a["S"].set_ydata(st.worst_S_db)
            self.readout, self._readout_colour = self._title(st), self._title_colour(st)
            # set on the title also where the widget shows it: a saved figure draws it
            a["title"].set_text(self.readout)
            a["title"].set_color(self._readout_colour)
            if self._readout_widget is not None:
                self._readout_widget.value = readout_html(self.readout, self._readout_colour)
            if redraw:
                self._redraw.redraw()
        self.update_ms = 1e3 * (time.perf_counter() - t0)
        if self._on_update is not None:
            self._on_update()
        return st

    def _wrapped(self, phase_deg):
        low = self._window[0]
        return low + np.mod(phase_deg - low, 360.0)

    def _marker_colours(self, st):
        return np.where(st.design_allowed, "tab:green", "tab:red")

    @staticmethod
    def _title_colour(st):
        return "black" if st.all_stable and st.bounds_met and st.gain_met else "tab:red"

    def summary(self, state: DesignState | None = None) -> str:
        """What the figure's title says: stability (the unstable case and its pole), bounds, specs, G.

        Parameters
        ----------
        state : DesignState, optional
            The state to describe (default: the current controller's).

        Returns
        -------
        str
            The verdict, each spec checked (met, or the design frequencies in rad/s where it
            fails) and the controller (wrapped), one per line.
        """
        return self._title(self.state() if state is None else state)

    def _title(self, st):
        n = st.stable.size
        bad = np.flatnonzero(~st.stable)
        if bad.size:
            c = int(bad[np.argmax(np.nan_to_num(st.rightmost_pole[bad].real, nan=-np.inf))])
            p = st.rightmost_pole[c]
            what = (f"closed-loop pole at {p.real:+.3g}{p.imag:+.3g}j" if np.isfinite(p) else
                    "stability undecided (improper controller or no state-space plant)" if np.isnan(p) else
                    "ill-posed loop (1 + L(∞) = 0)")
            head = f"UNSTABLE: plant case {c} of {n}: {what}" + (f" ({bad.size} unstable cases)" if bad.size > 1 else "")
        elif st.bounds_met and st.gain_met:
            head = f"all bounds met, all {n} plant case(s) stable"
        elif st.bounds_met:
            head = f"all bounds met, all {n} plant case(s) stable; the controller's gain bound is not"
        else:
            head = f"{n} plant case(s) stable; bounds violated at " + _where(self.bounds.omega[~st.design_allowed])
        specs = "; ".join(f"{name}: " + ("met" if v.size == 0 else "violated at " + _where(v))
                          for name, v in st.spec_violations.items())
        g = textwrap.fill(textwrap.shorten(f"G = {self.controller}", width=230, placeholder=" …"), 120)
        specs = textwrap.fill(f"specs checked: {specs}", 130)
        return f"{head}\n{specs}\n{g}"

    # -- widgets
    def widget(self):
        """ipywidgets UI: element list, parameter controls, add/remove, and the figure (shown once).

        Frequencies and gains move on log sliders (steps of 0.005 decade, 1.2 %, over ±1
        decade around the value when the element is selected, re-centred on a typed value
        outside; a negative gain keeps its sign) beside a text box whose typed value is used
        exactly.

        Returns
        -------
        ipywidgets.Widget
            A box holding the controls and the figure's canvas, ready to display.

        Raises
        ------
        ImportError
            Without ipywidgets.
        """
        if self.figure is None:
            self.draw()
        return build_widget(self)

    def element_options(self) -> list:
        """Labels of the elements for a selection list.

        Returns
        -------
        list of tuple
            ``(label, index)`` per element of the controller.
        """
        return [(f"{i}: {e}", i) for i, e in enumerate(self.controller.elements)]
