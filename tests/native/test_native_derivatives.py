"""Directional and adjoint derivatives of the native FMUs (``fmu_src/native/fmi/fmu_derivatives.c``), both FMI
versions, both interfaces: declared in the model description exactly for the models whose C port gives
the ``jacobian`` hook, equal to central differences of the same FMU and to Richardson-extrapolated
differences of the Python core, the adjoint the transpose of the directional derivative, and every
hostile call refused with a defined status and a logged reason.

Tolerances (``support.derivatives``): the central difference through the FMU with a relative step of
1e-6 errs by h^2 |f'''| / 6 + eps |f| / h, about 2e-10 of the outputs' scale (measured up to 2.1e-10):
the exact derivative must agree within 1e-7 of the row's largest scaled entry, plus 10 eps |f| / h for
an output much larger than what it moves by. The Python core, differenced with steps 2e-3, 1e-3, 5e-4
and extrapolated twice (error O(h^6), rounding about 1e-12; measured up to 1.4e-12), within 1e-10 (rows where
large terms cancel, ``support.derivatives.ROUNDING_ROWS``, within their differences' own rounding): an
independent derivative, as the Python cores convert their inputs to float (``np.asarray(dtype=float)``)
and cannot take the complex step. Where a model's values round above eps (a linear solve's cond eps:
ROUNDING) both bounds add that rounding's share; where its outputs interpolate tables each core computes
itself, the core comparison adds how far the two tables' slopes may differ (CORE_AGREEMENT). The adjoint
identity v^T (J w) = (J^T v)^T w holds to rounding (1e-13 of |v|^T |J| |w|).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
import zipfile
from ctypes import c_double, c_uint
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException

from driveline.catalog import MODELS
from fmu_harness.packaging import native
from fmu_harness.runs.runner import LoggedInstance
from support import derivatives
from support.model_exchange import ModelExchange
from support.native_rotor import SOLVE_ROUNDING

PROVIDING = [name for name in native.native_models() if native.provides_derivatives(name)]
INTERFACES = ("ModelExchange", "CoSimulation")
FMU_TOLERANCE = 1e-7
#: The FMU's differences are taken with the step and its half: the half step's truncation c h^2 / 4 is a third of
#: the two differences' gap (allowed twice, for the h^4 remainder and the gap's own rounding). Below the bound
#: where the outputs are smooth on the step's scale; PowertrainMounts' snubber blends are not: their stop rates
#: (up to 24 times the linear rate) come in over millimetres (the force's third derivative up to 6 k_s / w^2),
#: and a micrometre's step truncates by up to 1.2e-6 of a row's scale on the rubber default (measured 2026-12-07).
HALF_STEP = derivatives.FMU_STEP / 2
TRUNCATION_SHARE = 2.0 / 3.0
CORE_TOLERANCE = 1e-10
TIME = 0.05  # s: a point of a source away from t = 0
SHIFT = 0.4  # rad: the states moved from their start, away from the joints' symmetric positions
#: States a model's points set after the shift, point by point (the start values, then its
#: dependency_points). VehicleDriveline's slips moved by SHIFT would be 0.4 on both tyres, deep in the tyre
#: force's saturation (C_slip slip / (mu_road F_z) = 7.2: dF_x / d slip 0.18 N against F_x 4.5 kN, where the
#: core's extrapolated differences err by 7e-9), and its speed 0.4 and 0.45 m/s forward at both: the points
#: take a driving and a braking tyre each, in the linear range (0.02: 0.36 in the tanh), the transition (0.05)
#: and towards the saturation (-0.15: the slope 2 % of C_slip), the car reversing and within the rolling
#: resistance's regularisation (v_x / v_low = 0.5).
STATES = {"VehicleDriveline": ({"v_x": -2.0, "slip_left": 0.02, "slip_right": -0.05},
                               {"v_x": 0.05, "slip_left": 0.05, "slip_right": -0.15}),
          #: PowertrainMounts moved by SHIFT would carry each wheel's joint 0.4 m away, beyond its halfshaft's reach
          #: (the geometry outputs refuse it): a displacement and a velocity off every axis, a few mm and mrad, the
          #: launch's size
          "PowertrainMounts": (*({**dict(zip(("x", "y", "z", "roll", "pitch", "yaw"), np.array(q) * scale)),
                                     **dict(zip(("x_dot", "y_dot", "z_dot", "roll_dot", "pitch_dot", "yaw_dot"),
                                                np.array(v) * scale))}
                                    for scale in (1.0, -0.7)
                                    for q, v in [((2e-3, -1.5e-3, 3e-3, 4e-3, -3e-3, 5e-3),
                                                  (0.05, -0.04, 0.03, 0.2, -0.3, 0.25))]),
                               # the snubbed layout's point: every mount 28 mm or more onto its stop, beyond the blend;
                               # the rubber layout's the same (its gaps 2 to 10 mm), its branches' forces SHIFT in N
                               *({"x": 0.03, "y": -0.03, "z": 0.03, "roll": 0.005, "pitch": -0.004, "yaw": 0.003,
                                  "x_dot": 0.1, "y_dot": -0.1, "z_dot": 0.1, "roll_dot": 0.2, "pitch_dot": -0.2,
                                  "yaw_dot": 0.2},) * 2)}


#: Points of a model's derivatives beyond its dependency points (which the dependency tests pay for at every
#: parameter): CriticalSpeeds below zero with heavy damping, the unbalance and the response off the middle, and
#: on anisotropic damped bearings with two unbalances (the doubled response system, the sorted Campbell table);
#: PowertrainMounts on snubbers (tests/support/snubbed_mounts.toml) and on rubber (its Maxwell branches' states,
#: their rates' rows), its states moved by SHIFT far onto the stops:
#: the tangent rates k + k_s of the progressive characteristics (inside a stop's 2 mm blend the rate's third
#: derivative, k_s 6 / w^2, makes the differences' truncation error h^2 F''' / 6 exceed their bounds)
DERIVATIVE_POINTS = {"CriticalSpeeds": (
    {"omega_in": -500.0, "c_bearing": 5000.0, "unbalance_position": 0.3, "response_position": 0.8},
    {"layout": str(Path(__file__).parents[1] / "support" / "anisotropic_tube.toml"), "omega_in": -700.0}),
    "PowertrainMounts": ({"layout": str(Path(__file__).parents[1] / "support" / "snubbed_mounts.toml"),
                          "F_x": 300.0, "T_in_right": 400.0},
                         {"layout": "transverse_fwd_powertrain_rubber", "T_mean": 1100.0, "T_motor": 1100.0})}


#: Rows whose values round above eps, with their relative rounding: CriticalSpeeds' unbalance response and
#: bearing force come from a banded solve of the dynamic stiffness (support.native_rotor.SOLVE_ROUNDING). A
#: difference with step h errs by up to it |f| / h, the extrapolated one by EXTRAPOLATION_ROUNDING times that.
ROUNDING = {"CriticalSpeeds": {"unbalance_response": SOLVE_ROUNDING, "bearing_force_max": SOLVE_ROUNDING}}
#: A cubic spline's slope moves by at most 8.62 times a change of its knot values over the knot spacing
#: (not-a-knot ends; 2.9 inside; scipy, uniform knots).
SPLINE_SLOPE_GAIN = 8.62


def _critical_speeds_tables(name: str, values: dict, outputs: dict[str, float]) -> dict[str, float]:
    """CriticalSpeeds' rows read from cubic splines through tables each core computes itself (whirl roots, damped
    modes): how far the cores' slopes in omega_in may differ, from how closely their tabulated values agree
    (whirl frequencies within 1.0e-15 relative, their roots refined to rounding; damping ratios within 4.2e-13,
    two eigensolvers; measured 2026-11-27 at every knot of every point; 4e-15 and 1.5e-12 taken) over the
    smallest knot spacing."""
    model = derivatives.analysed(name, values)
    whirl = SPLINE_SLOPE_GAIN * 4e-15 / np.diff(model._analysis.whirl.knots).min()
    rows = {row: whirl * abs(outputs[row]) for row in
            ("whirl_forward_1", "whirl_forward_2", "whirl_backward_1", "whirl_backward_2")}
    return rows | {"damping_ratio": SPLINE_SLOPE_GAIN * 1.5e-12 / np.diff(model._unbalance.modes.x).min()}


#: Per model, its rows' bound on the difference of the cores' slopes beyond the extrapolation's error (its
#: models have one known)
CORE_AGREEMENT = {"CriticalSpeeds": _critical_speeds_tables}


def _rounding(name: str, rows: list[str]) -> np.ndarray:
    """Each row's relative rounding where ROUNDING declares it, else 0."""
    return np.array([ROUNDING.get(name, {}).get(row, 0.0) for row in rows])


