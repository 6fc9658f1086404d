"""Design sessions that survive: a plain, versioned JSON file and the record it reloads to.

A session keeps what a design session in Jupyter builds up, so that closing the notebook loses
nothing and reopening it gives the same numbers:

- the model reference: the embedded ``"iea15mw"``, an OpenFAST deck (``{"fst": path,
  "cp_table": path or null, "discon": path or null}``, read by
  :func:`specdesign.turbine.from_openfast`) or a set of OpenFAST ``.lin`` files
  (``{"lin_files": [...]}``); relative paths are taken from the session file's folder;
- the wind speeds (m/s) and the specifications (:class:`specdesign.spec.Specification`: the
  baseline T_{y,w}(s) as exact state-space or transfer-function coefficients, the shaping
  elements by their own fields) with the context their baseline is recomputed from (wind
  speed, output, Wöhler exponent, turbulence class);
- the controllers: a :class:`loopshaping.controller.Controller` in its own JSON form
  (:meth:`~loopshaping.controller.Controller.to_dict`) or a transfer function as ``{"num",
  "den"}``, the controller-file format ``specdesign validate`` reads (``docs/validation.md``);
- free-form JSON tables: the QFT bounds settings (``qft``: e.g. ``design_qft``'s options), the
  :class:`loopshaping.interactive.Designer` state (``designer``: its ``to_state()``), the
  validation campaign configuration (``campaign``) and a results summary (``results``).

Floats are written by JSON's shortest repr, which reads back to the same double: a reloaded
session gives bitwise the same promise and controller frequency responses. No pickle: a
session file is text that any JSON reader can open. The file carries ``"schema":
"specdesign.session"`` and an integer ``"version"``; a newer or unknown version is refused with
a message saying so, and every key is checked.
"""
from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import control as ct
import numpy as np

from loopshaping.controller import Controller

from . import spec as _spec_module
from . import turbine
from ._checks import distinct_keys, finite_system
from .openfast import read_linearization

__all__ = ["SCHEMA", "VERSION", "Session", "save_session", "load_session", "session_to_dict", "session_from_dict"]

SCHEMA = "specdesign.session"
VERSION = 1
_TABLES = ("qft", "designer", "campaign", "results")
_CONTEXT_KEYS = {"wind_speed", "output", "m", "turbulence_class"}
_ELEMENT_TYPES = {c.__name__: c for c in (_spec_module.Notch, _spec_module.Gain, _spec_module.LeadLag, _spec_module.LowPass)}


