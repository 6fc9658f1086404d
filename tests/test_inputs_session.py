"""Session doors (issue "Nothing silently wrong, part two"): a NaN or inf anywhere in a
controller or a specification's baseline is refused, in a session built in Python and in a
file loaded from disk (json reads NaN and Infinity), naming the entry; the file's path is in
the message."""
from __future__ import annotations

import json

import control as ct
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from specdesign import spec
from specdesign.session import SCHEMA, VERSION, Session, load_session, session_from_dict

PI = {"num": [-0.3, -0.06], "den": [1.0, 0.0]}
SS = {"ss": {"A": [[-1.0]], "B": [[1.0]], "C": [[2.0]], "D": [[0.0]]}}


def _file(tmp_path, controllers):
    data = {"schema": SCHEMA, "version": VERSION, "controllers": controllers}
    path = tmp_path / "s.json"
    path.write_text(json.dumps(data))  # json.dumps writes NaN / Infinity as bare words, which json.loads reads
    return path


def test_good_controllers_load(tmp_path):
    s = load_session(_file(tmp_path, {"PI": PI, "SS": SS}))
    # the state space 2/(s+1): DC gain 2
    assert float(np.real(ct.dcgain(s.controllers["SS"]))) == pytest.approx(2.0)


@pytest.mark.parametrize("bad, where", [
    ({"num": [float("nan")], "den": [1.0]}, r"controllers\['K'\]\.num holds NaN"),  # a NaN gain
    ({"num": [1.0], "den": [1.0, float("inf")]}, r"controllers\['K'\]\.den holds NaN or inf"),
    ({"num": [1.0], "den": [0.0, 0.0]}, r"controllers\['K'\]\.den is all zeros"),
    ({"num": [True], "den": [1.0]}, r"controllers\['K'\]\.num must be a list of numbers"),
    ({"num": "1", "den": [1.0]}, r"controllers\['K'\]\.num must be a list of numbers"),
    ({"ss": {**SS["ss"], "A": [[float("nan")]]}}, r"controllers\['K'\]\.ss\.A holds NaN"),
    ({"ss": {**SS["ss"], "D": [[float("-inf")]]}}, r"controllers\['K'\]\.ss\.D holds NaN"),
    ({"ss": {**SS["ss"], "B": [[1.0], [2.0]]}}, r"controllers\['K'\]\.ss\.B must have shape \(1, 1\)"),
    ({"ss": {**SS["ss"], "A": [[-1.0, 0.0], [0.0]]}}, r"controllers\['K'\]\.ss\.A must be a list of numbers"),
    ({"elements": {"version": 1, "elements": [{"kind": "gain", "params": {"k": float("nan")}}]}}, "k=nan"),
])
def test_a_nan_controller_is_refused_on_load_naming_file_and_entry(tmp_path, bad, where):
    path = _file(tmp_path, {"K": bad})
    with pytest.raises(ValueError, match=where) as e:
        load_session(path)
    assert str(path) in str(e.value)


@pytest.mark.parametrize("K", [ct.tf([np.nan], [1.0]), ct.ss([[-1.0]], [[1.0]], [[np.inf]], [[0.0]])])
def test_a_nan_controller_is_refused_in_python(K):
    with pytest.raises(ValueError, match=r"controllers\['K'\] has a NaN or inf entry"):
        Session(controllers={"K": K})


def test_a_nan_specification_baseline_is_refused():
    w = spec.Specification(ct.tf([1.0], [1.0, 1.0]))
    data = {"schema": SCHEMA, "version": VERSION,
            "specifications": {"W": {"name": "W", "context": {"wind_speed": 19.0, "output": "tower_base_my", "m": 4.0},
                                     "baseline": {"num": [float("nan")], "den": [1.0, 1.0]}, "elements": []}}}
    with pytest.raises(ValueError, match=r"specifications\['W'\]\.baseline\.num holds NaN"):
        session_from_dict(data)
    assert w.baseline is not None  # the finite one builds


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(allow_nan=False, allow_infinity=False), max_size=3),
       st.sampled_from([float("nan"), float("inf"), float("-inf")]), st.integers(0, 3), st.integers(0, 1))
def test_any_non_finite_coefficient_is_refused(finite, bad, at, which):
    coeffs = finite[:at] + [bad] + finite[at:]  # a non-finite value anywhere among finite ones
    d = {"num": [1.0], "den": [1.0, 1.0]}
    d["num" if which == 0 else "den"] = coeffs
    with pytest.raises(ValueError, match=r"holds NaN or inf"):
        session_from_dict({"schema": SCHEMA, "version": VERSION, "controllers": {"K": d}})


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), True])
def test_a_nan_gain_element_is_refused_on_load(bad):
    data = {"schema": SCHEMA, "version": VERSION,
            "specifications": {"W": {"name": "W", "context": {"wind_speed": 19.0, "output": "tower_base_my", "m": 4.0},
                                     "baseline": {"num": [1.0], "den": [1.0, 1.0]},
                                     "elements": [{"type": "Gain", "gain_db": bad}]}}}
    with pytest.raises(ValueError, match=r"Gain.gain_db=.* must be a finite number of dB"):
        session_from_dict(data)
    with pytest.raises(ValueError, match="Gain.gain_db"):
        spec.Gain(bad)
