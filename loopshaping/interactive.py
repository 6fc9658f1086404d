"""Interactive loop shaping in Jupyter (ipywidgets for the controls, ipympl for a live figure).

:class:`Designer` keeps a :class:`~loopshaping.controller.Controller`; every edit recomputes
the nominal loop on a dense grid, checks the bounds at the design frequencies exactly
(:meth:`~loopshaping.qft.Bounds.is_allowed`) and updates the line data of the Nichols chart
and of the closed-loop magnitude plot (worst case over the plant cases) without rebuilding
the figure. The numbers live in :meth:`Designer.state`, so the designer also works headless
(tests, benchmarks). ipywidgets is imported only by :meth:`Designer.widget`; with the
``%matplotlib widget`` backend (ipympl) the figure updates live in the notebook.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .bounds import Bounds
from .controller import KINDS, Controller, Element
from .freqresp import check_grid, evaluate
from .nichols import draw, loop_nichols
from .templates import Template

__all__ = ["DesignState", "Designer"]

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


@dataclass(frozen=True, eq=False)
class DesignState:
    """Numbers behind one redraw: nominal loop (Nichols), bound check, closed-loop peaks.

    Parameters
    ----------
    phase_deg : numpy.ndarray
        (n,) nominal loop phase on the dense grid, degrees.
    magnitude_db : numpy.ndarray
        (n,) nominal loop magnitude, dB.
    design_allowed : numpy.ndarray
        (n_design,) bounds met at each design frequency.
    worst_T_db : numpy.ndarray
        (n,) max over cases of |L/(1+L)|, dB.
    worst_S_db : numpy.ndarray
        (n,) max over cases of |1/(1+L)|, dB.
    """

    phase_deg: np.ndarray  # (n,) nominal loop phase on the dense grid
    magnitude_db: np.ndarray  # (n,)
    design_allowed: np.ndarray  # (n_design,) bounds met at each design frequency
    worst_T_db: np.ndarray  # (n,) max over cases of |L/(1+L)|, dB
    worst_S_db: np.ndarray  # (n,) max over cases of |1/(1+L)|, dB


class Designer:
    """Loop shaping by elements against ``bounds``, nominal plant taken from ``plant``.

    Parameters
    ----------
    bounds : Bounds
        The bounds to shape against.
    plant : Template or control LTI
        A :class:`~loopshaping.templates.Template` with systems (the nominal case is shaped,
        all cases enter the closed-loop plot) or a SISO LTI nominal plant.
    controller : Controller, optional
        Starting controller (default: unit gain).
    omega : array_like, optional
        Dense grid, rad/s (default 600 points, design range ×/÷ 100).

    Raises
    ------
    TypeError
        If ``bounds`` is not a Bounds.
    ValueError
        If the Template has no systems or the grid is bad.
    """

    def __init__(self, bounds: Bounds, plant, controller: Controller | None = None, omega=None):
        if not isinstance(bounds, Bounds):
            raise TypeError(f"bounds must be a loopshaping.qft.Bounds; got {type(bounds).__name__}")
        self.bounds = bounds
        d = bounds.omega
        w = np.logspace(np.log10(d.min() / 100), np.log10(d.max() * 100), 600) if omega is None else omega
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
        self.controller = controller if controller is not None else Controller((Element("gain", {"k": 1.0}),))
        self.figure = None
        self._artists = {}

    # -- numbers
    def state(self) -> DesignState:
        """The numbers of the current controller (no drawing).

        Returns
        -------
        DesignState
            Loop on the Nichols chart, bounds met, worst closed-loop magnitudes.
        """
        G = self.controller.response(self.omega)
        ph, mag = loop_nichols(self._P0 * G, self.omega)
        i = self._design_idx
        allowed = self.bounds.is_allowed(self.bounds.omega, ph[i], mag[i])
        L = self._P * G[:, None]
        with np.errstate(divide="ignore"):
            T = 20 * np.log10(np.abs(L / (1 + L)).max(axis=1))
            S = 20 * np.log10(np.abs(1 / (1 + L)).max(axis=1))
        return DesignState(ph, mag, allowed, T, S)

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
        """Change parameters of element ``index`` and update.

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
    def draw(self, live=None):
        """Build the figure (Nichols chart + closed-loop magnitudes).

        Parameters
        ----------
        live : bool, optional
            Redraw edits by blitting (only the loop, markers and closed-loop lines are
            re-rendered). Default: on with the ipympl backend. Blitted artists are skipped by
            ``savefig`` and static inline display, hence off elsewhere.

        Returns
        -------
        matplotlib.figure.Figure
            The designer's figure (also kept as ``self.figure``).
        """
        import matplotlib
        import matplotlib.pyplot as plt

        if live is None:
            live = "ipympl" in matplotlib.get_backend() or "widget" in matplotlib.get_backend()

        fig, (ax_n, ax_b) = plt.subplots(1, 2, figsize=(11, 4.5))
        draw(self.bounds, loop=None, ax=ax_n, legend=False)
        st = self.state()
        (loop,) = ax_n.plot(st.phase_deg, st.magnitude_db, "k-", lw=1.5, label="nominal loop L0")
        i = self._design_idx
        marks = ax_n.scatter(st.phase_deg[i], st.magnitude_db[i], s=50, zorder=5,
                             c=self._marker_colours(st), edgecolors="k", label="design frequencies")
        ax_n.legend(fontsize=8, loc="lower right")
        (t_line,) = ax_b.semilogx(self.omega, st.worst_T_db, label="max over cases |T| [dB]")
        (s_line,) = ax_b.semilogx(self.omega, st.worst_S_db, label="max over cases |S| [dB]")
        ax_b.set_xlabel("ω [rad/s]")
        ax_b.set_ylabel("Closed-loop magnitude [dB]")
        ax_b.grid(True, which="both", lw=0.3)
        ax_b.legend(fontsize=8)
        title = ax_n.set_title(self._title(st), fontsize=9)
        fig.tight_layout()  # once: a layout engine would re-run on every redraw
        self.figure = fig
        self._artists = dict(loop=loop, marks=marks, T=t_line, S=s_line, title=title)
        # Blitting: the bounds and axes are rendered once into a cached background; an edit
        # redraws only the changing artists on top of it.
        self._background = None
        self._live = bool(live)
        if self._live:
            for a in self._artists.values():
                a.set_animated(True)
            fig.canvas.mpl_connect("draw_event", self._on_draw)
        return fig

    def _on_draw(self, event=None):
        canvas = self.figure.canvas
        self._background = canvas.copy_from_bbox(self.figure.bbox)
        self._blit_artists()

    def _blit_artists(self):
        for a in self._artists.values():
            a.axes.draw_artist(a)

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
            The numbers behind this redraw (nominal loop, bound check, closed-loop peaks).
        """
        st = self.state()
        if self.figure is not None:
            a = self._artists
            a["loop"].set_data(st.phase_deg, st.magnitude_db)
            i = self._design_idx
            a["marks"].set_offsets(np.column_stack([st.phase_deg[i], st.magnitude_db[i]]))
            a["marks"].set_facecolors(self._marker_colours(st))
            a["T"].set_ydata(st.worst_T_db)
            a["S"].set_ydata(st.worst_S_db)
            a["title"].set_text(self._title(st))
            if redraw:
                canvas = self.figure.canvas
                if not self._live:
                    canvas.draw_idle()
                elif self._background is None:
                    canvas.draw()  # first time: full render, caches the background
                else:
                    canvas.restore_region(self._background)
                    self._blit_artists()
                    canvas.blit(self.figure.bbox)
        return st

    def _marker_colours(self, st):
        return np.where(st.design_allowed, "tab:green", "tab:red")

    def _title(self, st):
        bad = self.bounds.omega[~st.design_allowed]
        head = "all bounds met" if bad.size == 0 else "bounds violated at ω = " + ", ".join(f"{w:.3g}" for w in bad)
        return f"{head}\nG = {self.controller}"

    # -- widgets
    def widget(self):
        """ipywidgets UI: element list, parameter sliders, add/remove, and the figure.

        Returns
        -------
        ipywidgets.Widget
            A box holding the controls and the figure's canvas, ready to display.

        Raises
        ------
        ImportError
            Without ipywidgets.
        """
        try:
            import ipywidgets as ipw
        except ImportError as e:
            raise ImportError("the interactive designer needs ipywidgets (and ipympl for a live figure)") from e
        if self.figure is None:
            self.draw()
        elements = ipw.Select(options=self._element_options(), rows=6, description="elements")
        sliders = ipw.VBox()
        kind = ipw.Dropdown(options=KINDS, value="real_pole", description="add")
        add_btn, rm_btn = ipw.Button(description="add element"), ipw.Button(description="remove selected")
        json_box = ipw.Textarea(value=self.controller.to_json(), layout=ipw.Layout(width="100%"), disabled=True)

        busy = [False]

        def refresh(select=None):
            # Relabel the list without letting the selection (and the slider being dragged) jump.
            keep = elements.value if select is None else select
            busy[0] = True
            elements.options = self._element_options()
            if elements.options:
                elements.value = min(keep or 0, len(elements.options) - 1)
            busy[0] = False
            json_box.value = self.controller.to_json()

        def build_sliders(change=None):
            if busy[0]:
                return
            idx = elements.value
            if idx is None or idx >= len(self.controller.elements):
                sliders.children = ()
                return
            e = self.controller.elements[idx]
            items = []
            for name, value in e.params.items():
                if name == "order":
                    sl = ipw.IntSlider(value=value, min=1, max=4, description=name)
                elif name.startswith("zeta"):
                    sl = ipw.FloatSlider(value=value, min=0.0 if name == "zeta_zero" else 0.005, max=0.99,
                                         step=0.005, description=name, continuous_update=True)
                else:
                    sign = -1.0 if value < 0 else 1.0
                    mag = abs(value)
                    sl = ipw.FloatLogSlider(value=mag, base=10, min=np.log10(mag) - 3, max=np.log10(mag) + 3,
                                            step=0.01, description=name + (" (−)" if sign < 0 else ""))
                    sl._sign = sign

                def on_change(ch, name=name, sl=sl, idx=idx):
                    v = ch["new"] * getattr(sl, "_sign", 1.0)
                    self.set_param(idx, **{name: v})
                    refresh()

                sl.observe(on_change, names="value")
                items.append(sl)
            sliders.children = tuple(items)

        def on_add(_):
            self.add(kind.value)
            refresh(select=len(self.controller.elements) - 1)
            build_sliders()

        def on_remove(_):
            if elements.value is not None and self.controller.elements:
                self.remove(elements.value)
                refresh(select=0)
                build_sliders()

        elements.observe(build_sliders, names="value")
        add_btn.on_click(on_add)
        rm_btn.on_click(on_remove)
        build_sliders()
        canvas = self.figure.canvas
        fig_box = canvas if isinstance(canvas, ipw.DOMWidget) else ipw.Output()
        if not isinstance(canvas, ipw.DOMWidget):
            with fig_box:
                from IPython.display import display

                display(self.figure)
        controls = ipw.VBox([elements, ipw.HBox([kind, add_btn, rm_btn]), sliders, json_box])
        return ipw.VBox([controls, fig_box])

    def _element_options(self):
        return [(f"{i}: {e}", i) for i, e in enumerate(self.controller.elements)]
