"""PowertrainMounts' matrices and modes against a second, independently written assembly.

The reference (tests/support/mount_layouts.py) builds the body from a cloud of point masses (its
mass, centre of gravity and moments and products of inertia computed from the points, written to a
layout file as the file's convention asks) and takes the mass and stiffness matrices as the
Hessians of the kinetic energy of the points and of the mounts' potential energy, each mount's
displacement from the cross product ``t + theta x (p - c)``, by polarisation (exact for
quadratic forms up to rounding).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

from driveline.mounts.layout import loads_layout
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES, RigidBody, modes, torque_roll_axis, unrestrained_error
from driveline.variables import decade
from support.mount_layouts import random_layout, reference_matrices


@pytest.mark.parametrize("seed", range(8))
def test_modes_agree_with_the_energy_assembly(seed):
    """Frequencies within 1e-10 relative (eigh of two assemblies that share no code; both matrices
    are well conditioned: measured 2.7e-15)."""
    rng = np.random.default_rng(seed)
    text, points, masses, mounts = random_layout(rng, int(rng.integers(3, 9)))
    body = RigidBody.of(loads_layout(text))
    mass, stiffness, _ = reference_matrices(points, masses, mounts)
    expected = np.sqrt(eigh(stiffness, mass, eigvals_only=True)) / (2.0 * math.pi)
    found = modes(body)
    assert np.max(np.abs(found.frequencies / expected - 1.0)) < 1e-10
    assert np.allclose(np.sum(found.shares, axis=1), 1.0, rtol=0.0, atol=1e-12)
    assert unrestrained_error(found) is None


def test_one_mount_under_the_centre_of_gravity_bounces_at_sqrt_k_over_m():
    """The bounce (z) mode of a body on one mount straight below its centre of gravity is
    sqrt(k_z / m) / 2 pi exactly; the rotations about the mount, which one point spring cannot hold, are unrestrained."""
    k_z, mass = 2.5e5, 187.0
    layout = loads_layout(f"mass = {mass}\ncentre_of_gravity = [0.1, 0.2, 0.3]\ninertia = [9.0, 7.0, 8.0, 0, 0, 0]\n"
                          f"[[mounts]]\nposition = [0.1, 0.2, -0.1]\nstiffness = [1.0e5, 1.2e5, {k_z}]\n")
    found = modes(RigidBody.of(layout))
    bounce = [j for j in range(6) if COORDINATES[found.dominant[j]] == "z"]
    assert len(bounce) == 1
    assert found.frequencies[bounce[0]] == pytest.approx(math.sqrt(k_z / mass) / (2.0 * math.pi), rel=1e-14)
    assert found.shares[bounce[0], 2] == pytest.approx(1.0, abs=1e-14)
    assert "unrestrained (mode 1," in unrestrained_error(found)


def test_a_symmetric_layout_decouples_exactly():
    """Four equal mounts at (+-a, +-b) in the centre of gravity's horizontal plane, principal axes
    along the vehicle's: every mode moves one coordinate alone (shares 1 and 0 to rounding)."""
    mounts = "".join(f"[[mounts]]\nposition = [{x}, {y}, 0.4]\nstiffness = [1.1e5, 0.7e5, 2.3e5]\n"
                     for x in (0.2, -0.2) for y in (0.3, -0.3))
    layout = loads_layout(f"mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.4]\ninertia = [11.0, 8.0, 10.0, 0, 0, 0]\n"
                          + mounts)
    found = modes(RigidBody.of(layout))
    assert sorted(found.dominant) == list(range(6))
    assert np.max(np.abs(found.shares - np.eye(6)[found.dominant])) < 1e-12


