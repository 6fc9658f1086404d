"""One home per concept (issue 13) for ROSCO, the simulator, the turbine model and the wind.

ROSCO lives in :mod:`specdesign.rosco`, re-exported by :mod:`specdesign.turbine` and
:mod:`specdesign.simulate`; the simulator is the package :mod:`specdesign.simulate`; every name
importable before the split still is; the public names are documented (numpydoc) and their
examples run (methods and compiled kernels included). tests/test_architecture.py checks the
private names across modules and the module sizes for the whole package.
"""
import doctest
import importlib
import inspect

import numpy as np
import pytest

from specdesign import rosco, simulate, turbine, wind

MODULES = [
    "specdesign.rosco", "specdesign.wind",
    "specdesign.simulate", "specdesign.simulate.core", "specdesign.simulate.checks",
    "specdesign.simulate.schedule", "specdesign.simulate.controllers", "specdesign.simulate.kernels",
    "specdesign.turbine", "specdesign.turbine.model", "specdesign.turbine.operating",
    "specdesign.turbine.kernel", "specdesign.turbine.tables",
]

#: Every name of specdesign.simulate / specdesign.turbine before the split (imports of other
#: packages aside): still importable from there.
OLD_SIMULATE = [
    "KernelPlant", "MAX_STEP_EIGENVALUE", "SCHEDULE_FILTER_OMEGA", "SLOW_OMEGA", "ScheduledController",
    "SimulationDivergedError", "SimulationResult", "WIND_MEAN_TOLERANCE", "_BANKS", "_FORMS", "_KIND_LINEAR",
    "_KIND_TURBINE", "_NONFINITE", "_RADIUS_TOL", "_REBOUND", "_as_lti", "_bank", "_check_loop_step", "_check_step",
    "_compiled_for", "_is_lti_like", "_kout", "_krhs", "_lin_outputs", "_lin_rhs", "_make_bank", "_outputs_all",
    "_raise_diverged", "_rk4", "_run_batch", "_run_callable", "_run_one", "_step_all", "_turbine_outputs",
    "_turbine_rhs", "_warn_unstable", "_wind_at", "discretize", "linear_plant_params", "rosco_scheduled",
    "sampled_loop_radius", "scheduled", "seed_for", "simulate", "split_integrator", "split_slow", "turbine_plant",
    "wind_series",
]
OLD_TURBINE = [
    "AERO_VARIABLES", "AeroExpansion", "INPUT_NAMES", "LOAD_INPUT_NAMES", "OUTPUT_NAMES", "OperatingPoint",
    "P_ACT_OMEGA", "P_ACT_ZETA", "P_DPITCH", "P_DTSR", "P_GEN_EFF", "P_INERTIA", "P_MY_PER_M", "P_N_PITCH",
    "P_N_TSR", "P_PITCH0", "P_PITCH_MAX", "P_PITCH_MIN", "P_RADIUS", "P_RATE_LIM", "P_RHO", "P_TSR0", "P_TWR_DAMP",
    "P_TWR_MASS", "P_TWR_STIFF", "RoscoSchedule", "STATE_NAMES", "TurbineModel", "_DATA", "_H", "_HEADER",
    "_bicubic", "_bicubic_coefficients", "_read_rotor_table", "_read_text", "_rotor_coefficients", "_uniform",
    "aero_loads", "iea15mw", "mechanics", "outputs", "outputs_from", "rhs", "rosco_baseline", "rosco_gain_schedule",
    "speed_filter",
]


def test_rosco_has_one_home_re_exported_by_turbine_and_simulate():
    for name in ("RoscoSchedule", "rosco_gain_schedule", "speed_filter", "rosco_baseline"):
        assert getattr(turbine, name) is getattr(rosco, name)
    assert simulate.rosco_scheduled is rosco.rosco_scheduled
    assert simulate.seed_for is wind.seed_for and simulate.wind_series is wind.wind_series
    from specdesign.turbine import rosco_baseline  # the public contract

    assert rosco_baseline is rosco.rosco_baseline
    assert turbine._rotor_coefficients is rosco.first_order_rotor_model
    with pytest.raises(AttributeError):
        turbine.no_such_name  # noqa: B018
    with pytest.raises(AttributeError):
        simulate._no_such_name  # noqa: B018


@pytest.mark.parametrize("module, names", [("specdesign.simulate", OLD_SIMULATE), ("specdesign.turbine", OLD_TURBINE)])
def test_every_old_name_is_still_importable(module, names):
    mod = importlib.import_module(module)
    missing = [n for n in names if not hasattr(mod, n)]
    assert not missing, missing
    star = {}
    exec(f"from {module} import *", star)
    assert set(mod.__all__) <= set(star)


def test_old_private_aliases_are_the_public_functions():
    assert simulate._check_step is simulate.check_step
    assert simulate._check_loop_step is simulate.check_loop_step
    assert simulate._as_lti is simulate.as_lti and simulate._is_lti_like is simulate.is_lti_like
    assert simulate._turbine_rhs is turbine.rhs and simulate._turbine_outputs is turbine.outputs
    assert turbine._bicubic is turbine.kernel.bicubic and turbine._HEADER == turbine.kernel.HEADER_SIZE


def test_first_order_rotor_model_is_the_rotor_row_of_the_jacobian():
    model = turbine.iea15mw()
    pitch, a, b_beta, b_wind = rosco.first_order_rotor_model(model, 19.0)
    op = model.trim(19.0)
    A, B, _, _ = model.jacobians(op)
    assert (pitch, a, b_beta, b_wind) == (op.pitch, A[0, 0], A[0, 3], B[0, 0])
    s = rosco.rosco_gain_schedule(model, [15.0, 19.0, 23.0])
    assert np.array_equal(s.A, [rosco.first_order_rotor_model(model, v)[1] for v in (15.0, 19.0, 23.0)])


def _public_callables(module):
    mod = importlib.import_module(module)
    for name in mod.__all__:
        obj = getattr(mod, name)
        if not (inspect.isfunction(obj) or inspect.isclass(obj) or hasattr(obj, "py_func")):
            continue
        yield f"{module}.{name}"
        if inspect.isclass(obj) and obj.__module__ == module:
            for attr, v in vars(obj).items():
                if not attr.startswith("_") and (inspect.isfunction(v) or isinstance(v, (classmethod, staticmethod))):
                    yield f"{module}.{name}.{attr}"


@pytest.mark.parametrize("module", MODULES)
def test_public_names_have_numpydoc_docstrings_and_their_examples_run(module):
    from numpydoc.validate import validate

    bad = {}
    for qual in _public_callables(module):
        errs = [code for code, _ in validate(qual)["errors"] if code in ("GL08", "PR01", "PR02", "RT01")]
        if errs:
            bad[qual] = errs
    assert not bad, bad
    assert doctest.testmod(importlib.import_module(module), optionflags=doctest.ELLIPSIS).failed == 0
