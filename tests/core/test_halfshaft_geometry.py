"""The halfshaft's geometry from the housing's motion (driveline/halfshaft/geometry.py): closed forms for a
pure translation and a pure rotation of the housing, random 6-DOF poses against a direct vector
computation (the spider's position found as a root along the housing's axis), and the rates against
central differences of a smooth motion."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.spatial.transform import Rotation

from driveline.halfshaft.geometry import GeometryError, HousingMotion, design_wheel, shaft_geometry

# The launch's left joint: housing axis +y, X' up, bend 8 deg on a 0.45 m shaft (PowertrainMounts' defaults)
FRAME = np.column_stack([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
CENTRE = np.array([0.0, 0.22, 0.0])
LENGTH, BETA = 0.45, math.radians(8.0)
WHEEL = design_wheel(FRAME, CENTRE, LENGTH, BETA)
# Angles and lengths of order one in radians and 0.5 m, computed through a few square roots and
# arctangents: rounding stays within 1e-15 of them; the direct computation's root is found to 1e-15 m
EXACT = 1e-12


def at(frame=FRAME, position=CENTRE):
    return shaft_geometry(HousingMotion.at_rest(frame, position), WHEEL, LENGTH)


def test_the_design_position_gives_the_design_bend_in_the_vertical_plane():
    geometry = at()
    assert geometry.beta == pytest.approx(BETA, abs=EXACT)
    assert geometry.psi == pytest.approx(0.0, abs=EXACT) and geometry.plunge == pytest.approx(0.0, abs=EXACT)


@pytest.mark.parametrize("d", [-0.004, 0.0015, 0.02])
def test_a_translation_along_the_axis_is_plunge_alone(d):
    geometry = at(position=CENTRE + d * FRAME[:, 2])
    assert geometry.plunge == pytest.approx(-d, abs=EXACT)
    assert geometry.beta == pytest.approx(BETA, abs=EXACT) and geometry.psi == pytest.approx(0.0, abs=EXACT)


@pytest.mark.parametrize("d", [-0.01, 0.003, 0.03])
def test_a_translation_across_the_bend_plane_turns_the_plane(d):
    """Along Y' by d: the wheel centre lies at (-L sin beta0, -d) across the axis, so tan psi = d / (L sin
    beta0), sin beta = sqrt((L sin beta0)^2 + d^2) / L, and the plunge closes the length."""
    geometry = at(position=CENTRE + d * FRAME[:, 1])
    rho0 = LENGTH * math.sin(BETA)
    rho = math.hypot(rho0, d)
    assert geometry.psi == pytest.approx(math.atan2(d, rho0), abs=EXACT)
    assert geometry.beta == pytest.approx(math.asin(rho / LENGTH), abs=EXACT)
    assert geometry.plunge == pytest.approx(LENGTH * math.cos(BETA) - math.sqrt(LENGTH**2 - rho**2), abs=EXACT)


@pytest.mark.parametrize("theta", [-0.3, 0.01, 1.2])
def test_a_rotation_about_the_axis_turns_the_plane_back(theta):
    frame = Rotation.from_rotvec(theta * FRAME[:, 2]).as_matrix() @ FRAME
    geometry = at(frame=frame)
    assert geometry.psi == pytest.approx(-theta, abs=EXACT)
    assert geometry.beta == pytest.approx(BETA, abs=EXACT) and geometry.plunge == pytest.approx(0.0, abs=EXACT)


@pytest.mark.parametrize("theta", [-0.05, 0.02, 0.1])
def test_a_rotation_in_the_bend_plane_about_the_centre_adds_to_the_bend(theta):
    """About Y' through the joint centre (the spider's position at plunge 0): the centre stays at distance
    L from the wheel, so the plunge stays 0 and the housing's axis turns by theta in the bend plane; a
    positive turn about Y' takes Z' towards X', away from the wheel (which lies towards -X')."""
    frame = Rotation.from_rotvec(theta * FRAME[:, 1]).as_matrix() @ FRAME
    geometry = at(frame=frame)
    assert geometry.beta == pytest.approx(BETA + theta, abs=EXACT)
    assert geometry.plunge == pytest.approx(0.0, abs=EXACT) and geometry.psi == pytest.approx(0.0, abs=EXACT)


def direct(frame, position):
    """Bend, plane angle and plunge as vectors: the spider's centre the point of the housing's axis at the
    shaft's length from the wheel centre (the root nearer the wheel), the shaft from it to the wheel."""
    axis = frame[:, 2]
    plunge = brentq(lambda p: float(np.linalg.norm(WHEEL - position - p * axis)) - LENGTH,
                    float((WHEEL - position) @ axis) - LENGTH, float((WHEEL - position) @ axis), xtol=1e-16, rtol=1e-15)
    shaft = WHEEL - position - plunge * axis
    beta = math.atan2(float(np.linalg.norm(np.cross(axis, shaft))), float(shaft @ axis))
    return beta, math.atan2(-float(shaft @ frame[:, 1]), -float(shaft @ frame[:, 0])), plunge


