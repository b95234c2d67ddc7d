"""Tripod coupling kinematics: closed forms of the seed against the exact closed-loop solution."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.tripod import closed_form, exact, geometry, plane_solver
from driveline.tripod.model import TripodCouplingModel

R, L = 0.026, 0.700  # seed 000's worked example
PHI = np.linspace(0.0, 2.0 * np.pi, 720, endpoint=False)
ARCMIN = np.pi / (180.0 * 60.0)


@pytest.fixture(scope="module", params=[5.0, 15.0, 30.0, 45.0])
def pose(request: pytest.FixtureRequest) -> tuple[float, exact.ExactPose]:
    beta = np.radians(request.param)
    return beta, exact.exact_pose(PHI, beta, R, L)


def test_closure_residual_vanishes(pose):
    beta, p = pose
    x = np.column_stack([p.phi_out, p.swing])
    residual = exact._residual(x, PHI, np.full_like(PHI, beta), R, L)
    assert np.abs(residual).max() < 1e-15  # m^2-scaled residual at round-off


def test_orbit_radius_matches_exact_tripod_centre(pose):
    beta, p = pose
    axis = np.array([-np.sin(beta), 0.0, np.cos(beta)])
    offset = p.tripod_centre - np.outer(p.tripod_centre @ axis, axis)
    radius = np.linalg.norm(offset, axis=1)
    rho = geometry.orbit_radius(beta, R)
    # rho is the small-r/l planar result; the exact orbit differs by O(r/l) of rho.
    assert np.abs(radius / rho - 1.0).max() < R / L
    # the centre circles three times per turn, in the shaft's sense of rotation
    angle = np.unwrap(np.arctan2(offset @ np.array([0.0, 1.0, 0.0]), offset @ np.array([np.cos(beta), 0.0, np.sin(beta)])))
    assert (angle[-1] - angle[0]) == pytest.approx(3.0 * 2.0 * np.pi * (1 - 1 / len(PHI)), rel=1e-3)


def test_cone_angle_is_rho_over_l(pose):
    beta, p = pose
    assert np.abs(p.cone_angle * L / geometry.orbit_radius(beta, R) - 1.0).max() < R / L


def test_eq18_in_project_convention_matches_exact(pose):
    beta, p = pose
    amplitude = closed_form.deviation_amplitude(beta, R, L)
    error = np.abs((p.phi_out - PHI) - closed_form.angle_deviation(PHI, beta, R, L)).max()
    # measured: 1.3e-5 (10 deg), 3.3e-4 (30 deg), 1.7e-3 (45 deg) of the amplitude
    assert error < 2.5e-3 * amplitude
    # eq 18 read with phi = phi_in (groove 1 in the bend plane) would be wrong by ~sqrt(2) A
    literal = np.abs((p.phi_out - PHI) - amplitude * np.cos(3 * PHI)).max()
    assert literal > 1.3 * amplitude


def test_seed_claim_peak_deviation_below_10_arcmin_at_30_deg():
    p = exact.exact_pose(PHI, np.radians(30.0), R, L)
    peak = np.abs(p.phi_out - PHI).max()
    assert peak < 10 * ARCMIN
    assert peak / ARCMIN == pytest.approx(2.647, abs=0.01)  # measured 2.647 arcmin


def test_zero_bend_angle_gives_zero_deviation():
    p = exact.exact_pose(PHI, 0.0, R, L)
    assert np.abs(p.phi_out - PHI).max() < 1e-15
    assert np.abs(p.cone_angle).max() < 1e-15


def test_speed_ratio_is_the_derivative_of_the_angle(pose):
    beta, p = pose
    step = PHI[1] - PHI[0]
    for phi_out, ratio in [
        (p.phi_out, p.speed_ratio),
        (PHI + closed_form.angle_deviation(PHI, beta, R, L), closed_form.speed_ratio(PHI, beta, R, L)),
    ]:
        numerical = np.gradient(phi_out, step)
        # central-difference truncation error: step^2 / 6 * max|d3 phi_out| = step^2 / 6 * 27 A (x 1.5)
        # plus 1e-8 for the exact solver's finite-difference Jacobian (round-off ~ eps / 1e-7)
        bound = 1.5 * step**2 / 6.0 * 27.0 * closed_form.deviation_amplitude(beta, R, L) + 1e-8
        assert np.abs(numerical[1:-1] - ratio[1:-1]).max() < bound


def test_printed_eq19_is_not_the_derivative_of_eq18():
    beta = np.radians(30.0)
    amplitude = closed_form.deviation_amplitude(beta, R, L)
    printed = 1.0 - 3.0 * amplitude * np.cos(3.0 * closed_form.paper_angle(PHI))
    assert np.abs(printed - closed_form.speed_ratio(PHI, beta, R, L)).max() > 2.0 * amplitude


def test_corrected_eq21_arm_lengths(pose):
    beta, p = pose
    rho = geometry.orbit_radius(beta, R)
    assert np.abs(geometry.arm_lengths(PHI, beta, R) - p.arm_lengths).max() < 0.25 * rho
    mean = p.arm_lengths.mean()
    assert abs(mean - (R + rho)) < 0.1 * rho  # corrected mean r + rho
    assert abs(mean - (R - rho)) > 1.8 * rho  # the seed's r - rho is off by 2 rho


def test_warm_started_solve_matches_batch():
    beta = np.radians(40.0)
    batch = exact.solve_closure(PHI[:50], beta, R, L)
    x = None
    for k in range(50):
        x = exact.solve_closure(PHI[k], beta, R, L, start=x)
        np.testing.assert_allclose(x, batch[k], atol=1e-14)


@pytest.mark.parametrize("r_over_l", [0.005, 26 / 700, 0.2])
@pytest.mark.parametrize("beta_deg", [0.0, 1.0, 30.0, 60.0])
def test_plane_formulation_agrees_with_the_newton_closure(r_over_l, beta_deg):
    """Two independent exact formulations (FMU's scalar plane solver, batched 3-unknown Newton),
    both from a cold start, over a full turn up to the 60 deg guard limit."""
    beta, r, l = np.radians(beta_deg), R, R / r_over_l
    reference = exact.exact_pose(PHI[::4], beta, r, l)
    for k, phi in enumerate(PHI[::4]):
        phi_out, ratio, solution = plane_solver.solve(float(phi), float(beta), r, l)
        assert phi_out == pytest.approx(reference.phi_out[k], abs=1e-14)
        # the plane solver's Jacobian is analytic, the batched closure's a central difference (error ~1e-10):
        # measured worst 1.1e-10 (1.5e-8 while the plane solver differenced its Jacobian forward too)
        assert ratio == pytest.approx(reference.speed_ratio[k], abs=5e-10)
        assert solution.cone_angle == pytest.approx(reference.cone_angle[k], abs=1e-13)



@pytest.mark.parametrize("kinematics", [0, 1])
def test_omega_out_is_the_speed_at_the_current_bend_not_the_angles_rate_while_beta_moves(kinematics):
    """omega_out = omega_in d(phi_out)/d(phi_in), as its description says: d(phi_out)/dt (central
    difference over 1e-6 s, within 1e-8) at a held bend; while beta moves at 4.36 rad/s (5 -> 30 deg
    in 0.1 s) d(phi_out)/dt is omega_out + d(phi_out)/d(beta) beta_dot (3.5e-3 rad/s at 15 deg), the
    last term from phi_out at beta +- 1e-6 rad, within 1e-3 of itself."""
    h, beta0, rate = 1e-6, np.radians(15.0), np.radians(25.0) / 0.1

    def model(beta: float, phi_in: float, beta_dot: float = 0.0) -> TripodCouplingModel:
        coupling = TripodCouplingModel()
        coupling.kinematics, coupling.beta, coupling.beta_dot, coupling.phi_in_start = kinematics, beta, beta_dot, phi_in
        assert coupling.initialize(0.0) == []
        return coupling

    def run(beta_dot: float) -> tuple[float, float]:
        """d(phi_out)/dt and omega_out at t = h."""
        coupling = model(beta0, 0.3, beta_dot)
        angles, speeds = [coupling.phi_out], [coupling.omega_out]
        for k in range(2):
            coupling.beta = beta0 + beta_dot * k * h
            assert coupling.step(k * h, h) == []
            angles.append(coupling.phi_out)
            speeds.append(coupling.omega_out)
        return (angles[2] - angles[0]) / (2 * h), speeds[1]

    angle_rate, speed = run(0.0)
    assert angle_rate == pytest.approx(speed, rel=1e-8)
    angle_rate, speed = run(rate)
    phi_in = 0.3 + TripodCouplingModel().omega_in * h
    bend_term = (model(beta0 + rate * h + 1e-6, phi_in).phi_out
                 - model(beta0 + rate * h - 1e-6, phi_in).phi_out) / 2e-6 * rate
    assert abs(bend_term) > 3e-3  # rad/s: the difference the description names is there
    assert angle_rate - speed == pytest.approx(bend_term, rel=1e-3)


def _richardson(function, at: float, step: float) -> np.ndarray:
    """Central differences with steps h, h/2, h/4 extrapolated twice: error O(h^6) plus rounding."""
    def central(h: float) -> np.ndarray:
        return (np.asarray(function(at + h)) - np.asarray(function(at - h))) / (2.0 * h)
    d1, d2, d3 = central(step), central(step / 2.0), central(step / 4.0)
    return (16.0 * (4.0 * d3 - d2) / 3.0 - (4.0 * d2 - d1) / 3.0) / 15.0


@pytest.mark.parametrize("r_over_l", [0.005, 26 / 700, 0.2])
@pytest.mark.parametrize("beta_deg", [1.0, 30.0, 60.0])
def test_the_star_centres_analytic_derivatives_equal_extrapolated_differences(r_over_l, beta_deg):
    """The Newton Jacobian and the implicit function theorem's right-hand sides: the star centre's
    derivatives in x, y, beta and phi_in against Richardson-extrapolated differences (steps 1e-4 of
    the argument): within 1e-9 of the column's scale plus the differences' rounding, about
    12 eps |F| / h (the extrapolation's weights on eps |F| / (h / 4))."""
    beta, r, l = np.radians(beta_deg), R, R / r_over_l
    for phi in (0.0, 0.37, 1.9):
        _, _, solution = plane_solver.solve(phi, beta, r, l)
        point = (solution.x + 3e-4, solution.y - 2e-4, beta, phi)  # off the solution too

        def centre(*args: float) -> tuple[float, float, float]:
            x, y, b, p = args
            values, _ = plane_solver._star_centre(x, y, (np.cos(3 * p), np.sin(3 * p)), np.cos(b), np.sin(b), r, l,
                                                  math)
            return values[:3]

        _, exact_columns = plane_solver._star_centre(
            point[0], point[1], (np.cos(3 * phi), np.sin(3 * phi)), np.cos(beta), np.sin(beta), r, l, math,
            (plane_solver.ALONG_X, plane_solver.ALONG_Y, plane_solver.ALONG_BETA, plane_solver.ALONG_PHI))
        for k, column in enumerate(exact_columns):
            moved = lambda v, k=k: centre(*(v if i == k else a for i, a in enumerate(point)))  # noqa: E731
            reference = _richardson(moved, point[k], 1e-4)
            rounding = 12.0 * np.finfo(float).eps * np.abs(centre(*point)).max() / 1e-4
            allowed = 1e-9 * np.abs(reference).max() + rounding
            assert np.abs(np.array(column) - reference).max() <= allowed, (k, column, reference)


@pytest.mark.parametrize("beta_deg", [1.0, 30.0, 60.0])
def test_the_plane_solvers_speed_ratio_is_the_derivative_of_its_angle(beta_deg):
    """d(phi_out)/d(phi_in) by the implicit function theorem through the analytic Jacobian against
    the Richardson-extrapolated difference of phi_out itself (steps 1e-3; truncation ~1e-13, rounding
    about 12 eps |phi_out| / h, 5e-12): within 1e-11 (measured 3.3e-12; the forward-difference
    Jacobian it replaced gave 2.2e-10)."""
    beta = np.radians(beta_deg)
    for phi in np.linspace(0.0, 2.0, 7):
        reference = _richardson(lambda p: plane_solver.solve(p, beta, R, L)[0], phi, 1e-3)
        assert abs(plane_solver.solve(phi, beta, R, L)[1] - reference) <= 1e-11
