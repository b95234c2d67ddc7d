"""The launch study's runs without friction (``fmu_harness.studies.launch_study``): a quick launch of
the native ``VehicleLaunch.ssp``, 140 N.m for 4 s (Gauss-Seidel at 0.8 ms, about 1 s of CPU each), with
the package's joints (``mu`` = 0.05), without friction, and without friction or bend; on the package's mounts
(their rubber default) and on the linear layout."""

from __future__ import annotations

import numpy as np
import pytest

from driveline.mounts.spec import SHARED_LAYOUT
from fmu_harness.runs import system
from fmu_harness.studies import launch_study, order_tracking

CASES = {"friction": {},
         "no friction": {f"joint_{side}": {"mu": 0.0} for side in system.SIDES},
         "no friction, straight": {**{f"joint_{side}": {"mu": 0.0} for side in system.SIDES},
                                   "mounts": {"housing_motion": 0, "beta_design_left": 0.0, "beta_design_right": 0.0}}}


LAYOUTS = ("default", SHARED_LAYOUT)
"""The package's mounts on their rubber default, and on the linear layout, whose ringing is the floor below."""


@pytest.fixture(scope="module")
def launches(fmi2_dir, native_dir) -> dict[tuple[str, str], launch_study.Launch]:
    package = system.write_ssp(system.vehicle_launch(), fmi2_dir, native_dir)
    found = {}
    for layout in LAYOUTS:
        for name, changes in CASES.items():
            if layout != "default":
                changes = changes | {"mounts": changes.get("mounts", {}) | {"layout": layout}}
            found[layout, name] = launch_study.run(package, torque=140.0, stop_time=4.0, changes=changes)
    return found


def third_order(launch: launch_study.Launch, signal: str) -> float:
    return order_tracking.third_order_peak(launch.time, launch.shaft_angle, launch.values[signal])[0]


@pytest.mark.parametrize("layout", LAYOUTS)
def test_without_friction_the_third_order_falls_to_what_straight_joints_leave(launches, layout):
    """With mu = 0 the generated axial force is 0 over the launch, and the powertrain's third-order
    pitch acceleration (the housings moving) falls to at most 5 % of the friction case: on the rubber
    default from 0.492 rad/s2 to 0.0168 (3.4 %), on the linear layout from 6.83 to 0.179 (2.6 %).
    On the linear layout that rest is no third order of the joints: with straight frictionless joints,
    which excite no order at all, it is 0.182 (the tracking window of two revolutions weighs what lies
    within one order of the third, its main lobe: the mounts ringing after the torque ramp, the drive's
    torsional oscillation through the joints' torques), so the rest lies within a factor 1.5 of that
    floor. On rubber the floor is 0.00026 (the mounts' ringing damped alike in every mode, the pitch
    modes on their stops), 65 times below the frictionless rest, which the floor no longer hides. So the
    issue's "below 1e-9 of the friction case" cannot hold for a response order-tracked over a launch."""
    for side in system.SIDES:
        assert np.all(launches[layout, "no friction"].values[f"joint_{side}.Rz_in"] == 0.0)
        assert np.abs(launches[layout, "friction"].values[f"joint_{side}.Rz_in"]).max() > 100.0
    friction, frictionless, straight = (third_order(launches[layout, name], launch_study.RESPONSE) for name in CASES)
    assert frictionless < 0.05 * friction
    if layout == SHARED_LAYOUT:
        assert straight / 1.5 < frictionless < 1.5 * straight
