"""Universal reducer: ratio, RCRCR kinematics, strength relations and the model.

The RCRCR reference builds the mechanism numerically (axes as vectors, the closure
point E from the cylinder constraints by polynomial root finding), independently of
the closed forms in :mod:`driveline.reducer.mechanics`.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from driveline.reducer import mechanics
from driveline.reducer.model import UniversalReducerModel

from support import model_checks

E = 0.005  # eccentricity of table 1 [m]
E_Y = np.array([0.0, 1.0, 0.0])  # normal to the bend plane xz
N_IN = np.array([0.0, 0.0, 1.0])  # input axis a, pointing from the input shaft towards O


def output_axis(alpha: float) -> np.ndarray:
    """Axis d from O towards the load; the angle to -N_IN (a, taken from O) is alpha."""
    return Rotation.from_euler("y", math.pi - alpha).apply(N_IN)


def closure_roots(phi_in: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
    """Both closures of the cylinder constraints: E on axis b (eccentric at angle phi_in
    about a, from the bend-plane normal) and at distance e from axis d. In units of e the
    condition is quadratic in the slide u along a; returns the eccentric offset and the
    two roots, smaller magnitude first."""
    offset = Rotation.from_rotvec(phi_in * N_IN).apply(E_Y)
    d = output_axis(alpha)

    def excess(u: float) -> float:
        point = offset + u * N_IN
        return float(point @ point - (point @ d) ** 2 - 1.0)

    samples = np.array([-1.0, 0.0, 1.0])
    roots = np.roots(np.polyfit(samples, [excess(u) for u in samples], 2)).real  # exact fit of a quadratic
    return offset, roots[np.argsort(np.abs(roots))]


def closure_point(phi_in: float, alpha: float) -> np.ndarray:
    """E on the branch the mechanism reaches continuously from coaxial shafts (s = 0): the
    smaller root. The roots meet where sin(phi_in) = 0, so near there they are only known to
    ~1e-16 / (|sin phi_in| sin(bend)) (the conditioning of a near-double root)."""
    offset, roots = closure_roots(phi_in, alpha)
    return E * (offset + roots[0] * N_IN)


def angle_about(axis: np.ndarray, point: np.ndarray) -> float:
    """Angle of ``point`` about ``axis`` (right hand), from the bend-plane normal."""
    return math.atan2(float(point @ np.cross(axis, E_Y)), float(point @ E_Y))


def wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


# -- kinematics -------------------------------------------------------------------------------


def test_table_1_ratio_and_geometry() -> None:
    assert mechanics.transmission_ratio(34, 29) == pytest.approx(6.8, rel=1e-15)
    m = 0.002
    assert (m * 34, m * 29) == pytest.approx((0.068, 0.058))  # reference diameters, sec. 4.1
    assert 0.5 * m * (34 - 29) == pytest.approx(E)  # table 1's eccentricity is the centre distance


@pytest.mark.parametrize("alpha_deg", (95.0, 120.0, 135.0, 160.0, 179.0))
def test_closure_point_turns_with_the_input_about_both_axes(alpha_deg: float) -> None:
    alpha = math.radians(alpha_deg)
    d = output_axis(alpha)
    # Off the branch points sin(phi) = 0, |sin phi| >= 0.01 on this grid, so the roots are
    # good to ~1e-14 / sin(1 deg) ~ 1e-12 (see closure_point); 1e-10 rad leaves margin.
    for phi in np.linspace(-13.0, 13.0, 97) + 0.0123:
        point = closure_point(phi, alpha)
        assert wrap(angle_about(d, point) - phi) == pytest.approx(0.0, abs=1e-10)
        # Positions: the eigenvalue error of np.roots scales with the larger root, which is
        # cot^2(bend/2) ~ 1.3e4 times the physical one at 179 deg: ~1e-15 m; allow 1e-13 m.
        assert point @ N_IN == pytest.approx(float(mechanics.cylinder_slide(phi, alpha, E)), abs=1e-13)
        assert point @ (N_IN + d) == pytest.approx(0.0, abs=1e-13)  # E in the bisecting plane


def test_ratio_holds_while_the_angle_changes() -> None:
    # A path in which alpha sweeps 100-170 deg while the input turns 8 times.
    t = np.linspace(0.0, 1.0, 401)
    phi = 16.0 * math.pi * t**1.5 + 0.0123  # off the branch points, as above
    alpha = np.radians(135.0 + 35.0 * np.sin(9.0 * t))
    carrier = np.unwrap([angle_about(output_axis(a), closure_point(p, a)) for p, a in zip(phi, alpha)])
    np.testing.assert_allclose(carrier - carrier[0], phi - phi[0], rtol=0, atol=1e-9)


@pytest.mark.parametrize("alpha_deg", (100.0, 135.0, 160.0))
def test_second_closure_branch_turns_backwards_and_meets_at_half_turns(alpha_deg: float) -> None:
    # The other root puts E in the plane normal to a - d; there E turns about d through
    # -phi_in. The branches share E where sin(phi_in) = 0 (eccentric normal to the bend
    # plane): a change point twice per turn, which the model passes on the first branch.
    alpha = math.radians(alpha_deg)
    d = output_axis(alpha)
    for phi in np.linspace(-7.0, 7.0, 57) + 0.0123:
        offset, roots = closure_roots(phi, alpha)
        other = offset + roots[1] * N_IN
        assert wrap(angle_about(d, other) + phi) == pytest.approx(0.0, abs=1e-10)
    for phi in (0.0, math.pi, -3.0 * math.pi):
        _, roots = closure_roots(phi, alpha)
        np.testing.assert_allclose(roots, 0.0, atol=1e-7)  # double root: sqrt(eps) accuracy


@pytest.mark.parametrize("alpha_deg", (120.0, 160.0, 180.0))
def test_connecting_shaft_cannot_spin_unless_coaxial(alpha_deg: float) -> None:
    # The revolute f joining shafts 2 and 3 must stay normal to b (parallel to a) and to
    # c (parallel to d). Spin shaft 2 about b by psi: f turns to R_b(psi) f0, and the
    # residual (R_b(psi) f0) . d is sin(psi) times -sin(alpha). It vanishes only at psi = 0
    # (mod pi), i.e. the shaft only translates, except for coaxial shafts, where the
    # chain has a free spin: the singularity of eq 21 (determinant -sin alpha).
    alpha = math.radians(alpha_deg)
    d = output_axis(alpha)
    f0 = np.cross(N_IN, d)
    f0 = f0 / np.linalg.norm(f0) if np.linalg.norm(f0) > 0 else E_Y
    psi = np.linspace(-3.0, 3.0, 61)
    residual = Rotation.from_rotvec(psi[:, None] * N_IN).apply(f0) @ d
    np.testing.assert_allclose(residual, -np.sin(psi) * math.sin(alpha), atol=1e-15)


# -- strength relations (eqs 18-21) -----------------------------------------------------------

PROTOTYPE = dict(z1=34, z2=29, module=0.002, e=E, L1=0.020)  # L1 is not in the seed


def test_prototype_loads_recomputed_by_hand() -> None:
    # M_in = 10 N.m at alpha = 160 deg (a = 80 deg), L1 = 20 mm:
    # M_out = 6.8 * 10 = 68; F_B = 10 / 0.005 = 2000; M_E = 2 * 2000 * 0.02 * sin 80 = 78.78462
    # F_t = 2 * 68 / (0.002 * 34) = 2000; M_C1 = 2000 * 0.029 = 58
    # M_B = 58 / sin 160 + 2000 * 0.02 = 169.58066 + 40; M_C = 58 cot 160 + 40 = -159.35369 + 40
    loads = mechanics.connecting_shaft_loads(10.0, math.radians(160.0), **PROTOTYPE)
    hand = dict(M_out=68.0, F_B=2000.0, M_E=78.784620, F_t=2000.0, M_C1=58.0, M_B=209.58066, M_C=-119.35369)
    for name, value in hand.items():
        assert float(getattr(loads, name)) == pytest.approx(value, rel=1e-7), name  # 8 digits by hand
    # Shaft 3 at C, radius 15 mm: W = pi r^3 / 4 = 2.6507188e-6 m^3, W_t = 2 W.
    # sigma = -119.35369 / W = -45.02693 MPa; tau = 58 / W_t = 10.94042 MPa;
    # sigma_eq = sqrt(2027.42 + 478.77) MPa = 50.06191 MPa < 60 MPa.
    stress = mechanics.shaft_stress(loads.M_C, loads.M_C1, 0.015)
    assert float(stress.sigma) == pytest.approx(-45.02692e6, rel=1e-6)
    assert float(stress.tau) == pytest.approx(10.94042e6, rel=1e-6)
    assert float(stress.sigma_eq) == pytest.approx(50.06191e6, rel=1e-6)


@settings(max_examples=200, deadline=None)
@given(
    M_in=st.floats(-500.0, 500.0),
    alpha=st.floats(0.05, math.pi - 0.05),
    L1=st.floats(0.0, 0.05),
    z2=st.integers(1, 80),
    difference=st.integers(1, 6),
)
def test_moment_balance_eq_21_solved(M_in: float, alpha: float, L1: float, z2: int, difference: int) -> None:
    z1 = z2 + difference
    loads = mechanics.connecting_shaft_loads(M_in, alpha, z1, z2, 0.002, 0.001 * difference, L1)
    a = 0.5 * alpha
    matrix = np.array([[math.sin(a), math.sin(a)], [math.cos(a), -math.cos(a)]])
    rhs = np.array([loads.M_C1 * math.cos(a) + loads.M_E, loads.M_C1 * math.sin(a)])
    m_b, m_c = np.linalg.solve(matrix, rhs)
    # Condition number 1/|tan a| <= 1/tan(0.025) = 40: a few hundred ulp of the moments
    # (plus 1e-12 N.m for subnormal torques).
    scale = 1e-12 * (abs(loads.M_C1) + abs(loads.M_E)) / math.sin(alpha) + 1e-12
    assert float(loads.M_B) == pytest.approx(m_b, abs=scale)
    assert float(loads.M_C) == pytest.approx(m_c, abs=scale)
    # With e = m (z1 - z2) / 2 the gear force equals the eccentric force, and the planet's
    # torque is M_in z2 / (z1 - z2) (torque balance of the planet, omega_2 = 0).
    assert float(loads.F_t) == pytest.approx(float(loads.F_B), rel=1e-12, abs=1e-9)
    assert float(loads.M_C1) == pytest.approx(M_in * z2 / difference, rel=1e-12, abs=1e-9)


# -- the model through the SteppedModel interface --------------------------------------------


def started(**values: float) -> UniversalReducerModel:
    return model_checks.started(UniversalReducerModel, **values)


def test_steps_keep_the_ratio_exact_while_alpha_varies() -> None:
    model = started(omega_in=150.0, T_load=300.0, phi_in_start=0.4)
    i = 6.8
    h = 1e-3
    for k in range(1000):
        model.intersection_angle = math.radians(130.0 + 35.0 * math.sin(7.0 * k * h))
        model.omega_in = 150.0 * (1.0 + 0.5 * math.sin(3.0 * k * h))
        assert model.step(k * h, h) == []
        assert model.omega_out == pytest.approx(model.omega_in / i, rel=1e-15)
        assert model.phi_out == pytest.approx(model.phi_in / i, rel=1e-15)
        assert model.speed_ratio == pytest.approx(5.0 / 34.0, rel=1e-15)
        assert model.T_in * model.omega_in == pytest.approx(model.T_load * model.omega_out, rel=1e-14)
        assert model.s_b == float(mechanics.cylinder_slide(model.phi_in, model.intersection_angle, E))


def test_start_values_pass_the_strength_check() -> None:
    """The start values are the hand-checked prototype above: M_in = 10 N.m at 160 deg."""
    model = started()
    assert model.T_in == pytest.approx(10.0, rel=1e-15)
    assert model.utilisation == pytest.approx(50.06191 / 60.0, rel=1e-6)
    assert model.utilisation <= 1.0


def test_strength_outputs_scale_with_the_torque() -> None:
    model = started(T_load=68.0, alpha=math.radians(160.0))  # M_in = 10 N.m, as by hand above
    assert model.sigma_eq == pytest.approx(50.06191e6, rel=1e-6)
    assert model.utilisation == pytest.approx(50.06191 / 60.0, rel=1e-6)
    assert model.T_in_allow == pytest.approx(10.0 * 60.0 / 50.06191, rel=1e-6)
    model.T_load = -6.8 * model.T_in_allow  # reversed, at the allowable torque
    assert model.step(0.0, 1e-3) == []
    assert model.utilisation == pytest.approx(1.0, rel=1e-12)
    model.T_load = 0.0
    assert model.step(1e-3, 1e-3) == []
    assert (model.sigma_eq, model.utilisation) == (0.0, 0.0)
    assert model.T_in_allow == pytest.approx(10.0 * 60.0 / 50.06191, rel=1e-6)


@pytest.mark.parametrize(
    ("name", "value", "fragment"),
    [
        ("intersection_angle", math.pi, "input intersection_angle = 180 deg must not exceed intersection_angle_max = 170 deg (eq 21 is singular at 0 and"),
        ("intersection_angle", math.radians(60.0), "input intersection_angle = 60 deg must not be below intersection_angle_min = 90 deg"),
        ("intersection_angle", -0.1, "input intersection_angle = -0.1 rad is below its minimum"),
        ("omega_in", math.nan, "input omega_in = nan is not finite"),
        ("T_load", -math.inf, "input T_load = -inf is not finite"),
    ],
)
def test_invalid_input_is_refused_and_leaves_the_state(name: str, value: float, fragment: str) -> None:
    model = started()
    model_checks.assert_refused_without_trace(model, name, value, fragment)


@pytest.mark.parametrize(
    ("values", "fragment"),
    [
        (dict(z1=29, z2=29), "parameter z1 = 29 must exceed z2 = 29"),
        (dict(z2=0), "parameter z2 = 0 is below its minimum 1"),
        (dict(module=0.0), "parameter module = 0 mm must be positive"),
        (dict(r_shaft=0.0), "parameter r_shaft = 0 mm must be positive"),
        (dict(intersection_angle_max=math.pi), "parameter intersection_angle_max = 180 deg must be below 180 deg"),
        (dict(intersection_angle_min=2.0, intersection_angle_max=1.9),
         "parameter intersection_angle_min = 114.592 deg must not exceed intersection_angle_max = 108.862 deg"),
    ],
)
def test_invalid_parameters_are_refused(values: dict, fragment: str) -> None:
    model = UniversalReducerModel()
    for name, value in values.items():
        setattr(model, name, value)
    before = model.get_state()
    errors = model.initialize(0.0)
    assert any(fragment in e for e in errors), errors
    assert model.get_state() == before