def test_a_sloped_symmetric_pair_couples_roll_and_lateral():
    """The counter-check of the one before: the same mounts turned 30 deg about x (a focused pair)
    couple y with roll: some mode shares them (1.6e-3 of its energy, against 1e-12 above)."""
    c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
    mounts = "".join(f"[[mounts]]\nposition = [{x}, {y}, 0.2]\nstiffness = [1.1e5, 0.7e5, 2.3e5]\n"
                     f"orientation = [[1, 0, 0], [0, {c}, {s * (1 if y > 0 else -1)}], "
                     f"[0, {-s * (1 if y > 0 else -1)}, {c}]]\n"
                     for x in (0.2, -0.2) for y in (0.3, -0.3))
    layout = loads_layout(f"mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.4]\ninertia = [11.0, 8.0, 10.0, 0, 0, 0]\n"
                          + mounts)
    found = modes(RigidBody.of(layout))
    assert np.max(np.minimum(found.shares[:, 1], found.shares[:, 3])) > 1e-3


@pytest.mark.parametrize("seed", range(4))
def test_torque_roll_axis_is_the_free_rotation_under_the_torque(seed):
    """J a = e: the inertia tensor times the axis is parallel to the torque (cross product 0)."""
    rng = np.random.default_rng(seed)
    text, *_ = random_layout(rng, 3)
    inertia = loads_layout(text).inertia
    torque = rng.normal(size=3)
    axis = torque_roll_axis(inertia, torque)
    assert np.linalg.norm(axis) == pytest.approx(1.0, abs=1e-15)
    assert np.linalg.norm(np.cross(inertia @ axis, torque)) < 1e-13 * np.linalg.norm(inertia @ axis) * np.linalg.norm(torque)
    assert axis @ torque > 0.0


def test_static_sag_of_a_symmetric_layout_is_the_springs_own(tmp_path):
    """Four equal mounts in the centre of gravity's plane: the weight sags them by m g / (4 k_z),
    the mean torque T about y (motor_axis) turns the body by -T / (4 k_z a^2) about y."""
    path_text = ("mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.4]\ninertia = [11.0, 8.0, 10.0, 0, 0, 0]\n"
                 + "".join(f"[[mounts]]\nposition = [{x}, {y}, 0.4]\nstiffness = [1.1e5, 0.7e5, 2.3e5]\n"
                           for x in (0.2, -0.2) for y in (0.3, -0.3)))
    (tmp_path / "layout.toml").write_text(path_text)
    model = PowertrainMountsModel()
    model.layout, model.T_mean = str(tmp_path / "layout.toml"), 250.0
    assert model.initialize(0.0) == []
    assert model.z_static == pytest.approx(-200.0 * 9.81 / (4 * 2.3e5), rel=1e-13)
    assert model.pitch_static == pytest.approx(-250.0 / (4 * 2.3e5 * 0.2**2), rel=1e-13)
    assert abs(model.x_static) + abs(model.y_static) + abs(model.roll_static) + abs(model.yaw_static) < 1e-15
    assert model.F_z_mount1 + model.F_z_mount2 + model.F_z_mount3 + model.F_z_mount4 == pytest.approx(200.0 * 9.81,
                                                                                                     rel=1e-13)



def test_the_states_nominals_are_the_decades_of_the_default_layouts_sag_and_lowest_mode():
    """The spec's nominals (Model Exchange's absolute tolerance scale) against the default layout: a
    translation's the power of ten at or below its largest static sag along an axis, a rotation's about
    one, a velocity's that times the power of ten at or below the lowest mode's angular frequency."""
    model = PowertrainMountsModel()
    assert model.initialize(0.0) == []
    sag = {name: abs(getattr(model, f"{name}_static")) for name in COORDINATES}
    rate = 2.0 * math.pi * model.f_mode_1
    nominals = {state.name: state.nominal for state in PowertrainMountsModel.spec.states}
    translations, rotations = COORDINATES[:3], COORDINATES[3:]
    for names in (translations, rotations):
        assert {nominals[name] for name in names} == {decade(max(sag[name] for name in names))}
        assert {nominals[f"{name}_dot"] for name in names} == {decade(max(sag[name] for name in names)) * decade(rate)}