def _points(name: str) -> list[tuple[dict, dict]]:
    """Each point's start values and the states it sets (STATES)."""
    points = [{}, *MODELS[name].dependency_points, *DERIVATIVE_POINTS.get(name, ())]
    return list(zip(points, STATES.get(name, ({},) * len(points)), strict=True))




def _at_point(path, fmi: str, point: tuple[dict, dict], folder) -> ModelExchange:
    """A Model Exchange instance at the point's start values, time TIME and its states moved by SHIFT but
    for those the point sets."""
    start_values, states = point
    model = ModelExchange(path, fmi, start_values, folder)
    model.fmu.setTime(TIME)
    moved = model.get_states() + SHIFT
    names = [state.name for state in MODELS[model.description.modelName].spec.states]
    for state, value in states.items():
        moved[names.index(state)] = value
    model.set_states(moved)
    return model


def _description_flags(path, fmi: str) -> dict[str, dict[str, str]]:
    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read("modelDescription.xml"))
    names = ("providesDirectionalDerivatives", "providesAdjointDerivatives") if fmi == "3" else (
        "providesDirectionalDerivative",)
    return {interface.tag: {n: interface.get(n, "false") for n in names}
            for interface in root if interface.tag in INTERFACES}


@pytest.mark.parametrize("name", [n for n in native.native_models() if not MODELS[n].co_simulation_only])
def test_the_description_declares_the_derivatives_the_binary_gives(native_dir, tmp_path, name, fmi):
    """Every interface of the FMU declares them exactly when the C port gives the hook; a model
    without it refuses the call with Error and a reason, one with it answers."""
    path = native.fmu_path(native_dir, name, fmi)
    provides = "true" if name in PROVIDING else "false"
    assert all(set(flags.values()) == {provides} for flags in _description_flags(path, fmi).values())
    assert set(_description_flags(path, fmi)) == set(INTERFACES)
    model = ModelExchange(path, fmi, {}, tmp_path)
    rows, columns = derivatives.references(name, fmi)
    if name in PROVIDING:
        assert len(model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))) == len(rows)
    else:
        with pytest.raises(FMICallException) as refused:
            model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))
        assert refused.value.status == 3
        assert model.log[-1] == f"fmi{fmi}GetDirectionalDerivative is not supported by this FMU"


