"""The launch package against an independent monolithic model of the same closed loop, written from the
model pages (``support.launch_monolith``): the third-order peaks of the powertrain's lateral, yaw and pitch
accelerations and of mode 1 at the right joint's phases, with the housings held and, where the package has
it, moving with the powertrain; the model's halfshaft geometry on a moving powertrain against the project's
core (``driveline.halfshaft.geometry``), a second computation of H1-H4.

The package's mounts run the linear layout here (``transverse_fwd_powertrain``, the one the model reads), not
their rubber default: the model checks the loop's wiring, the joints' kinetics and the housings' geometry, and
its powertrain is equation (1) with viscous mounts; the rubber's snubbers and Maxwell branches are checked
against computations of their own (tests/core/test_mounts_rubber.py: the loss factor from a time-domain run,
the equilibrium against a second writing, the exact steps against solve_ivp of an independently assembled
state matrix, free decays of every mode)."""

from __future__ import annotations

import functools
import math

import numpy as np
import pytest

from driveline.halfshaft.geometry import HousingMotion, shaft_geometry
from driveline.mounts.spec import SHARED_LAYOUT
from fmu_harness.runs import system
from fmu_harness.studies import launch_study, order_tracking
from support import launch_monolith

SIGNALS = {"lateral": ("y_ddot", 1), "yaw": ("yaw_ddot", 5), "pitch": ("pitch_ddot", 4)}
FACTOR = 1.5
"""The package's third-order peaks within this factor of the monolithic model's: the model's joints are
of leading order in r/l (their generated axial force 10 to 25 % above the full model's, the page's
measurements; launch_monolith's docstring), the rest of the loop the same equations; measured 1.05 to
1.15 with the housings held, the package below the model everywhere (docs/vehicle_launch.md, "An
independent monolithic model")."""
LAUNCH = system.vehicle_launch()
MOUNTS = next(c for c in LAUNCH.components if c.model == "PowertrainMounts")
MOVING = "housing_motion" in MOUNTS.parameters
"""The package can move the joints' housings with the powertrain (``mounts.housing_motion``)."""
DRIVE_REACTION = any(c.start == ("drive", "T_reaction") for c in LAUNCH.connections)
"""The package loads the powertrain with the drive's reaction torque instead of the joints' ``T_in``."""


@pytest.fixture(scope="module")
def package(fmi2_dir, native_dir):
    return system.write_ssp(LAUNCH, fmi2_dir, native_dir)


def package_peaks(package, phase: float, moving: bool) -> dict[str, float]:
    """The package's launch (140 N.m, 4 s, Gauss-Seidel at 2e-4 s), the housings moving or held: each
    third-order peak, tracked in the left halfshaft's angle."""
    mounts = {"layout": SHARED_LAYOUT} | ({"housing_motion": int(moving)} if MOVING else {})
    changes = {"joint_right": {"phi_in_start": phase}, "mounts": mounts}
    run = launch_study.run(package, torque=140.0, stop_time=4.0, step=2e-4, changes=changes)
    accelerations = run.accelerations()
    body, found = launch_study.powertrain_modes(SHARED_LAYOUT)
    signals = {name: accelerations[:, k] for name, (_, k) in SIGNALS.items()}
    signals["mode 1"] = launch_study.modal_accelerations(body, found, accelerations)[:, 0]
    return {name: order_tracking.third_order_peak(run.time, run.shaft_angle, signal)[0]
            for name, signal in signals.items()}


@functools.cache
def monolith_peaks(phase: float, moving: bool) -> dict[str, float]:
    """The model's launch (LSODA, 20 to 60 s of CPU): each third-order peak, tracked in the left joint's angle."""
    run = launch_monolith.Launch(joints=launch_monolith.launch_joints(phase), housing_motion=moving,
                                 drive_reaction=DRIVE_REACTION).run()
    signals = {name: run[column] for name, (column, _) in SIGNALS.items()} | {"mode 1": run["mode_1"]}
    return {name: order_tracking.third_order_peak(run["time"], run["phi_in_left"], signal)[0]
            for name, signal in signals.items()}