@dataclass(frozen=True, eq=False)
class Session:
    """One design session (frozen): what :func:`save_session` writes and :func:`load_session` returns.

    Parameters
    ----------
    model : str or dict
        ``"iea15mw"`` (the embedded model), ``{"fst": path, "cp_table": path or None,
        "discon": path or None}`` (an OpenFAST deck, :func:`specdesign.turbine.from_openfast`)
        or ``{"lin_files": [paths]}`` (OpenFAST linearisations, read by :meth:`linearization`).
    wind_speeds : tuple of float
        The session's operating points, m/s.
    specifications : dict
        Name → :class:`specdesign.spec.Specification`.
    spec_context : dict
        Name → ``{"wind_speed"`` (m/s), ``"output"`` (e.g. ``"tower_base_my"``), ``"m"``
        (Wöhler exponent, -), optionally ``"turbulence_class"}``: how the specification's
        baseline is recomputed (:meth:`baseline`). Every specification needs one.
    controllers : dict
        Name → :class:`loopshaping.controller.Controller` or a SISO python-control LTI (rad per
        rad/s for a pitch controller, β = −C·Ω_g).
    qft : dict
        QFT bounds settings (JSON values), e.g. ``{"wind_speed": 19.0, "target_reduction": 25.0,
        "options": design.options}``.
    designer : dict
        A :class:`loopshaping.interactive.Designer` state (its ``to_state()``), or empty.
    campaign : dict
        The validation campaign configuration (the keys of ``docs/validation.md``), or empty.
    results : dict
        A results summary (JSON values: numbers, strings, lists, tables), or empty.
    notes : str
        Free text.

    Raises
    ------
    TypeError
        If a field has the wrong type (naming it).
    ValueError
        If a specification has no context, a wind speed is not a positive finite number, or a
        table holds something JSON cannot write exactly (NaN, infinity, a non-string key).

    Examples
    --------
    >>> from loopshaping.controller import Controller, gain
    >>> from specdesign.session import Session, session_from_dict, session_to_dict
    >>> s = Session(wind_speeds=(19.0,), controllers={"C": Controller((gain(-0.5),))})
    >>> back = session_from_dict(session_to_dict(s))
    >>> back.wind_speeds, back.controllers["C"] == s.controllers["C"]
    ((19.0,), True)
    """

    model: Any = "iea15mw"
    wind_speeds: tuple = ()
    specifications: Mapping = field(default_factory=dict)
    spec_context: Mapping = field(default_factory=dict)
    controllers: Mapping = field(default_factory=dict)
    qft: Mapping = field(default_factory=dict)
    designer: Mapping = field(default_factory=dict)
    campaign: Mapping = field(default_factory=dict)
    results: Mapping = field(default_factory=dict)
    notes: str = ""

    def __post_init__(self):
        _model_ref(self.model)
        speeds = tuple(self.wind_speeds) if np.ndim(self.wind_speeds) else (self.wind_speeds,)
        for v in speeds:
            if isinstance(v, bool) or not isinstance(v, (int, float, np.floating, np.integer)) or not np.isfinite(v) or v <= 0:
                raise ValueError(f"wind_speeds must be positive finite numbers in m/s, got {v!r}")
        object.__setattr__(self, "wind_speeds", tuple(float(v) for v in speeds))
        for name in ("specifications", "spec_context", "controllers", *_TABLES):
            value = getattr(self, name)
            if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
                raise TypeError(f"{name} must be a dict with string keys, got {type(value).__name__}")
            object.__setattr__(self, name, dict(value))
        for k, s in self.specifications.items():
            if not isinstance(s, _spec_module.Specification):
                raise TypeError(f"specifications[{k!r}] must be a specdesign.spec.Specification, got {type(s).__name__}")
            if k not in self.spec_context:
                raise ValueError(f"specifications[{k!r}] needs spec_context[{k!r}] = {{'wind_speed', 'output', 'm'}} "
                                 "(how its baseline is recomputed)")
        for k, c in self.spec_context.items():
            _check_context(k, c)
        for k, c in self.controllers.items():
            if not isinstance(c, (Controller, ct.LTI)):
                raise TypeError(f"controllers[{k!r}] must be a loopshaping Controller or a python-control LTI, "
                                f"got {type(c).__name__}")
            if isinstance(c, ct.LTI):  # a Controller's elements refuse NaN themselves
                finite_system(c, f"controllers[{k!r}]")
        for k, s in self.specifications.items():
            finite_system(s.baseline, f"specifications[{k!r}].baseline")
        for name in _TABLES:
            _json_exact(getattr(self, name), name)
        if not isinstance(self.notes, str):
            raise TypeError(f"notes must be a string, got {type(self.notes).__name__}")

    @classmethod
    def from_qft(cls, design: Any, *, model: Any = "iea15mw", designer: Any = None, campaign: Mapping | None = None,
                 results: Mapping | None = None, notes: str = "") -> "Session":
        """The session of one :func:`specdesign.qft.design_qft` design.

        Its wind speed, the specifications (``"notch"``: the unrelaxed notch specification of
        ``design.shaping``, whose promise the paper's Table 3 lists; ``"tower"``: the (relaxed)
        ``design.tower_spec`` the controller meets, both of the tower-base moment; ``"speed"``:
        ``design.speed_spec``, generator speed; m = 4), both controllers (``"pitch"``,
        ``"atd"``), the QFT settings (``wind_speed``, ``target_reduction``, ``options``) and a
        results summary (promised and predicted DEL reductions, %, margins, ``success``),
        merged with ``results``.

        Parameters
        ----------
        design : specdesign.qft.QFTDesign
            The design.
        model : str or dict
            The model reference the design was made on (see :class:`Session`).
        designer : loopshaping.interactive.Designer or dict, optional
            A Designer (its ``to_state()`` is kept) or a saved state.
        campaign : dict, optional
            A validation campaign configuration.
        results : dict, optional
            More results (JSON values), added to the design's summary.
        notes : str
            Free text.

        Returns
        -------
        Session
            The session.

        Raises
        ------
        TypeError
            If ``design`` is not a QFTDesign.
        """
        from .qft import QFTDesign

        if not isinstance(design, QFTDesign):
            raise TypeError(f"design must be a specdesign.qft.QFTDesign (from design_qft), got {type(design).__name__}")
        v = float(design.wind_speed)
        state = designer.to_state() if hasattr(designer, "to_state") else dict(designer or {})
        summary = {"notch_spec_promised_del_pct": float(design.shaping.promise.exact_del),
                   "tower_spec_promised_del_pct": float(design.promise.exact_del),
                   "predicted_del_pct": float(design.del_reduction),
                   "gain_margin_db": float(design.gain_margin_db), "phase_margin_deg": float(design.phase_margin_deg),
                   "success": bool(design.success), "message": str(design.message)}
        options = json.loads(json.dumps(design.options, default=float))  # tuples → lists, numpy scalars → floats
        tower = {"wind_speed": v, "output": "tower_base_my", "m": 4.0}
        return cls(model=model, wind_speeds=(v,),
                   specifications={"notch": design.shaping.specification, "tower": design.tower_spec,
                                   "speed": design.speed_spec},
                   spec_context={"notch": tower, "tower": dict(tower), "speed": {"wind_speed": v, "output": "gen_speed", "m": 4.0}},
                   controllers={"pitch": design.pitch_controller, "atd": design.atd_controller},
                   qft={"wind_speed": v, "target_reduction": float(design.target_reduction), "options": options},
                   designer=state, campaign=dict(campaign or {}), results={**summary, **dict(results or {})}, notes=notes)

    def turbine(self):
        """The turbine model the session refers to.

        Returns
        -------
        specdesign.turbine.TurbineModel
            The embedded IEA 15 MW model, or the reduced model of the OpenFAST deck.

        Raises
        ------
        ValueError
            If the session refers to a set of ``.lin`` files (read those with :meth:`linearization`).
        """
        if self.model == "iea15mw":
            return turbine.iea15mw()
        if "fst" in self.model:
            return turbine.from_openfast(self.model["fst"], self.model.get("cp_table"), self.model.get("discon"))
        raise ValueError("the session's model is a set of OpenFAST .lin files, not a TurbineModel; "
                         "read it with Session.linearization()")

    def linearization(self, **kwargs):
        """The session's OpenFAST linearisation set (:func:`specdesign.openfast.read_linearization`).

        Parameters
        ----------
        **kwargs
            Passed to :func:`specdesign.openfast.read_linearization` (``inputs``, ``outputs``).

        Returns
        -------
        specdesign.openfast.LinearizationData
            The azimuth-averaged linear model.

        Raises
        ------
        ValueError
            If the session refers to the embedded model.
        """
        if not isinstance(self.model, dict) or "lin_files" not in self.model:
            raise ValueError("the session's model is not a set of .lin files; use Session.turbine()")
        return read_linearization(self.model["lin_files"], **kwargs)

    def specification_name(self, name: str | None = None) -> str:
        """The name of a saved specification (the first when ``name`` is None).

        Parameters
        ----------
        name : str, optional
            A specification name.

        Returns
        -------
        str
            The name.

        Raises
        ------
        ValueError
            If the session has no specification or none called ``name``.
        """
        if not self.specifications:
            raise ValueError("the session holds no specification")
        if name is None:
            return next(iter(self.specifications))
        if name not in self.specifications:
            raise ValueError(f"no specification {name!r} in the session; it holds {sorted(self.specifications)}")
        return name

    def baseline(self, name: str | None = None):
        """The baseline of a saved specification, recomputed from the model and its context.

        Parameters
        ----------
        name : str, optional
            Which specification (default the first).

        Returns
        -------
        specdesign.spec.Baseline
            :func:`specdesign.spec.baseline_analysis` at the context's wind speed (m/s), output
            and Wöhler exponent: the same numbers as when the session was saved.
        """
        name = self.specification_name(name)
        c = self.spec_context[name]
        return _spec_module.baseline_analysis(self.turbine(), c["wind_speed"], c["output"], m=c["m"],
                                              turbulence_class=c.get("turbulence_class", "B"))


