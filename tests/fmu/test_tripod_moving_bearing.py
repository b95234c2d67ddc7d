"""TripodCoupling on a moving suspension, through the real FMUs, against the multibody model
(tripod_multibody.py beside this file) whose output bearing moves with beta(t): the bend ramp
5 -> 30 deg in 0.1 s at 2000 rpm (peak rate 8.7 rad/s) and the speed ramp 1000 -> 3000 rpm in
0.5 s at 25 deg, host step 2e-5 s, inputs set at the start of each step.

The windows are the first half of the bend ramp (rate and acceleration through their peaks) and
the first 0.05 s of the speed ramp; the errors over the whole ramps are in docs/tripod_coupling.md.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from support import tripod_multibody
from fmu_harness.packaging import native
from fmu_harness.runs.runner import FmuInstance

RPM = math.pi / 30.0
FORCES = ("Rx_in", "Ry_in", "Rx_out", "Ry_out", "Rz_out", "F_arm1", "F_arm2", "F_arm3",
          "F_plunger1", "F_plunger2", "F_plunger3")
MOMENTS = ("Mx_in", "My_in", "T_in")
BEND = tripod_multibody.Case(math.radians(5.0), 0.0, 2000 * RPM, beta_end=math.radians(30.0), ramp_time=0.1)
SPEED = tripod_multibody.Case(math.radians(25.0), 0.0, 1000 * RPM, omega_end=3000 * RPM, ramp_time=0.5)
SPEED_RATE = (SPEED.omega_end - SPEED.omega) / SPEED.ramp_time
#: samples after the speed ramp's start where the multibody integrator still answers the jump of
#: the prescribed acceleration (an oscillation from 8.7 N decaying below 2e-3 N within 1 ms)
SETTLING = 50


@functools.lru_cache(maxsize=None)
def multibody(case: tripod_multibody.Case) -> tripod_multibody.Result:
    """1500 steps per turn at 2000 rpm, 3000 at 1000 rpm: a 2e-5 s step, the host's."""
    if case is BEND:
        return tripod_multibody.simulate(case, 1500, window=0.05)
    return tripod_multibody.simulate(case, 3000, window=0.05)


def host_run(path, reference: tripod_multibody.Result, case: tripod_multibody.Case, bend_rates: str,
             derivatives: bool = False) -> np.ndarray:
    """The FMU (exact mode) over the reference's samples; ``bend_rates``: "inputs" (beta_dot and
    beta_ddot set), "samples" (beta_rate = 1, beta alone), "none" (beta alone, quasi-static).
    ``derivatives``: the rates through fmi2SetRealInputDerivatives instead of the inputs."""
    start = reference.time[0]
    names = ("phi_in",) + FORCES + MOMENTS
    rows = []
    with FmuInstance(path) as fmu:

        def inputs(t: float) -> None:
            beta, rate, acceleration = case.bend(t, start)
            ramp = case.omega_end is not None and t - start < case.ramp_time - 1e-12
            omega = case.omega + (SPEED_RATE * (t - start) if case.omega_end is not None else 0.0)
            alpha = SPEED_RATE if ramp else 0.0
            fmu.set({"beta": beta, "omega_in": omega})
            if derivatives:
                refs = [fmu.variables[name].valueReference for name in ("beta", "beta", "omega_in")]
                fmu.fmu.setRealInputDerivatives(refs, [1, 2, 1], [rate, acceleration, alpha])
            else:
                fmu.set({"alpha_in": alpha, **({"beta_dot": rate, "beta_ddot": acceleration}
                                               if bend_rates == "inputs" else {})})

        fmu.set({"kinematics": 1, "phi_in_start": reference.phi_in[0], "T_load": case.T_load,
                 "beta_rate": int(bend_rates == "samples")})
        inputs(start)
        fmu.initialize({}, start)
        rows.append(fmu.get(names))
        for t, after in zip(reference.time[:-1], reference.time[1:]):
            inputs(t)
            fmu.step(after - t)
            rows.append(fmu.get(names))
    return {name: np.array(column) for name, column in zip(names, np.array(rows).T)}


def errors(result: dict, reference: tripod_multibody.Result, skip: int = 0) -> tuple[float, float]:
    """Largest force [N] and moment [N.m] differences."""
    np.testing.assert_allclose(result["phi_in"], reference.phi_in, rtol=0, atol=1e-9)
    largest = [max(np.abs(result[n][skip:] - reference.values[n][skip:]).max() for n in names)
               for names in (FORCES, MOMENTS)]
    return largest[0], largest[1]


@pytest.mark.parametrize("bend_rates, bound", [("inputs", (0.02, 0.002)), ("samples", (0.05, 0.005))])
def test_a_bend_ramp_matches_the_moving_bearing_model(tripod_fmu, bend_rates, bound):
    """The issue's targets are 0.5 N / 0.05 N.m with the rates given, 3 N from samples alone;
    measured over the whole ramp 2.7e-3 N / 5.1e-4 N.m given (the multibody integrator's own error
    is of that size: 1e-3 N at constant bend) and 4.5e-3 N / 5.1e-4 N.m from samples."""
    reference = multibody(BEND)
    force, moment = errors(host_run(tripod_fmu, reference, BEND, bend_rates), reference)
    assert force < bound[0] and moment < bound[1]


def test_without_the_bend_rates_the_plungers_miss_the_coriolis_force(tripod_fmu):
    """Quasi-static in beta (no rates): F_plunger is off by 2 m r sec^2(beta) beta_dot omega,
    20.5-21.1 N at the ramp's middle (the issue's measurement), the arm forces by 0.8 N."""
    reference = multibody(BEND)
    force, _ = errors(host_run(tripod_fmu, reference, BEND, "none"), reference)
    assert 19.0 < force < 23.0


def test_a_speed_ramp_with_alpha_in_matches_the_multibody_model(tripod_fmu):
    """phi_in advances by omega h + alpha h^2 / 2 and the outputs use omega + alpha h: target
    0.02 N; measured 2e-3 N after the multibody's settling (the phase of a held speed fell
    behind by h alpha t / 2, 0.5 N at the end of the full ramp)."""
    reference = multibody(SPEED)
    force, moment = errors(host_run(tripod_fmu, reference, SPEED, "none"), reference, SETTLING)
    assert force < 0.01 and moment < 0.002


def test_native_fmi2_input_derivatives_give_the_rates(native_dir):
    """The native FMI 2.0 FMU (canInterpolateInputs) takes beta's first and second derivatives
    and omega_in's first from fmi2SetRealInputDerivatives: the bend ramp as with the inputs."""
    reference = multibody(BEND)
    path = native.fmu_path(native_dir, "TripodCoupling", "2")
    through_derivatives = host_run(path, reference, BEND, "none", derivatives=True)
    through_inputs = host_run(path, reference, BEND, "inputs")
    for name in FORCES + MOMENTS:
        np.testing.assert_array_equal(through_derivatives[name], through_inputs[name], err_msg=name)
    force, moment = errors(through_derivatives, reference)
    assert force < 0.02 and moment < 0.002