@pytest.mark.parametrize("name", PROVIDING)
def test_directional_derivatives_equal_central_differences_of_the_fmu(native_dir, tmp_path, name, fmi):
    """Model Exchange, at the start values and the model's dependency points, the states moved: the
    exact Jacobian against central differences of the same instance (within the differences' own
    error), its zeros where the model description declares no dependency."""
    path = native.fmu_path(native_dir, name, fmi)
    rows, columns = derivatives.layout(name)
    for n, point in enumerate(_points(name)):
        model = _at_point(path, fmi, point, tmp_path / str(n))
        jacobian = derivatives.exact(model.fmu, name, fmi)
        coarse, _ = derivatives.fmu_differences(model, name)
        differences, values = derivatives.fmu_differences(model, name, HALF_STEP)
        at = np.array(model.get(columns), dtype=float)
        rounding = np.maximum(10 * np.finfo(float).eps, _rounding(name, rows)) * np.abs(values) / HALF_STEP
        bound = derivatives.row_bounds(name, FMU_TOLERANCE, CORE_TOLERANCE)[0]
        allowed = (bound + rounding / derivatives.row_scales(jacobian, at))[:, None]  # the difference's, scaled
        truncation = TRUNCATION_SHARE * derivatives.scaled_error(coarse, differences, at)
        assert np.all(derivatives.scaled_error(jacobian, differences, at) <= allowed + truncation), point
        declared = {u.variable.name: {k.name for k in u.dependencies}
                    for u in (*model.description.outputs, *model.description.derivatives)}
        for i, row in enumerate(rows):
            moved = {columns[j] for j in np.flatnonzero(jacobian[i])}
            assert moved <= declared.get(row, set(columns)), (row, moved)
        model.close()