def _model_ref(model):
    if model == "iea15mw":
        return
    lin = (isinstance(model, dict) and set(model) == {"lin_files"} and isinstance(model["lin_files"], list)
           and model["lin_files"] and all(isinstance(p, str) and p for p in model["lin_files"]))
    deck = (isinstance(model, dict) and "fst" in model and set(model) <= {"fst", "cp_table", "discon"}
            and isinstance(model["fst"], str) and model["fst"]
            and all(model.get(k) is None or isinstance(model[k], str) and model[k] for k in ("cp_table", "discon")))
    if not (lin or deck):
        raise ValueError("model must be 'iea15mw' (the embedded model), {'fst': path, 'cp_table': path or None, "
                         "'discon': path or None} (an OpenFAST deck) or {'lin_files': [paths of OpenFAST .lin files]}, "
                         f"got {model!r:.120}")


def _check_context(name, c):
    if not isinstance(c, dict) or not {"wind_speed", "output", "m"} <= set(c) or set(c) - _CONTEXT_KEYS:
        raise ValueError(f"spec_context[{name!r}] must hold 'wind_speed' (m/s), 'output' and 'm' (and optionally "
                         f"'turbulence_class'), got {c!r:.120}")
    if not isinstance(c["output"], str) or not all(isinstance(c[k], (int, float)) and np.isfinite(c[k]) and c[k] > 0
                                                   for k in ("wind_speed", "m")):
        raise ValueError(f"spec_context[{name!r}]: output must be a string, wind_speed and m positive numbers; got {c!r:.120}")


