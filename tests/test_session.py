"""Design sessions (specdesign.session): a saved session reloads to bitwise the same numbers.

The oracle of every round trip is the object before saving: the reloaded specification's
promise (recomputed from the model and the saved context), the specification's response and
each controller's frequency response must be equal to the last bit, since JSON writes floats
by their shortest repr, which reads back to the same double.
"""
from __future__ import annotations

import json

import control as ct
import numpy as np
import pytest

from loopshaping import controller as lc
from specdesign import spec
from specdesign.session import Session, load_session, save_session, session_to_dict
from specdesign.turbine import iea15mw, rosco_baseline


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    model = iea15mw()
    base = spec.baseline_analysis(model, 19.0)
    res = spec.shape_to_target(base, 15.0)
    specification = res.specification.add(spec.LeadLag(2.0, 4.0)).add(spec.Gain(0.5)).add(spec.LowPass(5.0, 0.6))
    pitch = lc.Controller((lc.gain(-0.31234567891), lc.integrator(1), lc.real_zero(0.07), lc.notch(1.08, 0.05, 0.4),
                           lc.real_pole(3.3)))
    speed = spec.speed_specification(model, 19.0, margin_db=3.0)
    session = Session(
        wind_speeds=(19.0,), specifications={"tower": specification, "speed": speed},
        spec_context={"tower": {"wind_speed": 19.0, "output": "tower_base_my", "m": 4.0},
                      "speed": {"wind_speed": 19.0, "output": "gen_speed", "m": 4.0}},
        controllers={"pitch": pitch, "rosco": rosco_baseline(model, 19.0), "ss": ct.ss(ct.tf([1.0, 0.3], [1.0, 2.0, 1.7]))},
        qft={"wind_speed": 19.0, "target_reduction": 25.0, "options": {"speed_relax_db": 4.5, "template_offsets": [-1, 0, 1]}},
        campaign={"turbine": "iea15mw", "wind_speeds": [19.0], "seeds": [0, 1], "duration": 600.0},
        results={"promised_del_pct": res.promise.exact_del, "table": [[1.5, 2.25]]}, notes="issue 18")
    path = save_session(tmp_path_factory.mktemp("session") / "design.json", session)
    return session, base, path


def test_a_saved_session_reloads_to_bitwise_the_same_numbers(saved):
    session, base, path = saved
    back = load_session(path)
    w = np.logspace(-3, 2, 997)
    # the promise, recomputed from the model and the saved context, is the one before saving
    for name in ("tower", "speed"):
        before = spec.promise_of(session.specifications[name], spec.baseline_analysis(
            iea15mw(), 19.0, session.spec_context[name]["output"]))
        assert spec.promise_of(back.specifications[name], back.baseline(name)) == before
        np.testing.assert_array_equal(back.specifications[name].response(w), session.specifications[name].response(w))
        assert back.specifications[name].elements == session.specifications[name].elements
    assert back.baseline("tower").damage_rate == base.damage_rate
    # every controller's frequency response, bitwise
    np.testing.assert_array_equal(back.controllers["pitch"].response(w), session.controllers["pitch"].response(w))
    assert back.controllers["pitch"] == session.controllers["pitch"]
    for name in ("rosco", "ss"):
        a, b = (ct.frequency_response(s, w) for s in (session.controllers[name], back.controllers[name]))
        np.testing.assert_array_equal(np.asarray(b.complex), np.asarray(a.complex))
    for key in ("qft", "campaign", "results", "notes", "model"):
        assert getattr(back, key) == json.loads(json.dumps(getattr(session, key)))
    assert back.wind_speeds == session.wind_speeds == (19.0,)
    # plain JSON any reader opens (no NaN tokens, no pickle), with the schema and its version
    data = json.loads(path.read_text())
    assert data["schema"] == "specdesign.session" and data["version"] == 1
    assert data["controllers"]["rosco"].keys() == {"num", "den"}  # the controller-file format of `validate`