def assert_within_factor(found: dict[str, float], expected: dict[str, float]) -> None:
    for name in expected:
        assert 1.0 / FACTOR < found[name] / expected[name] < FACTOR, (name, found[name], expected[name])


@pytest.mark.parametrize("degrees", [0.0, 60.0])
def test_with_the_housings_held_the_packages_peaks_are_the_monolithic_models(package, degrees):
    """In phase and 60 deg apart, the housings held at the design geometry: lateral, yaw, pitch and mode 1
    within :data:`FACTOR` either way."""
    phase = math.radians(degrees)
    assert_within_factor(package_peaks(package, phase, False), monolith_peaks(phase, False))


@pytest.mark.skipif(not MOVING, reason="the package's joints do not follow the powertrain (no mounts.housing_motion)")
def test_at_60_deg_the_housings_motion_cuts_the_lateral_peak_as_in_the_monolithic_model(package):
    """The issue's check: at 60 deg the package's third-order lateral peak with the housings moving at least
    2 times below the same launch with them held, and within :data:`FACTOR` of the monolithic model with the
    housings moving (measured 2026-12-07: the model 17.98 m/s2 held, 2.18 moving; the package with the
    joints following the powertrain 16.0 held, 2.07 moving)."""
    phase = math.radians(60.0)
    held, moving = (package_peaks(package, phase, flag)["lateral"] for flag in (False, True))
    expected = monolith_peaks(phase, True)["lateral"]
    assert moving < held / 2.0
    assert 1.0 / FACTOR < moving / expected < FACTOR, (moving, expected)


def test_the_housings_motion_cuts_the_monolithic_models_lateral_response():
    """The issue's measurement, in the model alone: at 60 deg the groove friction on the sliding speed
    relative to the moving housing cuts the third-order lateral peak at least 2 times (measured 8.2 times,
    17.98 to 2.18 m/s2)."""
    phase = math.radians(60.0)
    held, moving = (monolith_peaks(phase, flag)["lateral"] for flag in (False, True))
    assert moving < held / 2.0


def test_the_models_halfshaft_geometry_is_the_cores():
    """200 random poses and velocities of the powertrain (up to 5 mm, 20 mrad, 0.2 m/s, 2 rad/s) for each
    joint: the model's bend angle, plane angle, plunge and their first rates against ``shaft_geometry`` of
    the housing's motion at the joint centre, within 1e-12 (angles in rad, plunge in m; rates also within
    1e-10 of their size: a handful of operations on the same inputs)."""
    rng = np.random.default_rng(39)
    powertrain = launch_monolith.Powertrain()
    for joint in launch_monolith.launch_joints():
        for _ in range(200):
            q = np.concatenate([rng.uniform(-5e-3, 5e-3, 3), rng.uniform(-0.02, 0.02, 3)])
            q_dot = np.concatenate([rng.uniform(-0.2, 0.2, 3), rng.uniform(-2.0, 2.0, 3)])
            rotation = launch_monolith.rotation(q[3:])
            arm = rotation @ (np.array(joint.centre) - powertrain.cg)
            motion = HousingMotion(rotation @ joint.frame, powertrain.cg + q[:3] + arm,
                                   q_dot[:3] + np.cross(q_dot[3:], arm), np.zeros(3), q_dot[3:], np.zeros(3))
            core = shaft_geometry(motion, joint.wheel, joint.l)
            beta, psi, plunge, beta_dot, psi_dot, plunge_dot = launch_monolith.halfshaft(joint, powertrain.cg, q, q_dot)
            assert beta == pytest.approx(core.beta, abs=1e-12)
            assert psi == pytest.approx(core.psi, abs=1e-12)
            assert plunge == pytest.approx(core.plunge, abs=1e-12)
            assert beta_dot == pytest.approx(core.beta_dot, abs=1e-12, rel=1e-10)
            assert psi_dot == pytest.approx(core.psi_dot, abs=1e-12, rel=1e-10)
            assert plunge_dot == pytest.approx(core.plunge_dot, abs=1e-12, rel=1e-10)
