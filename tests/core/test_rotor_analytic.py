"""Transfer matrices and frequencies against closed-form results."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from driveline.rotor import Bearing, ConcentratedMass, Driveline, ShaftSegment

from support import rotor_checks

E, RHO, D, L = 2.1e11, 7850.0, 0.040, 1.0
A = math.pi / 4 * D**2
I = math.pi / 64 * D**4


def pinned(seg: ShaftSegment) -> Driveline:
    return Driveline([seg], left="pinned", right="pinned")


def rayleigh_pinned(n: int, spin: float) -> tuple[float, float]:
    """Exact forward and backward whirl of mode n of a spinning pinned Rayleigh beam.

    U = sin(k z), k = n pi / L in EI U'''' + rho I (w^2 - 2 Omega w) U'' - rho A w^2 U = 0:
    (rho A + rho I k^2) w^2 - 2 rho I k^2 Omega w - EI k^4 = 0.
    """
    k = n * math.pi / L
    a = RHO * A + RHO * I * k * k
    b = RHO * I * k * k * spin
    root = math.sqrt(b * b + a * E * I * k**4)
    return (b + root) / a, (root - b) / a


def test_euler_bernoulli_pinned_matches_analytic():
    # Exact: (n pi/L)^2 sqrt(EI/(rho A)). Tolerance 1e-6 relative as specified; the
    # transfer matrix is exact, so only brentq's tolerance (1e-13) and round-off remain
    # (measured <= 3e-16).
    d = pinned(ShaftSegment(L, D, 0.0, E, RHO, rotary_inertia=False, gyroscopic=False))
    got = d.whirl_frequencies(0.0, 4).forward
    exact = np.array([(n * math.pi / L) ** 2 * math.sqrt(E * I / (RHO * A)) for n in range(1, 5)])
    assert np.allclose(got, exact, rtol=1e-6, atol=0.0)
    assert np.allclose(got, exact, rtol=1e-12, atol=0.0)  # what we actually achieve


@pytest.mark.parametrize("spin", [0.0, 800.0, 3000.0])
def test_spinning_rayleigh_pinned_matches_analytic(spin):
    # Exact closed form above; same reasoning as for the Euler-Bernoulli case: 1e-10.
    d = pinned(ShaftSegment(L, D, 0.0, E, RHO))
    wf = d.whirl_frequencies(spin, 4)
    exact = np.array([rayleigh_pinned(n, spin) for n in range(1, 5)])
    assert np.allclose(wf.forward, exact[:, 0], rtol=1e-10, atol=0.0)
    assert np.allclose(wf.backward, exact[:, 1], rtol=1e-10, atol=0.0)


def test_critical_speeds_pinned_rayleigh_analytic():
    # w = +-Omega in the dispersion relation: Omega = k^2 sqrt(EI / (rho A - rho I k^2))
    # forward, k^2 sqrt(EI / (rho A + 3 rho I k^2)) backward. Exact: 1e-10.
    d = pinned(ShaftSegment(L, D, 0.0, E, RHO))
    ks = np.array([n * math.pi / L for n in range(1, 4)])
    fwd = ks**2 * np.sqrt(E * I / (RHO * A - RHO * I * ks**2))
    bwd = ks**2 * np.sqrt(E * I / (RHO * A + 3 * RHO * I * ks**2))
    assert np.allclose(d.critical_speeds(3), fwd, rtol=1e-10, atol=0.0)
    assert np.allclose(d.critical_speeds(3, whirl="backward"), bwd, rtol=1e-10, atol=0.0)


@pytest.mark.parametrize("order", [2, 3, 6])
def test_order_resonances_pinned_rayleigh_analytic(order):
    # w = order * Omega: Omega = k^2 sqrt(EI / ((rho A + rho I k^2) q^2 - 2 rho I k^2 q)).
    d = pinned(ShaftSegment(L, D, 0.0, E, RHO))
    ks = np.array([n * math.pi / L for n in range(1, 4)])
    q = order
    exact = ks**2 * np.sqrt(E * I / ((RHO * A + RHO * I * ks**2) * q * q - 2 * RHO * I * ks**2 * q))
    got = [r.spin for r in d.order_resonances((order,), ("forward",), n=3)]
    assert np.allclose(got, exact, rtol=1e-10, atol=0.0)
    assert all(r.order == order and math.isclose(r.frequency, order * r.spin) for r in d.order_resonances((order,)))


@pytest.mark.parametrize(
    "left,right,beta_l",
    [
        ("clamped", "free", [1.875104068711961, 4.694091132974175, 7.854757438237613]),
        ("clamped", "clamped", [4.730040744862704, 7.853204624095838, 10.995607838001671]),
        ("clamped", "pinned", [3.926602312047919, 7.068582745628732, 10.210176122813031]),
        ("free", "free", [4.730040744862704, 7.853204624095838, 10.995607838001671]),
    ],
)
def test_end_conditions_euler_bernoulli(left, right, beta_l):
    # Classical roots of the Euler-Bernoulli frequency equations (13 digits); 1e-10.
    seg = ShaftSegment(L, D, 0.0, E, RHO, rotary_inertia=False, gyroscopic=False)
    d = Driveline([seg], left=left, right=right)
    got = d.whirl_frequencies(0.0, 3).forward
    exact = (np.array(beta_l) / L) ** 2 * math.sqrt(E * I / (RHO * A))
    assert np.allclose(got, exact, rtol=1e-10, atol=0.0)


@pytest.mark.parametrize("w,spin", [(0.0, 0.0), (1e-3, 0.0), (50.0, 900.0), (700.0, 700.0), (-700.0, 700.0),
                                    (4000.0, 100.0), (-2.5e4, 3000.0), (6e4, 0.0)])
def test_field_matrix_equals_matrix_exponential(w, spin):
    # H = expm(A l) for s' = A s, s = [U, psi, M, V]; both exact, so round-off only.
    # Entries are compared relative to the largest entry of each row (1e-12).
    seg = ShaftSegment(0.7, 0.0762, 0.0729, E, RHO)
    EI, m = seg.bending_stiffness, seg.mass_per_length
    c = RHO * seg.second_moment * (w * w - 2 * spin * w)
    Amat = np.array([[0, 1, 0, 0], [0, 0, 1 / EI, 0], [0, -c, 0, 1], [m * w * w, 0, 0, 0]])
    ref = sla.expm(Amat * seg.length)
    got = seg.transfer_matrix(w, spin)[0]
    scale = np.abs(ref).max(axis=1, keepdims=True)
    assert np.all(np.abs(got - ref) <= 1e-12 * scale)


def test_field_matrix_is_unimodular_and_composes():
    # det H = exp(trace(A) l) = 1, and H(l1 + l2) = H(l2) H(l1) exactly (1e-12).
    seg = ShaftSegment(0.9, 0.0762, 0.0729, E, RHO)
    w, spin = np.array([300.0, -1200.0, 5000.0]), np.array([1000.0, 1000.0, 50.0])
    H = seg.transfer_matrix(w, spin)
    assert np.allclose(np.linalg.det(H), 1.0, rtol=0, atol=1e-9)
    H2 = seg.transfer_matrix(w, spin, 0.5) @ seg.transfer_matrix(w, spin, 0.4)
    assert np.allclose(H2, H, rtol=1e-12, atol=1e-12 * np.abs(H).max())


def test_point_matrices():
    m = ConcentratedMass(0, 2.5, polar_inertia=0.004, diametral_inertia=0.002)
    P = m.transfer_matrix(100.0, 50.0)[0]
    # entries are plain products: pytest.approx's default 1e-6 is ample
    assert P[3, 0] == pytest.approx(2.5 * 100.0**2)
    assert P[2, 1] == pytest.approx(-(0.002 * 100.0**2 - 0.004 * 50.0 * 100.0))
    b = Bearing(0, 1e7)
    assert b.transfer_matrix(10.0)[0][3, 0] == -1e7


def test_rigid_body_on_springs():
    # A short, practically rigid and massless shaft carrying one body at node 0, on a
    # bearing at each end. Reference: the 2-dof rigid body q = [U0, psi] with
    # (K + w Omega G - w^2 M) q = 0; shaft flexibility and mass enter at ~1e-8: 1e-6.
    seg = ShaftSegment(0.2, 0.5, 0.0, 1e16, 1e-6, rotary_inertia=False, gyroscopic=False)
    m, Jp, Jd, k, spin = 10.0, 0.8, 0.5, 1e5, 150.0
    d = Driveline([seg], [ConcentratedMass(0, m, Jp, Jd)], [Bearing(0, k), Bearing(1, k)])
    ln = seg.length
    K = np.array([[2 * k, k * ln], [k * ln, k * ln * ln]])  # springs at U0 and U0 + l psi
    forward, backward = rotor_checks.rigid_body_whirl(K, m, Jd, Jp, spin)
    wf = d.whirl_frequencies(spin, 2)
    assert np.allclose(wf.forward, forward, rtol=1e-6)
    assert np.allclose(wf.backward, backward, rtol=1e-6)
