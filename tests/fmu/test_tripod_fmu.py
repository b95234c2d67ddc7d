"""The TripodCoupling FMU end to end through fmpy: description, results, bad input, state."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from fmpy.validation import validate_fmu

from driveline.tripod import closed_form, dynamics, geometry
from driveline.tripod.exact import exact_pose
from driveline.tripod.outputs import coupling_outputs
from fmu_harness.runs.runner import FmuInstance, StepRefused, simulate

R, L, M = 0.026, 0.700, 0.2
OMEGA = 2000.0 * math.pi / 30.0


def test_validates_clean(tripod_fmu):
    assert validate_fmu(str(tripod_fmu)) == []


def test_model_description_carries_units_ranges_and_structure(tripod_fmu):
    md = read_model_description(str(tripod_fmu))
    units = {u.name: u for u in md.unitDefinitions}
    assert [d.name for d in units["rad"].displayUnits] == ["deg"]
    assert [d.name for d in units["rad/s"].displayUnits] == ["rpm"]
    variables = {v.name: v for v in md.modelVariables}
    assert variables["beta"].unit == "rad" and variables["beta"].displayUnit == "deg"
    assert variables["omega_out"].displayUnit == "rpm"
    assert float(variables["beta"].max) == pytest.approx(math.radians(60.0))
    assert "eq 30" in variables["Rz_out"].description
    outputs = {v.name for v in md.modelVariables if v.causality == "output"}
    assert {u.variable.name for u in md.outputs} == outputs
    assert {u.variable.name for u in md.initialUnknowns} == outputs
    assert md.defaultExperiment.stopTime is not None
    assert md.coSimulation.canGetAndSetFMUstate and md.coSimulation.canSerializeFMUstate


def test_rates_are_declared_as_input_derivatives(fmu_path, fmi):
    """alpha_in, beta_dot, beta_ddot, psi_dot and psi_ddot are the derivatives of omega_in, beta, beta_dot, psi
    and psi_dot (FMI 3.0's derivative attribute; FMI 2.0 has it for states only). They come after every
    variable of before them, the roller tripods' parameters after them and the moving housing's inputs after
    those, so the earlier value references (positions) stay."""
    md = read_model_description(str(fmu_path("TripodCoupling", fmi)))
    variables = {v.name: v for v in md.modelVariables}
    pairs = {"alpha_in": "omega_in", "beta_dot": "beta", "beta_ddot": "beta_dot", "psi_dot": "psi",
             "psi_ddot": "psi_dot"}
    if fmi == "3":
        assert {name: variables[name].derivative.name for name in pairs} == pairs
    names = [v.name for v in md.modelVariables if v.causality != "independent"]
    last = names.index("F_plunger3")
    assert names[last + 1:] == ["beta_dot", "beta_ddot", "beta_rate", "tripod_type", "mu_roll", "roller_radius",
                                "roller_bore_radius", "trunnion_radius", "track_width", "psi", "psi_dot", "psi_ddot",
                                "plunge_dot"]
    assert [variables[n].valueReference for n in names] == sorted(variables[n].valueReference for n in names)


@pytest.mark.parametrize("kinematics", [0, 1])
@pytest.mark.parametrize("seed_reactions", [0, 1])
def test_outputs_match_the_physics_core(tripod_fmu, kinematics, seed_reactions):
    """On a linear speed ramp (omega_in and its rate alpha_in given at each communication point),
    phi_in and every output follow the ramp exactly: phi_in = phi_0 + omega t + alpha t^2 / 2."""
    beta, alpha = math.radians(35.0), 1500.0
    result = simulate(
        tripod_fmu, 0.02, 1e-4,
        inputs={"omega_in": lambda t: OMEGA + alpha * t, "beta": beta, "T_load": 250.0, "alpha_in": alpha},
        start_values={"kinematics": kinematics, "phi_in_start": 0.3, "seed_reactions": seed_reactions},
    )
    time = result["time"]
    phi, omega = 0.3 + OMEGA * time + 0.5 * alpha * time**2, OMEGA + alpha * time
    np.testing.assert_allclose(result["phi_in"], phi, rtol=1e-12)
    if kinematics:
        reference = exact_pose(phi, beta, R, L)
        phi_out, ratio = reference.phi_out, reference.speed_ratio
    else:
        phi_out = phi + closed_form.angle_deviation(phi, beta, R, L)
        ratio = closed_form.speed_ratio(phi, beta, R, L)
    np.testing.assert_allclose(result["phi_out"], phi_out, rtol=0, atol=1e-12)
    np.testing.assert_allclose(result["omega_out"], omega * ratio, rtol=1e-9)
    np.testing.assert_allclose(result["F_pin"], dynamics.pin_force(250.0, geometry.orbit_radius(beta, R), R), rtol=1e-12)
    np.testing.assert_allclose(result["rho"], geometry.orbit_radius(beta, R), rtol=1e-12)
    # every other output as the vectorised core gives it (the FMU warm-starts a scalar solver)
    core, _ = coupling_outputs(phi, np.full_like(phi, beta), omega, 250.0, R, L, M, kinematics, None, alpha, seed_reactions)
    for name, values in core.items():
        scale = np.abs(values).max()
        np.testing.assert_allclose(result[name], values, rtol=0, atol=1e-7 * scale + 1e-12, err_msg=name)
    if seed_reactions:
        seed = dynamics.reactions(phi, beta, omega, geometry.orbit_radius(beta, R), L, M)
        np.testing.assert_allclose(result["Rz_out"], seed.Rz_out, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(result["Ry_in"], seed.Ry_in, rtol=1e-9, atol=1e-12)


def test_power_balance_through_the_fmu(tripod_fmu):
    """T_in omega_in = T_load omega_spin + dKE/dt with the plungers' kinetic energy from the
    Newton closure (exact.py), for a speed that rises at alpha_in; omega_spin differs from
    omega_out by the output shaft's cone (geometric phase), about 3 omega_in (1 - cos theta)."""
    beta, T_load, alpha = math.radians(40.0), 500.0, 3000.0
    result = simulate(tripod_fmu, 0.01, 1e-4, inputs={"omega_in": lambda t: OMEGA + alpha * t, "beta": beta,
                                                      "T_load": T_load, "alpha_in": alpha}, start_values={"kinematics": 1})
    omega = OMEGA + alpha * result["time"]
    step = 2e-3  # five-point differences in phi: truncation (step z)^4 ~1e-11, round-off 1e-16 z / step^2
    travel = [exact_pose(result["phi_in"] + k * step, beta, R, L).plunger_positions for k in (-2, -1, 0, 1, 2)]
    dz = (travel[0] - 8 * travel[1] + 8 * travel[3] - travel[4]) / (12 * step)
    d2z = (-travel[0] + 16 * travel[1] - 30 * travel[2] + 16 * travel[3] - travel[4]) / (12 * step**2)
    zdot, zddot = dz * omega[:, None], d2z * omega[:, None] ** 2 + dz * alpha
    energy_rate = M * (3 * R**2 * omega * alpha + np.sum(zdot * zddot, axis=1))
    residual = result["T_in"] * omega - T_load * result["omega_spin"] - energy_rate
    assert np.abs(residual).max() < 1e-9 * (T_load * OMEGA + M * R**2 * OMEGA**3)  # measured 1e-6 W
    # the geometric phase of a cone traced three times per turn: 3 omega_in (1 - cos theta), to 2 %
    phase = 3 * omega * (1 - np.cos(result["theta"]))
    np.testing.assert_allclose(result["omega_out"] - result["omega_spin"], phase, rtol=0.03)


@pytest.mark.parametrize("kinematics", [0, 1])
def test_a_bend_change_takes_effect_at_the_communication_point(tripod_fmu, kinematics):
    """With the rates from the inputs (beta_rate = 0, none set) beta enters quasi-statically: after a
    change the outputs are those of a run started at the new beta (the default, beta_rate = 2,
    would see the jump in its samples as a spike of rate)."""
    names = ["phi_out", "Rx_in", "Ry_in", "Mx_in", "My_in", "Rz_out", "Rx_out", "Ry_out", "T_in", "F_plunger1"]
    with FmuInstance(tripod_fmu, "changed") as changed, FmuInstance(tripod_fmu, "fresh") as fresh:
        changed.initialize({"kinematics": kinematics, "beta": 0.2, "beta_rate": 0})
        changed.run(0.005, 1e-3)
        changed.set({"beta": 0.5})
        changed.step(1e-3)
        fresh.initialize({"kinematics": kinematics, "beta": 0.5, "phi_in_start": OMEGA * 0.005, "beta_rate": 0})
        fresh.time = 0.005
        fresh.step(1e-3)
        np.testing.assert_allclose(changed.get(names), fresh.get(names), rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("kinematics", [0, 1])
def test_omega_out_is_the_derivative_of_phi_out(tripod_fmu, kinematics):
    step = 1e-5
    result = simulate(tripod_fmu, 0.01, step, inputs={"beta": math.radians(40.0)}, start_values={"kinematics": kinematics})
    numerical = (result["phi_out"][2:] - result["phi_out"][:-2]) / (2 * step)
    amplitude = closed_form.deviation_amplitude(math.radians(40.0), R, L)
    # central differences: truncation step^2/6 * 27 A omega^3, round-off eps * phi / step
    bound = 1.5 * step**2 / 6 * 27 * amplitude * OMEGA**3 + 1e-15 * 3 / step
    assert np.abs(numerical - result["omega_out"][1:-1]).max() < bound


@pytest.mark.parametrize("kinematics", [0, 1])
def test_results_do_not_depend_on_the_step_size(tripod_fmu, kinematics):
    runs = [
        simulate(tripod_fmu, 0.02, step, inputs={"beta": 0.6}, start_values={"kinematics": kinematics})
        for step in (1e-3, 1e-4)
    ]
    coarse, fine = runs[0], runs[1][::10]
    np.testing.assert_allclose(coarse["time"], fine["time"], atol=1e-12)
    # phi_in is integrated exactly (omega held), so only summation round-off differs
    np.testing.assert_allclose(coarse["phi_out"], fine["phi_out"], rtol=0, atol=1e-12)


def test_seed_claims_through_the_fmu(tripod_fmu):
    period = 2 * math.pi / OMEGA
    steps = 720
    result = simulate(tripod_fmu, period, period / steps, inputs={"beta": math.radians(30.0)},
                      start_values={"seed_reactions": 1})[:-1]
    assert np.abs(result["delta_phi"]).max() < 10 * math.pi / (180 * 60)  # below 10 arcmin
    spectrum = {name: np.abs(np.fft.rfft(result[name])) for name in ("Rz_out", "Rx_in", "Ry_in", "delta_phi")}
    assert np.argmax(spectrum["Rz_out"]) == 3
    assert np.argmax(spectrum["Rx_in"]) == 3
    assert np.argmax(spectrum["Ry_in"]) == 6
    assert np.argmax(spectrum["delta_phi"]) == 3
    straight = simulate(tripod_fmu, period, period / 36, inputs={"beta": 0.0}, start_values={"seed_reactions": 1})
    for name in ("delta_phi", "Rz_out", "Rx_in", "Ry_in", "a_plunger_sum"):
        assert np.abs(straight[name]).max() == 0.0


@pytest.mark.parametrize("kinematics", [0, 1])
def test_reactions_excite_the_third_order_and_carry_the_load(tripod_fmu, kinematics):
    """The force balance (default) against the seed: 3rd order everywhere (not 6th for R_y'),
    a mean side force T tan(beta/2)/l at both bearings, nothing without bend but the torque."""
    period = 2 * math.pi / OMEGA
    result = simulate(tripod_fmu, period, period / 360, inputs={"beta": math.radians(45.0), "T_load": 500.0},
                      start_values={"kinematics": kinematics})[:-1]
    if kinematics:
        for name in ("Rz_out", "Rx_in", "Ry_in", "Rx_out", "Ry_out", "Mx_in", "My_in"):
            assert np.argmax(np.abs(np.fft.rfft(result[name]))[1:]) + 1 == 3, name
    side = 500.0 * math.tan(math.radians(22.5)) / L
    assert np.mean(result["Ry_in"]) == pytest.approx(-side, rel=1e-3)
    assert np.mean(result["Ry_out"]) == pytest.approx(side, rel=1e-3)
    straight = simulate(tripod_fmu, period, period / 36, inputs={"beta": 0.0, "T_load": 500.0},
                        start_values={"kinematics": kinematics})
    for name in ("Rz_out", "Rx_in", "Ry_in", "Rx_out", "Ry_out", "Mx_in", "My_in", "a_plunger_sum"):
        assert np.abs(straight[name]).max() < 1e-9, name  # round-off of the 250 N plunger forces
    np.testing.assert_allclose(straight["T_in"], 500.0, rtol=1e-12)


@pytest.mark.parametrize("omega", [-150.0, 0.0])
def test_reverse_rotation_and_standstill(tripod_fmu, omega):
    result = simulate(tripod_fmu, 0.01, 1e-3, inputs={"omega_in": omega, "T_load": 80.0}, start_values={"kinematics": 1})
    np.testing.assert_allclose(result["phi_in"], omega * result["time"], atol=1e-12)
    assert np.all(np.isfinite(result["T_in"]))
    assert np.all(np.abs(result["T_in"] - 80.0) < 80.0 * 0.02)


BAD_INPUTS = [
    ({"beta": math.radians(50.0)}, "beta_max"),
    ({"beta": -0.1}, "beta"),
    ({"beta": math.nan}, "beta"),
    ({"omega_in": math.inf}, "omega_in"),
    ({"T_load": -math.inf}, "T_load"),
    ({"alpha_in": math.nan}, "alpha_in"),
    ({"omega_in": math.nan}, "omega_in"),
]
BAD_PARAMETERS = [
    ({"r": 0.0}, "r"),
    ({"r": -0.01}, "r"),
    ({"l": 0.02}, "l"),
    ({"m_plunger": -1.0}, "m_plunger"),
    ({"beta_max": math.radians(85.0)}, "beta_max"),
    ({"kinematics": 3}, "kinematics"),
    ({"seed_reactions": 2}, "seed_reactions"),
    ({"phi_in_start": math.nan}, "phi_in_start"),
]


@pytest.mark.parametrize("values, name", BAD_INPUTS)
def test_bad_input_is_refused_with_a_reason_and_the_run_can_go_on(tripod_fmu, values, name):
    with FmuInstance(tripod_fmu) as fmu:
        fmu.initialize({"beta": 0.3})
        fmu.step(1e-3)
        before = fmu.get(["phi_in", "phi_out"])
        fmu.set(values)
        with pytest.raises(StepRefused) as refused:
            fmu.step(1e-3)
        assert refused.value.status == "Discard"
        assert any(name in message for message in refused.value.messages)
        assert fmu.get(["phi_in", "phi_out"]) == before  # the refused step left no trace
        fmu.set({"beta": 0.3, "omega_in": OMEGA, "T_load": 100.0, "alpha_in": 0.0})
        fmu.step(1e-3)
        assert fmu.get(["phi_in"])[0] == pytest.approx(2 * OMEGA * 1e-3, rel=1e-12)


@pytest.mark.parametrize("values, name", BAD_PARAMETERS)
def test_non_physical_parameter_is_refused(tripod_fmu, values, name):
    with pytest.raises(StepRefused) as refused:
        simulate(tripod_fmu, 0.01, 1e-3, start_values=values)
    assert any(name in message for message in refused.value.messages)


@pytest.mark.parametrize("step", [0.0, -1e-3, math.nan])
def test_bad_step_size_is_refused(tripod_fmu, step):
    with FmuInstance(tripod_fmu) as fmu:
        fmu.initialize()
        with pytest.raises(StepRefused) as refused:
            fmu.step(step)
        assert "step size" in refused.value.messages[0]


def test_what_plain_simulate_fmu_sees_of_a_refused_step(tripod_fmu):
    """fmpy's simulate_fmu treats pythonfmu's fmi2Discard as an early end: the run stops short.
    Our harness raises instead (documented in docs/hosting.md)."""
    signal = np.array([(0.0, 0.3), (0.005, 1.2)], dtype=[("time", float), ("beta", float)])
    result = simulate_fmu(str(tripod_fmu), stop_time=0.01, step_size=1e-3, output_interval=1e-3, input=signal)
    assert result["time"][-1] < 0.01


def test_instances_are_independent_and_state_round_trips(tripod_fmu):
    with FmuInstance(tripod_fmu, "a") as a, FmuInstance(tripod_fmu, "b") as b:
        a.initialize({"kinematics": 1, "beta": 0.5})
        b.initialize({"kinematics": 0, "beta": 0.2, "omega_in": -50.0})
        for _ in range(5):
            a.step(1e-3)
            b.step(1e-3)
        state = a.fmu.getFMUstate()
        serialized = a.fmu.serializeFMUstate(state)
        reference = a.run(0.02, 1e-3, outputs=["phi_out", "Rz_out", "theta"])
        a.fmu.setFMUstate(a.fmu.deSerializeFMUstate(serialized))
        a.time = 0.005
        again = a.run(0.02, 1e-3, outputs=["phi_out", "Rz_out", "theta"])
        assert reference.tobytes() == again.tobytes()  # bit-identical continuation
        assert b.get(["phi_in"])[0] == pytest.approx(-50.0 * 0.005)
        a.fmu.freeFMUstate(state)
        a.reset()
        a.initialize({"kinematics": 1, "beta": 0.5})
        a.run(0.005, 1e-3)
        assert a.run(0.02, 1e-3, outputs=["phi_out", "Rz_out", "theta"]).tobytes() == reference.tobytes()