def test_random_poses_against_the_direct_vector_computation():
    """500 poses of the powertrain: rotations up to 0.1 rad about random axes through a point 0.3 m away,
    translations up to 20 mm."""
    rng = np.random.default_rng(39)
    centre_of_gravity = np.array([0.05, -0.1, 0.2])
    for _ in range(500):
        rotation = Rotation.from_rotvec(rng.uniform(-0.1, 0.1, 3)).as_matrix()
        position = centre_of_gravity + rotation @ (CENTRE - centre_of_gravity) + rng.uniform(-0.02, 0.02, 3)
        frame = rotation @ FRAME
        geometry = at(frame, position)
        beta, psi, plunge = direct(frame, position)
        assert geometry.beta == pytest.approx(beta, abs=EXACT)
        assert geometry.psi == pytest.approx(psi, abs=EXACT)
        assert geometry.plunge == pytest.approx(plunge, abs=EXACT)


def motion(t: float, axis: np.ndarray, pivot: np.ndarray) -> HousingMotion:
    """A smooth motion: a turn theta(t) about a fixed ``axis`` through ``pivot`` and a translation u(t)."""
    theta, theta_dot, theta_ddot = 0.05 * math.sin(7.0 * t), 0.35 * math.cos(7.0 * t), -2.45 * math.sin(7.0 * t)
    u = np.array([0.01 * math.sin(5.0 * t), -0.004 * t * t, 0.006 * math.cos(3.0 * t)])
    u_dot = np.array([0.05 * math.cos(5.0 * t), -0.008 * t, -0.018 * math.sin(3.0 * t)])
    u_ddot = np.array([-0.25 * math.sin(5.0 * t), -0.008, -0.054 * math.cos(3.0 * t)])
    rotation = Rotation.from_rotvec(theta * axis).as_matrix()
    arm = rotation @ (CENTRE - pivot)
    omega, omega_dot = theta_dot * axis, theta_ddot * axis
    velocity = u_dot + np.cross(omega, arm)
    acceleration = u_ddot + np.cross(omega_dot, arm) + np.cross(omega, np.cross(omega, arm))
    return HousingMotion(rotation @ FRAME, pivot + arm + u, velocity, acceleration, omega, omega_dot)


@pytest.mark.parametrize("seed", range(5))
def test_the_rates_are_the_derivatives(seed):
    """Central differences of step 1e-5 s: truncation (h^2 f''' / 6, about 1e-9 of the rates here) and
    rounding (eps f / h, 1e-11) stay below 1e-7 of each rate's scale."""
    rng = np.random.default_rng(seed)
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    pivot = np.array([0.05, -0.1, 0.2])
    h = 1e-5
    for t in (0.1, 0.37):
        now = shaft_geometry(motion(t, axis, pivot), WHEEL, LENGTH)
        before, after = (shaft_geometry(motion(t + s, axis, pivot), WHEEL, LENGTH) for s in (-h, h))
        for name in ("beta", "psi", "plunge"):
            rate = (getattr(after, name) - getattr(before, name)) / (2 * h)
            acceleration = (getattr(after, name + "_dot") - getattr(before, name + "_dot")) / (2 * h)
            assert getattr(now, name + "_dot") == pytest.approx(rate, rel=1e-7, abs=1e-9), name
            assert getattr(now, name + "_ddot") == pytest.approx(acceleration, rel=1e-6, abs=1e-7), name


def test_a_wheel_beyond_the_shaft_length_is_refused():
    with pytest.raises(GeometryError, match="beyond the halfshaft's length"):
        at(position=CENTRE + 0.5 * FRAME[:, 0])