def _json_exact(value, where):
    """Refuse what JSON cannot write or read back exactly (NaN, ±inf, non-string keys, objects)."""
    try:
        json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{where} must hold plain JSON values (finite numbers, strings, lists, dicts with string "
                         f"keys; None for a missing number): {e}") from None


def _floats(a):
    return np.asarray(a, float).tolist()


def _lti_to_dict(sys, where):
    if not isinstance(sys, ct.LTI) or sys.ninputs != 1 or sys.noutputs != 1:
        raise ValueError(f"{where} must be a SISO python-control LTI")
    if not ct.isctime(sys):  # dt None (a static gain such as a zero ATD) holds in continuous time too
        raise ValueError(f"{where} must be a continuous-time system (dt = 0)")
    if isinstance(sys, ct.TransferFunction):
        return {"num": _floats(sys.num[0][0]), "den": _floats(sys.den[0][0])}
    if isinstance(sys, ct.StateSpace):
        return {"ss": {k: _floats(getattr(sys, k)) for k in "ABCD"}}
    raise ValueError(f"{where}: a {type(sys).__name__} is neither a transfer function nor a state space")


def _lti_from_dict(d, where):
    if isinstance(d, dict) and set(d) == {"num", "den"}:
        num, den = (_finite_list(d[k], f"{where}.{k}") for k in ("num", "den"))
        if not np.any(den):
            raise ValueError(f"{where}.den is all zeros: no transfer function has that denominator")
        return ct.tf(num, den)
    if isinstance(d, dict) and set(d) == {"ss"} and isinstance(d["ss"], dict) and set(d["ss"]) == set("ABCD"):
        m = d["ss"]
        n = len(m["A"]) if isinstance(m["A"], list) else -1
        shapes = {"A": (n, n), "B": (n, 1), "C": (1, n), "D": (1, 1)}
        arrs = {k: _finite_list(m[k], f"{where}.ss.{k}") for k in "ABCD"}
        for k in "ABCD":
            if arrs[k].size != max(shapes[k][0], 0) * shapes[k][1]:
                raise ValueError(f"{where}.ss.{k} must have shape {shapes[k]} (A is {n}×{n}), got {arrs[k].size} values")
        return ct.ss(*(arrs[k].reshape(shapes[k]) for k in "ABCD"))
    raise ValueError(f"{where} must be {{'num', 'den'}} or {{'ss': {{'A', 'B', 'C', 'D'}}}}, got {d!r:.120}")