@pytest.mark.parametrize("name", PROVIDING)
def test_directional_derivatives_equal_the_python_cores_extrapolated_differences(native_dir, tmp_path, name, fmi):
    """Against the Python core within CORE_TOLERANCE, plus where a row's cores round above eps
    (ROUNDING, amplified by the extrapolation) or interpolate tables each computes itself (CORE_AGREEMENT)."""
    path = native.fmu_path(native_dir, name, fmi)
    spec = MODELS[name].spec
    rows, columns = derivatives.layout(name)
    for n, point in enumerate(_points(name)):
        model = _at_point(path, fmi, point, tmp_path / str(n))
        jacobian = derivatives.exact(model.fmu, name, fmi)
        values = {v.name: v.start for v in spec.variables} | point[0]
        values |= dict(zip(columns, model.get(columns)))
        reference = derivatives.core_differences(name, values, TIME)
        at = np.array([values[c] for c in columns], dtype=float)
        error = derivatives.scaled_error(jacobian, reference, at)
        outputs = derivatives.core_rows(name, values, TIME)
        rounding = derivatives.EXTRAPOLATION_ROUNDING * _rounding(name, rows) * np.abs(outputs) / derivatives.core_step(name)
        tables = CORE_AGREEMENT[name](name, values, dict(zip(rows, outputs))) if name in CORE_AGREEMENT else {}
        slopes = np.array([tables.get(row, 0.0) for row in rows]) * np.max(derivatives.scales(at), initial=1.0)
        bound = derivatives.row_bounds(name, FMU_TOLERANCE, CORE_TOLERANCE)[1]
        assert np.all(error <= (bound + (rounding + slopes) / derivatives.row_scales(jacobian, at))[:, None]), (
            point, error)
        model.close()


def test_critical_speeds_at_standstill_gives_the_derivative_for_a_growing_speed(native_dir, tmp_path, fmi):
    """At omega_in = 0, where the outputs of |omega_in| have a kink (the whirl frequencies part there), the
    derivatives for a growing omega_in: forward differences of the FMU, steps 1e-2 and 5e-3 rad/s
    extrapolated (error O(h^2), rounding 2 eps |f| / h: 5e-11 of the whirl rows' scale), within 1e-7 of the
    row's scale; the response's and the bearing force's 0 (they grow as omega_in^2)."""
    path = native.fmu_path(native_dir, "CriticalSpeeds", fmi)
    rows, columns = derivatives.layout("CriticalSpeeds")
    model = _at_point(path, fmi, ({"omega_in": 0.0}, {}), tmp_path)
    jacobian = derivatives.exact(model.fmu, "CriticalSpeeds", fmi)

    def forward(h: float) -> np.ndarray:
        model.set({"omega_in": h})
        above = np.array(model.get(rows))
        model.set({"omega_in": 0.0})
        return (above - np.array(model.get(rows))) / h

    reference = 2.0 * forward(5e-3) - forward(1e-2)
    assert np.all(derivatives.scaled_error(jacobian, reference[:, None], np.zeros(1)) <= FMU_TOLERANCE)
    assert jacobian[rows.index("whirl_forward_1"), 0] > 0.0 > jacobian[rows.index("whirl_backward_1"), 0]
    assert jacobian[rows.index("unbalance_response"), 0] == jacobian[rows.index("bearing_force_max"), 0] == 0.0
    model.close()


