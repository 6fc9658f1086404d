"""One home per concept (issue 13) for ROSCO, the simulator, the turbine model and the wind.

ROSCO is reached in :mod:`specdesign.rosco` (its baseline re-exported from
:mod:`specdesign.turbine.baseline`, its torque law and DISCON.IN reader from
:mod:`specdesign.controller`: the same objects); the simulator is the package :mod:`specdesign.simulate`; every public
name importable before the split still is (the private ones are gone: no module uses another's).
tests/test_architecture.py checks private names across modules and module sizes,
tests/test_docstrings.py the documentation, for the whole package.
"""
import importlib
import inspect

import numpy as np
import pytest

from specdesign import rosco, simulate, turbine, wind

MODULES = [
    "specdesign.rosco", "specdesign.rosco.scheduled", "specdesign.wind",
    "specdesign.controller", "specdesign.controller.scheduled", "specdesign.controller.lti",
    "specdesign.controller.torque", "specdesign.controller.discon_file",
    "specdesign.simulate", "specdesign.simulate.core", "specdesign.simulate.checks", "specdesign.simulate.kernels",
    "specdesign.turbine", "specdesign.turbine.model", "specdesign.turbine.operating",
    "specdesign.turbine.kernel", "specdesign.turbine.tables", "specdesign.turbine.plant", "specdesign.turbine.baseline",
]

#: Every public name of specdesign.simulate / specdesign.turbine before the split: still
#: importable from there (discretize, renamed, warns: see below).
OLD_SIMULATE = [
    "KernelPlant", "MAX_STEP_EIGENVALUE", "SCHEDULE_FILTER_OMEGA", "SLOW_OMEGA", "ScheduledController",
    "SimulationDivergedError", "SimulationResult", "WIND_MEAN_TOLERANCE", "linear_plant_params", "rosco_scheduled",
    "sampled_loop_radius", "scheduled", "seed_for", "simulate", "split_integrator", "split_slow", "turbine_plant",
    "wind_series",
]
OLD_TURBINE = [
    "AERO_VARIABLES", "AeroExpansion", "INPUT_NAMES", "LOAD_INPUT_NAMES", "OUTPUT_NAMES", "OperatingPoint",
    "P_ACT_OMEGA", "P_ACT_ZETA", "P_DPITCH", "P_DTSR", "P_GEN_EFF", "P_INERTIA", "P_MY_PER_M", "P_N_PITCH",
    "P_N_TSR", "P_PITCH0", "P_PITCH_MAX", "P_PITCH_MIN", "P_RADIUS", "P_RATE_LIM", "P_RHO", "P_TSR0", "P_TWR_DAMP",
    "P_TWR_MASS", "P_TWR_STIFF", "RoscoSchedule", "STATE_NAMES", "TurbineModel", "aero_loads", "iea15mw", "mechanics", "outputs", "outputs_from", "rhs", "rosco_baseline", "rosco_gain_schedule",
    "speed_filter",
]


def test_rosco_has_one_home_re_exported_by_turbine_and_simulate():
    for name in ("RoscoSchedule", "rosco_gain_schedule", "speed_filter", "rosco_baseline"):
        assert getattr(turbine, name) is getattr(rosco, name)
    assert simulate.rosco_scheduled is rosco.rosco_scheduled
    assert simulate.seed_for is wind.seed_for and simulate.wind_series is wind.wind_series
    from specdesign.turbine import rosco_baseline  # the public contract

    assert rosco_baseline is rosco.rosco_baseline
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


def test_tustin_matrices_are_python_controls_tustin_map():
    import control

    c = control.tf([1.0, 0.2], [1.0, 1.0, 0.5])
    A, B, C, D = simulate.tustin_matrices(c, 0.05)
    d = control.c2d(control.ss(c), 0.05, method="tustin")  # python-control's own Tustin map
    np.testing.assert_allclose(A, d.A, rtol=1e-12)
    np.testing.assert_allclose(np.r_[B, C, D], np.r_[np.ravel(d.B), np.ravel(d.C), np.ravel(d.D)], rtol=1e-12)


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