def _finite_list(value, where):
    """A (nested) list of finite numbers as a float array; a NaN, an inf (json reads NaN and
    Infinity), a bool or a string is refused naming ``where``."""
    flat = np.ravel(np.asarray(value, dtype=object)) if isinstance(value, list) else None
    if flat is None or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in flat):
        raise ValueError(f"{where} must be a list of numbers, got {value!r:.80}")
    a = np.asarray(value, float)
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{where} holds NaN or inf ({value!r:.80}); a controller or specification needs finite "
                         "coefficients")
    return a


def session_to_dict(session: Session) -> dict:
    """The session as plain JSON values (the file's content).

    Parameters
    ----------
    session : Session
        The session.

    Returns
    -------
    dict
        ``{"schema", "version", "model", "wind_speeds", "specifications", "controllers", "qft",
        "designer", "campaign", "results", "notes"}``; read back by :func:`session_from_dict`.

    Raises
    ------
    TypeError
        If ``session`` is not a :class:`Session`.
    """
    if not isinstance(session, Session):
        raise TypeError(f"session must be a specdesign.session.Session, got {type(session).__name__}")
    specs = {}
    for name, s in session.specifications.items():
        specs[name] = {"name": s.name, "context": dict(session.spec_context[name]),
                       "baseline": _lti_to_dict(s.baseline, f"specifications[{name!r}].baseline"),
                       "elements": [{"type": type(e).__name__, **{k: float(v) for k, v in asdict(e).items()}}
                                    for e in s.elements]}
    ctrls = {name: ({"elements": c.to_dict()} if isinstance(c, Controller) else _lti_to_dict(c, f"controllers[{name!r}]"))
             for name, c in session.controllers.items()}
    return {"schema": SCHEMA, "version": VERSION, "model": session.model, "wind_speeds": list(session.wind_speeds),
            "specifications": specs, "controllers": ctrls, **{k: getattr(session, k) for k in _TABLES},
            "notes": session.notes}