@pytest.mark.parametrize("name", PROVIDING)
def test_co_simulation_gives_the_model_exchange_derivatives(native_dir, tmp_path, name, fmi):
    """At the start and after 0.01 s the co-simulation instance's Jacobian is the Model Exchange
    instance's at the same time, states and inputs, bit for bit (the same map of one instant). The steps
    are the default experiment's (VehicleDriveline refuses a step over 1.04 ms)."""
    path = native.fmu_path(native_dir, name, fmi)
    spec = MODELS[name].spec
    states = [state.name for state in spec.states]
    cs = ModelExchange(path, fmi, {}, tmp_path / "cs", interface="CoSimulation")
    step, time = spec.default_experiment.step_size, 0.0
    for steps in (0, round(0.01 / step)):
        for _ in range(steps):
            cs.fmu.doStep(time, step)
            time += step
        me = ModelExchange(path, fmi, {}, tmp_path / f"me{time}")
        me.fmu.setTime(time)
        me.set_states(np.array(cs.get(states), dtype=float))
        assert np.array_equal(derivatives.exact(cs.fmu, name, fmi), derivatives.exact(me.fmu, name, fmi))
        me.close()
    cs.close()


@pytest.mark.parametrize("interface", INTERFACES)
@pytest.mark.parametrize("name", PROVIDING)
def test_the_adjoint_is_the_transpose(native_dir, tmp_path, name, interface):
    """FMI 3.0: unit seeds give the directional derivatives' Jacobian exactly, and random seeds
    v^T (J w) = (J^T v)^T w to rounding."""
    path = native.fmu_path(native_dir, name, "3")
    model = ModelExchange(path, "3", {}, tmp_path, interface=interface)
    rows, columns = derivatives.references(name, "3")
    jacobian = derivatives.exact(model.fmu, name, "3")
    assert np.array_equal(derivatives.exact(model.fmu, name, "3", adjoint=True), jacobian)
    generator = np.random.default_rng(30)
    for _ in range(3):
        v, w = generator.normal(size=len(rows)), generator.normal(size=len(columns))
        forward = v @ np.array(model.fmu.getDirectionalDerivative(rows, columns, list(w)))
        backward = np.array(model.fmu.getAdjointDerivative(rows, columns, list(v), len(columns))) @ w
        assert abs(forward - backward) <= 1e-13 * (np.abs(v) @ np.abs(jacobian) @ np.abs(w)) + 1e-300
    model.close()


def _refusal(path, fmi: str, folder, interface: str, call, point: dict | None = None) -> tuple[int, str]:
    """The status and the last message of ``call(fmu, rows, columns)`` on a fresh instance after initialisation."""
    model = ModelExchange(path, fmi, point or {}, folder, interface=interface)
    rows, columns = derivatives.references("CardanJoint", fmi)
    with pytest.raises(FMICallException) as refused:
        call(model.fmu, rows, columns)
    return refused.value.status, model.log[-1]


