"""The launch study's runs without friction (``fmu_harness.studies.launch_study``): a quick launch of
the native ``VehicleLaunch.ssp``, 140 N.m for 4 s (Gauss-Seidel at 0.8 ms, 1 s of CPU for the three), with
the package's joints (``mu`` = 0.05), without friction, and without friction or bend."""

from __future__ import annotations

import numpy as np
import pytest

from fmu_harness.runs import system
from fmu_harness.studies import launch_study, order_tracking

CASES = {"friction": {},
         "no friction": {f"joint_{side}": {"mu": 0.0} for side in system.SIDES},
         "no friction, straight": {**{f"joint_{side}": {"mu": 0.0} for side in system.SIDES},
                                   "mounts": {"housing_motion": 0, "beta_design_left": 0.0, "beta_design_right": 0.0}}}


@pytest.fixture(scope="module")
def launches(fmi2_dir, native_dir) -> dict[str, launch_study.Launch]:
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    return {name: launch_study.run(package, torque=140.0, stop_time=4.0, changes=changes)
            for name, changes in CASES.items()}


def third_order(launch: launch_study.Launch, signal: str) -> float:
    return order_tracking.third_order_peak(launch.time, launch.shaft_angle, launch.values[signal])[0]


def test_without_friction_the_third_order_falls_to_what_straight_joints_leave(launches):
    """With mu = 0 the generated axial force is 0 over the launch, and the powertrain's third-order
    pitch acceleration falls from 9.57 rad/s2 to 0.237 (2.5 %). That rest is no third order of the
    joints: with straight frictionless joints, which excite no order at all, it is 0.198 (the
    tracking window of two revolutions weighs what lies within one order of the third, its main
    lobe: the mounts ringing after the torque ramp, the drive's torsional oscillation through the
    joints' torques). So the
    issue's "below 1e-9 of the friction case" cannot hold for a response order-tracked over a launch;
    what holds: at most 5 % of the friction case and within a factor 1.5 of the straight joints' floor."""
    for side in system.SIDES:
        assert np.all(launches["no friction"].values[f"joint_{side}.Rz_in"] == 0.0)
        assert np.abs(launches["friction"].values[f"joint_{side}.Rz_in"]).max() > 100.0
    friction, frictionless, straight = (third_order(launches[name], launch_study.RESPONSE) for name in CASES)
    assert frictionless < 0.05 * friction
    assert straight / 1.5 < frictionless < 1.5 * straight