def session_from_dict(data: dict) -> Session:
    """The session of :func:`session_to_dict`; the schema, the version and every key are checked.

    Parameters
    ----------
    data : dict
        As written by :func:`session_to_dict`.

    Returns
    -------
    Session
        The session.

    Raises
    ------
    ValueError
        For another schema, a newer or unknown version, unknown keys or an invalid entry (named).
    """
    if not isinstance(data, dict) or data.get("schema") != SCHEMA:
        raise ValueError(f"not a design session: the file must be a JSON object with \"schema\": \"{SCHEMA}\"")
    version = data.get("version")
    if type(version) is not int or not 1 <= version <= VERSION:
        newer = type(version) is int and version > VERSION
        raise ValueError(f"design session version {version!r} is not supported: this specdesign reads versions 1 to "
                         f"{VERSION}" + ("; the file was written by a newer specdesign, upgrade to read it" if newer else ""))
    allowed = {"schema", "version", "model", "wind_speeds", "specifications", "controllers", *_TABLES, "notes"}
    extra = set(data) - allowed
    if extra:
        raise ValueError(f"unknown design session key(s) {sorted(extra)}; allowed: {sorted(allowed)}")
    specs, context = {}, {}
    for name, s in (data.get("specifications") or {}).items():
        where = f"specifications[{name!r}]"
        if not isinstance(s, dict) or set(s) != {"name", "context", "baseline", "elements"}:
            raise ValueError(f"{where} must hold exactly 'name', 'context', 'baseline' and 'elements'")
        elements = []
        for i, e in enumerate(s["elements"]):
            cls = _ELEMENT_TYPES.get(e.get("type")) if isinstance(e, dict) else None
            if cls is None:
                raise ValueError(f"{where}.elements[{i}] must have 'type' one of {sorted(_ELEMENT_TYPES)}, got {e!r:.80}")
            want = {f.name for f in fields(cls)}
            got = set(e) - {"type"}
            if got != want:
                raise ValueError(f"{where}.elements[{i}] ({cls.__name__}) must have exactly {sorted(want)}, got {sorted(got)}")
            elements.append(cls(**{k: e[k] for k in want}))
        specs[name] = _spec_module.Specification(_lti_from_dict(s["baseline"], f"{where}.baseline"), tuple(elements), s["name"])
        context[name] = s["context"]
    ctrls = {}
    for name, c in (data.get("controllers") or {}).items():
        if isinstance(c, dict) and set(c) == {"elements"}:
            ctrls[name] = Controller.from_dict(c["elements"])
        else:
            ctrls[name] = _lti_from_dict(c, f"controllers[{name!r}]")
    return Session(model=data.get("model", "iea15mw"), wind_speeds=tuple(data.get("wind_speeds", ())), specifications=specs,
                   spec_context=context, controllers=ctrls, notes=data.get("notes", ""),
                   **{k: data.get(k) or {} for k in _TABLES})


def save_session(path: str | os.PathLike, session: Session) -> Path:
    """Write a design session to a JSON file (plain text, versioned; floats exact).

    Parameters
    ----------
    path : str or os.PathLike
        The file to write (``.json``; its folder must exist).
    session : Session
        The session.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    TypeError
        If ``session`` is not a :class:`Session`.
    """
    path = Path(path)
    text = json.dumps(session_to_dict(session), indent=1, allow_nan=False, ensure_ascii=False)
    path.write_text(text + "\n", encoding="utf-8")
    return path


def load_session(path: str | os.PathLike) -> Session:
    """Read a design session written by :func:`save_session`.

    Relative paths of the model reference (``fst``, ``cp_table``, ``discon``, ``lin_files``) are
    taken from the session file's folder.

    Parameters
    ----------
    path : str or os.PathLike
        The session file.

    Returns
    -------
    Session
        The session, with the same numbers as the one saved.

    Raises
    ------
    FileNotFoundError
        If the file does not exist.
    ValueError
        If it is not JSON, repeats a key, or is not a design session of a version this
        specdesign reads (the message names the file).
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"), object_pairs_hook=distinct_keys())
        model = data.get("model") if isinstance(data, dict) else None
        if isinstance(model, dict):
            def here(p):
                return str((path.parent / p).resolve()) if isinstance(p, str) and p else p

            for k in ("fst", "cp_table", "discon"):
                if k in model:
                    model[k] = here(model[k])
            if isinstance(model.get("lin_files"), list):
                model["lin_files"] = [here(p) for p in model["lin_files"]]
        return session_from_dict(data)
    except (ValueError, TypeError) as e:
        raise ValueError(f"{path}: {e}") from None