HOSTILE = {
    "an unknown reference": (lambda fmu, rows, columns: fmu.getDirectionalDerivative([9999], columns, [1.0] * len(columns)),
                             3, "value reference 9999 is no unknown (a Real output or a state derivative)"),
    "an input as unknown": (lambda fmu, rows, columns: fmu.getDirectionalDerivative([columns[1]], columns,
                                                                                    [1.0] * len(columns)),
                            3, "value reference 4 (beta) is no unknown (a Real output or a state derivative)"),
    "an output as known": (lambda fmu, rows, columns: fmu.getDirectionalDerivative(rows, [rows[1]], [1.0]),
                           3, "value reference 7 (phi_out) is no known (a Real input or a continuous state)"),
    "a parameter as known": (lambda fmu, rows, columns: fmu.getDirectionalDerivative(rows, [0], [1.0]),
                             3, "value reference 0 (beta_max) is no known (a Real input or a continuous state)"),
    "a NaN seed": (lambda fmu, rows, columns: fmu.getDirectionalDerivative(rows, columns, [1.0, np.nan] + [0.0] * (len(columns) - 2)),
                   3, "seed[1] = nan is not finite"),
    "an overflowing seed": (lambda fmu, rows, columns: fmu.getDirectionalDerivative(rows, columns, [1e308] * len(columns)),
                            2, "the directional derivative at t = 0.0 s overflows: the seed is too large"),
}


@pytest.mark.parametrize("interface", INTERFACES)
@pytest.mark.parametrize("case", HOSTILE)
def test_a_hostile_call_gets_a_status_and_a_reason(native_dir, tmp_path, case, interface, fmi):
    call, status, message = HOSTILE[case]
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    got = _refusal(path, fmi, tmp_path, interface, call)
    assert got == (status, f"fmi{fmi}GetDirectionalDerivative: {message}" if status == 3 else message)


@pytest.mark.parametrize("interface", INTERFACES)
def test_fmi3_sizes_that_do_not_match_are_refused(native_dir, tmp_path, interface):
    path = native.fmu_path(native_dir, "CardanJoint", "3")
    directional = _refusal(path, "3", tmp_path / "d", interface,
                           lambda fmu, rows, columns: fmu.getDirectionalDerivative(rows, columns, [1.0] * 4, 3))
    adjoint = _refusal(path, "3", tmp_path / "a", interface,
                       lambda fmu, rows, columns: fmu.getAdjointDerivative(rows, columns, [1.0] * 3, 4))
    rows, columns = derivatives.references("CardanJoint", "3")
    assert directional == (3, "fmi3GetDirectionalDerivative: nSeed, nSensitivity = 4, 3 where the knowns and "
                              f"unknowns give {len(columns)}, {len(rows)} (scalar variables only)")
    assert adjoint == (3, "fmi3GetAdjointDerivative: nSeed, nSensitivity = 3, 4 where the unknowns and knowns "
                          f"give {len(rows)}, {len(columns)} (scalar variables only)")