@pytest.fixture
def small_loop():
    """A three-case template and its stability bounds for the Designer, on the Agg backend (figures closed after)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from loopshaping import qft

    P = [ct.tf([k], [1, 31, 30]) for k in (1.0, 5.0, 10.0)]
    tmpl = qft.Template.from_systems(P, np.array([0.1, 5.0, 100.0]))
    yield tmpl, qft.bounds(tmpl, "stability", 1.2)
    plt.close("all")


def test_the_designer_and_the_explorer_start_from_a_saved_session(saved, small_loop, tmp_path):
    from loopshaping.interactive import Designer
    from specdesign.plots.spec import NotchExplorer

    session, base, _ = saved
    tmpl, b = small_loop
    d = Designer(b, tmpl, lc.Controller((lc.gain(379.123), lc.real_zero(42.0), lc.complex_pole(247.0, 0.5))))
    d.selected = 2
    s2 = Session(**{**{f: getattr(session, f) for f in ("wind_speeds", "specifications", "spec_context", "controllers")},
                    "designer": d.to_state()})
    back = load_session(save_session(tmp_path / "s.json", s2))
    d2 = Designer.from_session(back, b, tmpl)
    assert d2.controller == d.controller and d2.selected == 2
    st, st2 = d.state(), d2.state()
    for k in ("phase_deg", "magnitude_db", "worst_T_db", "stable", "rightmost_pole"):
        np.testing.assert_array_equal(getattr(st2, k), getattr(st, k))
    # the explorer: the saved specification's first notch and its promise, bitwise
    ex = NotchExplorer.from_session(back, "tower")
    notch = [e for e in session.specifications["tower"].elements if isinstance(e, spec.Notch)][0]
    assert ex.notch == notch
    assert ex.promise == spec.promise_of(notch.response(base.omega), base)
    ex2 = NotchExplorer.from_session(save_session(tmp_path / "s2.json", s2), "tower")  # from the path
    assert ex2.promise == ex.promise
    with pytest.raises(ValueError, match="no notch"):
        NotchExplorer.from_session(back, "speed")
    with pytest.raises(ValueError, match="designer state"):
        Designer.from_session(session, b, tmpl)


def test_a_newer_or_foreign_file_is_refused_with_a_clear_message(saved, tmp_path):
    session, _, path = saved
    data = json.loads(path.read_text())
    cases = [
        ({**data, "version": 2}, "newer specdesign"),
        ({**data, "version": "1"}, "version '1' is not supported"),
        ({k: v for k, v in data.items() if k != "schema"}, "not a design session"),
        ({**data, "pickle": "x"}, r"unknown design session key\(s\) \['pickle'\]"),
        ({**data, "model": "nrel5mw"}, "model must be 'iea15mw'"),
    ]
    for bad, msg in cases:
        p = tmp_path / "bad.json"
        p.write_text(json.dumps(bad))
        with pytest.raises(ValueError, match=msg) as e:
            load_session(p)
        assert str(p) in str(e.value)
    p.write_text('{"schema": "specdesign.session", "version": 1, "notes": "a", "notes": "b"}')
    with pytest.raises(ValueError, match="'notes' appears twice"):
        load_session(p)
    spec_bad = json.loads(path.read_text())
    spec_bad["specifications"]["tower"]["elements"][0]["depth"] = 3.0
    p.write_text(json.dumps(spec_bad))
    with pytest.raises(ValueError, match=r"elements\[0\] \(Notch\) must have exactly"):
        load_session(p)


def test_bad_session_fields_name_the_field():
    with pytest.raises(ValueError, match="results must hold plain JSON values"):
        Session(results={"deviation_pp": float("nan")})
    with pytest.raises(ValueError, match="wind_speeds"):
        Session(wind_speeds=(19.0, -3.0))
    with pytest.raises(TypeError, match=r"controllers\['C'\]"):
        Session(controllers={"C": "PI"})
    with pytest.raises(ValueError, match=r"needs spec_context\['W'\]"):
        Session(specifications={"W": spec.Specification(ct.tf([1.0], [1.0, 1.0]))})
    with pytest.raises(TypeError, match="Session"):
        session_to_dict({"wind_speeds": [19.0]})
    with pytest.raises(ValueError, match="continuous-time"):
        session_to_dict(Session(controllers={"C": ct.tf([1.0], [1.0, 0.5], 0.1)}))


def test_a_session_on_an_openfast_deck_reloads_its_model_by_reference(tmp_path):
    # the model is referred to, not copied: the deck's path relative to the session file; the
    # baseline recomputed from the reloaded session is the one computed from the deck directly
    try:
        from specdesign.rosco import rosco_test_cases

        deck = rosco_test_cases() / "NREL-5MW"
    except ModuleNotFoundError as e:
        pytest.skip(f"the rosco package (its OpenFAST decks) is not installed ({e})")
    import os
    import shutil

    from specdesign.turbine import from_openfast

    shutil.copytree(deck, tmp_path / "NREL-5MW")
    folder = tmp_path / "sessions"
    folder.mkdir()
    model = from_openfast(tmp_path / "NREL-5MW" / "NREL-5MW.fst")
    base = spec.baseline_analysis(model, 18.0)
    w = base.system
    s = Session(model={"fst": os.path.join("..", "NREL-5MW", "NREL-5MW.fst")}, wind_speeds=(18.0,),
                specifications={"tower": spec.Specification(w, (spec.Notch(2.0, 3.0, 0.3),))},
                spec_context={"tower": {"wind_speed": 18.0, "output": "tower_base_my", "m": 4.0}})
    back = load_session(save_session(folder / "deck.json", s))
    assert back.model["fst"] == str((tmp_path / "NREL-5MW" / "NREL-5MW.fst").resolve())
    assert back.turbine().name == "NREL-5MW"
    again = back.baseline("tower")
    np.testing.assert_array_equal(again.sensitivity, base.sensitivity)
    assert spec.promise_of(back.specifications["tower"], again) == spec.promise_of(s.specifications["tower"], base)
    with pytest.raises(ValueError, match="not a set of .lin files"):
        back.linearization()
    with pytest.raises(ValueError, match="an OpenFAST deck"):
        Session(model={"fst": "a.fst", "turbsim": "b.inp"})


@pytest.mark.slow  # one design_qft at 19 m/s (~10 s)
def test_the_session_of_a_qft_design_reloads_bitwise_and_reopens_the_designer(tmp_path):
    import warnings

    from loopshaping.controller import Controller
    from loopshaping.interactive import Designer
    from specdesign import qft
    from specdesign.plots.spec import NotchExplorer

    model = iea15mw()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        d = qft.design_qft(model, 19.0, spec=qft.spec_notch(25.0))
    designer = Designer(d.pitch_bounds, d.pitch_template, Controller.from_tf(d.pitch_controller))
    designer.set_param(0, k=1.1 * designer.controller.elements[0].params["k"])
    s = Session.from_qft(d, designer=designer, results={"note": "gain +10 %"})
    back = load_session(save_session(tmp_path / "qft.json", s))
    w = d.dense_omega
    for name, c in (("pitch", d.pitch_controller), ("atd", d.atd_controller)):
        np.testing.assert_array_equal(back.controllers[name](1j * w), c(1j * w))
    for name, sp in (("notch", d.shaping.specification), ("tower", d.tower_spec), ("speed", d.speed_spec)):
        np.testing.assert_array_equal(back.specifications[name].response(w), sp.response(w))
    # the notch specification's promise, recomputed from the reloaded session: bitwise the one of
    # the specification before saving, and the design's own (computed from the notch response
    # instead of W/T: equal to rounding)
    promise = spec.promise_of(back.specifications["notch"], back.baseline("notch"))
    assert promise == spec.promise_of(d.shaping.specification, d.baseline)
    assert promise.exact_del == pytest.approx(d.shaping.promise.exact_del, rel=1e-12)
    assert back.results["notch_spec_promised_del_pct"] == d.shaping.promise.exact_del
    assert back.results["note"] == "gain +10 %" and back.results["success"] == d.success
    assert back.qft["options"]["template_offsets"] == list(d.options["template_offsets"])
    again = Designer.from_session(back, d.pitch_bounds, d.pitch_template)
    assert again.controller == designer.controller
    np.testing.assert_array_equal(again.state().rightmost_pole, designer.state().rightmost_pole)
    assert NotchExplorer.from_session(back, "notch").notch == d.shaping.notches[0]
    with pytest.raises(TypeError, match="QFTDesign"):
        Session.from_qft(s)
    # design_qft's default (specification-driven: the certificate, reduced; no ATD, a static zero
    # whose timebase python-control leaves unspecified) saves and reloads as well
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # cvxpy: "solution may be inaccurate" on some rungs
        t = qft.design_qft(model, 19.0)
    back_t = load_session(save_session(tmp_path / "target.json", Session.from_qft(t)))
    for name, c in (("pitch", t.pitch_controller), ("atd", t.atd_controller)):
        np.testing.assert_array_equal(back_t.controllers[name](1j * w), c(1j * w))
    np.testing.assert_array_equal(back_t.specifications["tower"].response(w), t.tower_spec.response(w))
    import matplotlib.pyplot as plt

    plt.close("all")


def test_widgets_opened_from_a_saved_session_show_its_state(saved, small_loop, tmp_path):
    # the controls of a reloaded Designer and explorer show the saved controller and notch
    # (the figure draws those: test above), exactly (no browser rounds a slider to its step here)
    from loopshaping.interactive import Designer
    from specdesign.plots.spec import NotchExplorer

    session, _, _ = saved
    tmpl, b = small_loop
    d = Designer(b, tmpl, session.controllers["pitch"])
    d.selected = 3  # the notch
    back = load_session(save_session(tmp_path / "s.json", Session(**{
        **{f: getattr(session, f) for f in ("wind_speeds", "specifications", "spec_context")}, "designer": d.to_state()})))
    ui = Designer.from_session(back, b, tmpl).widget()
    select, _, rows, json_box, _ = ui.children[0].children
    assert select.value == 3 and json_box.value == session.controllers["pitch"].to_json()
    saved_notch = session.controllers["pitch"].elements[3].params
    shown = {row.children[0].description: (row.children[0].value, row.children[1].value) for row in rows.children}
    assert shown == {name: (v, v) for name, v in saved_notch.items()}
    ex = NotchExplorer.from_session(back, "tower")
    sliders = ex.widget().children[0].children
    assert [s.value for s in sliders] == [ex.notch.omega_n, ex.notch.depth_db, ex.notch.width]
