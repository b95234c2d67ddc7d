"""The roller tripods through the TripodCoupling FMUs (tripod_type 1 and 2): outputs as the core gives
them, the generated axial force against the plain tripod's, the plain tripod untouched by the rollers'
parameters, and a roller geometry that cannot assemble refused at initialisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.tripod.outputs import coupling_outputs
from driveline.tripod.spec import DOUBLE_ROLLER, EXACT, ROLLING_RESISTANCE, SINGLE_ROLLER
from fmu_harness.runs.runner import StepRefused, simulate

R, L, M = 0.026, 0.700, 0.2
OMEGA = 2000.0 * math.pi / 30.0
TURN = 2.0 * math.pi / OMEGA
SAMPLES = 60  # per turn: the third order is resolved exactly (no aliasing below the 29th)
FRICTION = {"kinematics": EXACT, "mu": 0.05}


def one_turn(path, tripod_type, beta_deg, T_load=300.0, **start_values):
    return simulate(path, TURN, TURN / SAMPLES, inputs={"beta": math.radians(beta_deg), "T_load": T_load},
                    start_values={**FRICTION, "tripod_type": tripod_type, **start_values})


def third_order(values):
    return 2.0 * np.abs(np.fft.rfft(values[1:]))[3] / SAMPLES  # the turn's samples after the start


@pytest.mark.parametrize("tripod_type", [SINGLE_ROLLER, DOUBLE_ROLLER])
def test_outputs_match_the_core(fmu_path, fmi, tripod_type):
    """Every output of a turn as the vectorised core gives it (the FMU warm-starts a scalar solver:
    within 1e-7 of each output's largest value; a_plunger_sum, three plunger accelerations cancelling
    to 1e-9 of their size, of theirs)."""
    result = one_turn(fmu_path("TripodCoupling", fmi), tripod_type, 8.0)
    phi = result["phi_in"]
    core, _ = coupling_outputs(phi, np.full_like(phi, math.radians(8.0)), OMEGA, 300.0, R, L, M, EXACT, mu=0.05,
                               tripod_type=tripod_type, mu_roll=ROLLING_RESISTANCE, roller_radius=0.0165,
                               roller_bore_radius=0.0115)
    for name, values in core.items():
        scale = np.abs(core["F_plunger1"]).max() / M if name == "a_plunger_sum" else np.abs(values).max()
        np.testing.assert_allclose(result[name], values, rtol=0, atol=1e-7 * scale + 1e-12, err_msg=name)


def test_generated_axial_force_below_the_plain_tripods(fmu_path):
    """At 300 N.m, mu = 0.05 and the default mu_roll, read through the FMU: both roller tripods' third-order
    generated axial force lies below the plain tripod's at 4, 8 and 12 deg and grows from 4 to 12 deg (the
    single roller's skew, the double roller's needles, docs/tripod_coupling.md)."""
    path = fmu_path("TripodCoupling", "2")
    amplitude = {(t, deg): third_order(one_turn(path, t, deg)["Rz_in"])
                 for t in (0, SINGLE_ROLLER, DOUBLE_ROLLER) for deg in (4.0, 8.0, 12.0)}
    for roller in (SINGLE_ROLLER, DOUBLE_ROLLER):
        for deg in (4.0, 8.0, 12.0):
            assert amplitude[roller, deg] < amplitude[0, deg]
        assert amplitude[roller, 4.0] < amplitude[roller, 8.0] < amplitude[roller, 12.0]


def test_the_rollers_parameters_leave_the_plain_tripod_bit_for_bit(fmu_path, fmi):
    path = fmu_path("TripodCoupling", fmi)
    plain = one_turn(path, 0, 12.0)
    other = one_turn(path, 0, 12.0, mu_roll=0.01, roller_radius=0.02, roller_bore_radius=0.012,
                     trunnion_radius=0.01, track_width=0.05)
    for name in plain.dtype.names:
        assert np.array_equal(plain[name], other[name]), name


@pytest.mark.parametrize("values, name", [
    ({"roller_bore_radius": 0.017}, "roller_bore_radius"),  # the bore outside the roller
    ({"trunnion_radius": 0.012}, "trunnion_radius"),  # the trunnion past the roller's bore
    ({"track_width": 0.032}, "track_width"),  # the roller wider than its track
    ({"roller_radius": -0.01}, "roller_radius"),
    ({"mu_roll": -0.001}, "mu_roll"),
    ({"kinematics": 0, "mu": 0.0}, "mu_roll"),  # rolling resistance needs the exact kinematics
])
def test_a_roller_geometry_that_cannot_assemble_is_refused(fmu_path, fmi, values, name):
    with pytest.raises(StepRefused) as refused:
        simulate(fmu_path("TripodCoupling", fmi), 1e-3, 1e-3,
                 start_values={**FRICTION, "tripod_type": SINGLE_ROLLER, **values})
    lines = [message for message in refused.value.messages if name in message]
    assert lines and all("\n" not in line for line in lines), refused.value.messages