def test_a_point_a_step_would_refuse_is_discarded_with_its_reason(native_dir, tmp_path, fmi):
    """beta beyond beta_max, set after initialisation: Discard with the co-simulation step's words,
    in both interfaces; corrected, the derivatives are given again."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    for interface in INTERFACES:
        model = ModelExchange(path, fmi, {}, tmp_path / interface, interface=interface)
        rows, columns = derivatives.references("CardanJoint", fmi)
        model.set({"beta": 1.0})
        with pytest.raises(FMICallException) as refused:
            model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))
        assert refused.value.status == 2
        assert model.log[-1] == "input beta = 57.2958 deg must not exceed beta_max = 45 deg"
        model.set({"beta": 0.5})
        assert len(model.fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))) == len(rows)
        model.close()


def test_outside_step_mode_the_call_is_an_error(native_dir, tmp_path, fmi):
    """Before and during initialisation (the initial unknowns' derivatives are not offered): Error."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    description = read_model_description(str(path))
    log: list[str] = []
    instance = LoggedInstance(extract(str(path), unzipdir=str(tmp_path)), description, "ModelExchange", "instance",
                              log.append)
    fmu = instance.fmu
    rows, columns = derivatives.references("CardanJoint", fmi)
    for mode in ("Instantiated", "InitializationMode"):
        if mode == "InitializationMode":
            fmu.reset()
            if fmi == "3":
                fmu.enterInitializationMode(startTime=0.0)
            else:
                fmu.setupExperiment(startTime=0.0)
                fmu.enterInitializationMode()
        with pytest.raises(FMICallException) as refused:
            fmu.getDirectionalDerivative(rows, columns, [1.0] * len(columns))
        assert refused.value.status == 3
        assert log[-1] == f"fmi{fmi}GetDirectionalDerivative is not allowed in {mode}"
    fmu.freeInstance()
    instance.release()


@pytest.mark.parametrize("interface", INTERFACES)
def test_a_null_array_is_an_error(native_dir, tmp_path, interface, fmi):
    """The C call with the unknowns' references missing (NULL, one unknown named): Error, logged."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    model = ModelExchange(path, fmi, {}, tmp_path, interface=interface)
    knowns, seed, sensitivity = (c_uint * 1)(3), (c_double * 1)(1.0), (c_double * 1)()
    arguments = (None, 1, knowns, 1, seed, 1, sensitivity, 1) if fmi == "3" else (None, 1, knowns, 1, seed, sensitivity)
    with pytest.raises(FMICallException) as refused:
        getattr(model.fmu, f"fmi{fmi}GetDirectionalDerivative")(model.fmu.component, *arguments)
    assert refused.value.status == 3
    assert model.log[-1] == f"fmi{fmi}GetDirectionalDerivative: null array"


def test_vehicle_driveline_at_standstill_gives_the_derivative_for_a_growing_speed(native_dir, tmp_path, fmi):
    """At v_x = 0 the slip speed |v_x| + v_low of (V6) has a kink: d slip_dot / d v_x is the one for a
    growing v_x, (-1 - slip) / sigma_slip, the forward difference's (slip_dot is linear in v_x on each
    side: within rounding), not the backward one's (-1 + slip) / sigma_slip; a_x, smooth there, takes
    both (its drag v |v| bends by rho_air c_drag A_front h / m: 4e-10 of the row at h = 1e-6)."""
    path = native.fmu_path(native_dir, "VehicleDriveline", fmi)
    model = _at_point(path, fmi, ({}, {"v_x": 0.0, "slip_left": 0.05, "slip_right": -0.05}), tmp_path)
    rows, columns = derivatives.layout("VehicleDriveline")
    speed, h = columns.index("v_x"), 1e-6
    exact = derivatives.exact(model.fmu, "VehicleDriveline", fmi)[:, speed]
    names = ["slip_dot_left", "slip_dot_right", "a_x"]
    picked = [rows.index(name) for name in names]

    spec = MODELS["VehicleDriveline"].spec
    states = model.get_states()

    def at_speed(v: float) -> np.ndarray:
        states[[state.name for state in spec.states].index("v_x")] = v
        model.set_states(states)
        return np.array(model.get(names), dtype=float)

    centre = at_speed(0.0)
    forward, backward = (at_speed(h) - centre) / h, (centre - at_speed(-h)) / h
    sigma = spec["sigma_slip"].start
    assert exact[picked[:2]] == pytest.approx([(-1.0 - 0.05) / sigma, (-1.0 + 0.05) / sigma], rel=1e-15)
    assert exact[picked] == pytest.approx(forward, rel=1e-8)
    assert exact[picked[2]] == pytest.approx(backward[2], rel=1e-8)
    assert np.all(np.abs(exact[picked[:2]] - backward[:2]) >= 0.09 / sigma)
    model.close()


@pytest.mark.parametrize("interface", INTERFACES)
def test_the_kept_jacobian_follows_every_change_of_the_point(native_dir, tmp_path, interface, fmi):
    """The layer keeps the last Jacobian while the point is the same (a host asking column by column):
    after an input, the state or the time changes the point, the derivatives are those of a fresh
    instance there, bit for bit, and after restoring the first point's FMU state the first ones again."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    model = ModelExchange(path, fmi, {}, tmp_path / "kept", interface=interface)
    first = derivatives.exact(model.fmu, "CardanJoint", fmi)
    saved = model.fmu.getFMUState()
    time = 0.0
    changes = [("beta", lambda: model.set({"beta": 0.5}))]
    if interface == "ModelExchange":
        changes += [("state", lambda: model.set_states(model.get_states() + 0.3)),
                    ("time", lambda: model.fmu.setTime(0.2))]
    for what, change in changes:
        change()
        time = 0.2 if what == "time" else time
        moved = derivatives.exact(model.fmu, "CardanJoint", fmi)
        fresh = ModelExchange(path, fmi, {"beta": 0.5}, tmp_path / what, interface=interface)
        if interface == "ModelExchange":
            fresh.fmu.setTime(time)
            fresh.set_states(model.get_states())
        assert not np.array_equal(moved, first), what
        assert np.array_equal(moved, derivatives.exact(fresh.fmu, "CardanJoint", fmi)), what
        fresh.close()
    model.fmu.setFMUState(saved)
    assert np.array_equal(derivatives.exact(model.fmu, "CardanJoint", fmi), first)
    model.fmu.freeFMUState(saved)
    model.close()


