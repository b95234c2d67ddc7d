"""TripodCoupling in a moving housing through the real FMUs, both families and FMI versions
(docs/tripod_coupling.md, "The moving housing"): the bend plane turning with an acceleration and the spider
plunging, every tripod type with friction, against the core at the same instants; a constant bend plane
against the run at the shifted start angle."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.tripod.outputs import coupling_outputs
from driveline.tripod.spec import CLOSED_FORM, DOUBLE_ROLLER, EXACT, PLAIN_TRIPOD, SINGLE_ROLLER
from fmu_harness.runs.runner import simulate

R, L, M, OMEGA, ALPHA, BETA = 0.026, 0.7, 0.2, 40.0, 300.0, math.radians(20.0)
PSI, PSI_DOT, PSI_DDOT, PLUNGE_DOT = 0.5, 6.0, -80.0, -0.015
ROLLERS = {"mu_roll": 0.0025, "roller_radius": 0.0165, "roller_bore_radius": 0.0115}
TERMS = {"a_plunger_sum": "F_plunger1", "Rz_out": "F_arm1"}  # sums of large terms that cancel, and one term


def _housing(t: float) -> dict:
    """The bend plane's angle and rates along a quadratic in time (what a step carries over exactly)."""
    return {"psi": PSI + PSI_DOT * t + 0.5 * PSI_DDOT * t * t, "psi_dot": PSI_DOT + PSI_DDOT * t, "psi_ddot": PSI_DDOT}


@pytest.mark.parametrize("kinematics, tripod_type", [(CLOSED_FORM, PLAIN_TRIPOD), (EXACT, PLAIN_TRIPOD),
                                                     (EXACT, SINGLE_ROLLER), (EXACT, DOUBLE_ROLLER)])
def test_a_turning_bend_plane_and_a_plunging_spider_are_the_cores(family, fmi, kinematics, tripod_type):
    """Inputs set at each communication point (the speed's and the plane's rates with them), 200 steps of
    1e-4 s; every output at the step's end equals the vectorised core's at the same phi_in, psi and rates:
    within 1e-9 of each output's largest magnitude (the FMU's exact solver is warm-started and scalar,
    the core's vectorised, both converged to rounding; the native family within its own 1e-12 on top)."""
    inputs = {"omega_in": lambda t: OMEGA + ALPHA * t, "alpha_in": ALPHA, "beta": BETA, "T_load": 150.0,
              "plunge_dot": PLUNGE_DOT, **{name: (lambda t, n=name: _housing(t)[n]) for name in _housing(0.0)}}
    mu = 0.05 if kinematics == EXACT else 0.0
    start = {"kinematics": kinematics, "tripod_type": tripod_type, "mu": mu, "phi_in_start": 0.3, **ROLLERS}
    result = simulate(family.path("TripodCoupling", fmi), 0.02, 1e-4, inputs=inputs, start_values=start)
    time = result["time"]
    housing = _housing(time)
    core, _ = coupling_outputs(result["phi_in"], np.full_like(time, BETA), OMEGA + ALPHA * time, 150.0, R, L, M,
                               kinematics, None, ALPHA, 0, mu, 1e-3, 0.0, 0.0, tripod_type, ROLLERS["mu_roll"],
                               ROLLERS["roller_radius"], housing["psi"], housing["psi_dot"], PSI_DDOT,
                               np.full_like(time, PLUNGE_DOT), ROLLERS["roller_bore_radius"])
    for name, values in core.items():
        scale = np.abs(values).max()
        np.testing.assert_allclose(result[name], values, rtol=0, atol=1e-9 * scale + 1e-12, err_msg=name)
    # the housing's motion shows: the plane turns by 0.1 rad over the run, the groove friction takes the plunge
    assert np.ptp(result["phi_out"] - result["phi_in"]) > 0.0 and abs(housing["psi"][-1] - PSI) > 0.1


@pytest.mark.parametrize("kinematics", [CLOSED_FORM, EXACT])
def test_a_constant_bend_plane_is_the_run_from_the_shifted_start_angle(family, fmi, kinematics):
    """psi held at 1.2 rad: phi_out is the run from phi_in_start - psi plus psi, the input bearing's force
    and moment that run's turned by psi, every other output the same (within rounding: the two runs' phi_in
    are sums rounded differently, up to half an ulp of 2 rad per step, 2.2e-14 rad over the 100 steps: the
    angles within 1e-13 rad, every other output within 1e-12 of its largest magnitude, or of its terms' where
    they cancel: the plungers' accelerations in their sum, the arm forces in the output bearing's axial one)."""
    psi, mu = 1.2, (0.05 if kinematics == EXACT else 0.0)
    common = {"kinematics": kinematics, "mu": mu}
    inputs = {"omega_in": OMEGA, "beta": BETA, "T_load": 150.0}
    path = family.path("TripodCoupling", fmi)
    moved = simulate(path, 0.01, 1e-4, inputs={**inputs, "psi": psi}, start_values={**common, "phi_in_start": 0.3})
    today = simulate(path, 0.01, 1e-4, inputs=inputs, start_values={**common, "phi_in_start": 0.3 - psi})
    c, s = math.cos(psi), math.sin(psi)
    expected = {"phi_out": today["phi_out"] + psi, "Rx_in": c * today["Rx_in"] - s * today["Ry_in"],
                "Ry_in": s * today["Rx_in"] + c * today["Ry_in"], "Mx_in": c * today["Mx_in"] - s * today["My_in"],
                "My_in": s * today["Mx_in"] + c * today["My_in"]}
    for name in moved.dtype.names:
        if name in ("time", "phi_in"):
            continue
        reference = expected.get(name, today[name])
        scale = max(np.abs(reference).max(), np.abs(today[TERMS[name]]).max() / (M if name == "a_plunger_sum" else 1.0) if name in TERMS else 0.0)
        bound = 1e-13 if name in ("phi_out", "delta_phi") else 1e-12 * scale + 1e-15
        np.testing.assert_allclose(moved[name], reference, rtol=0, atol=bound, err_msg=name)