def _refuse_the_point(model, interface: str, fmi: str) -> None:
    """A refusal at the instance's point with beta beyond beta_max: a refused step in co-simulation, refused
    derivatives in Model Exchange."""
    model.set({"beta": 1.0})
    with pytest.raises(FMICallException) as refused:
        if interface == "CoSimulation":
            model.fmu.doStep(0.0, 1e-3)
        else:
            model.derivatives()
    assert refused.value.status == 2


@pytest.mark.parametrize("interface", INTERFACES)
def test_an_earlier_refusal_does_not_refuse_the_kept_jacobian(native_dir, tmp_path, interface, fmi):
    """The kept Jacobian's point refused in between (a refused step, refused Model Exchange values) and then set
    again: the derivatives are given with OK, as before, and the refusal's messages are not logged again."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    model = ModelExchange(path, fmi, {}, tmp_path, interface=interface)
    beta = model.get(["beta"])[0]
    first = derivatives.exact(model.fmu, "CardanJoint", fmi)
    _refuse_the_point(model, interface, fmi)
    logged = len(model.log)
    model.set({"beta": beta})
    assert np.array_equal(derivatives.exact(model.fmu, "CardanJoint", fmi), first)
    assert np.array_equal(derivatives.exact(model.fmu, "CardanJoint", fmi, adjoint=fmi == "3"), first)
    assert len(model.log) == logged
    model.close()


@pytest.mark.parametrize("interface", INTERFACES)
def test_an_overflowing_seed_leaves_the_sensitivities_and_the_next_call_alone(native_dir, tmp_path, interface, fmi):
    """Seeds of 1e308 overflow the products: Discard with the reason, the sensitivities the host passed left
    as they were (the layer's promise); the next call at the same point is OK."""
    path = native.fmu_path(native_dir, "CardanJoint", fmi)
    model = ModelExchange(path, fmi, {}, tmp_path, interface=interface)
    rows, columns = derivatives.references("CardanJoint", fmi)
    first = derivatives.exact(model.fmu, "CardanJoint", fmi)
    unknowns, knowns = (c_uint * len(rows))(*rows), (c_uint * len(columns))(*columns)
    seed, sensitivity = (c_double * len(columns))(*[1e308] * len(columns)), (c_double * len(rows))(*[7.0] * len(rows))
    arguments = ((unknowns, len(rows), knowns, len(columns), seed, len(columns), sensitivity, len(rows)) if fmi == "3"
                 else (unknowns, len(rows), knowns, len(columns), seed, sensitivity))
    with pytest.raises(FMICallException) as refused:
        getattr(model.fmu, f"fmi{fmi}GetDirectionalDerivative")(model.fmu.component, *arguments)
    assert refused.value.status == 2
    assert model.log[-1] == "the directional derivative at t = 0.0 s overflows: the seed is too large"
    assert list(sensitivity) == [7.0] * len(rows)
    assert np.array_equal(derivatives.exact(model.fmu, "CardanJoint", fmi), first)
    model.close()
