"""Timoshenko segments (shear deformation): matrix exponential, closed form, FE, limits."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from driveline.rotor import Driveline, ShaftSegment, fem, loads_driveline, one_piece_shaft

E, RHO, D, L = 2.1e11, 7850.0, 0.040, 1.0


def tube_segment(**switches) -> ShaftSegment:
    return ShaftSegment(0.7, 0.0762, 0.0729, E, RHO, shear=True, **switches)


@pytest.mark.parametrize("w,spin", [(0.0, 0.0), (1e-3, 0.0), (50.0, 900.0), (700.0, 700.0), (-700.0, 700.0),
                                    (4000.0, 100.0), (-2.5e4, 3000.0), (6e4, 0.0), (9.5e4, 0.0), (2e5, 100.0)])
def test_shear_field_matrix_equals_matrix_exponential(w, spin):
    # H = expm(A l) with U' = psi - V/(kappa G A); both exact: round-off only. The last
    # three points lie above the tube's cut-off sqrt(kappa G A / rho I) = 8.9e4 rad/s,
    # where beta1**2 < 0 (measured <= 3.7e-13 of each row's largest entry); 1e-11.
    seg = tube_segment()
    EI, m, kGA = seg.bending_stiffness, seg.mass_per_length, seg.shear_stiffness
    c = RHO * seg.second_moment * (w * w - 2 * spin * w)
    A = np.array([[0, 1, 0, -1 / kGA], [0, 0, 1 / EI, 0], [0, -c, 0, 1], [m * w * w, 0, 0, 0]])
    ref = sla.expm(A * seg.length)
    got = seg.transfer_matrix(w, spin)[0]
    assert np.all(np.abs(got - ref) <= 1e-11 * np.abs(ref).max(axis=1, keepdims=True))


def test_cowper_shear_coefficient():
    # Cowper (1966): 6(1+nu)/(7+6nu) for a solid circle, 2(1+nu)/(4+3nu) for a thin ring
    nu = 0.3
    assert ShaftSegment(1.0, 0.04, poisson_ratio=nu).shear_coefficient == pytest.approx(6 * (1 + nu) / (7 + 6 * nu),
                                                                                        rel=1e-15)
    thin = ShaftSegment(1.0, 0.04, 0.04 * (1 - 1e-9), poisson_ratio=nu).shear_coefficient
    assert thin == pytest.approx(2 * (1 + nu) / (4 + 3 * nu), rel=1e-8)


def pinned_timoshenko(n: int, spin: float, seg: ShaftSegment) -> tuple[float, float]:
    """Lowest forward and backward whirl of mode ``n`` (U = sin(k z)) of a pinned spinning Timoshenko beam:
    the roots in ``w`` of ``k^4 - k^2 (c/EI + rho A w^2/kGA) - rho A w^2 (1 - c/kGA)/EI = 0``,
    ``c = rho I (w^2 - 2 Omega w)``."""
    k = n * math.pi / seg.length
    P, R, K, EI = RHO * seg.second_moment, RHO * seg.area, seg.shear_stiffness, seg.bending_stiffness
    roots = np.roots([R * P / (EI * K), -2 * spin * R * P / (EI * K), -k * k * (P / EI + R / K) - R / EI,
                      2 * spin * k * k * P / EI, k**4])
    real = np.real(roots[np.abs(roots.imag) < 1e-9 * np.abs(roots)])
    return float(np.min(real[real > 0])), float(-np.max(real[real < 0]))


@pytest.mark.parametrize("spin", [0.0, 800.0, 3000.0])
def test_spinning_pinned_timoshenko_matches_closed_form(spin):
    # Exact transfer matrices against the closed-form dispersion relation: measured
    # <= 1.5e-14; 1e-10 as for the Rayleigh closed forms.
    seg = ShaftSegment(L, D, 0.0, E, RHO, shear=True)
    wf = Driveline([seg], left="pinned", right="pinned").whirl_frequencies(spin, 4)
    exact = np.array([pinned_timoshenko(n, spin, seg) for n in range(1, 5)])
    np.testing.assert_allclose(wf.forward, exact[:, 0], rtol=1e-10, atol=0.0)
    np.testing.assert_allclose(wf.backward, exact[:, 1], rtol=1e-10, atol=0.0)


@pytest.mark.parametrize("spin", [0.0, 800.0])
def test_shear_tube_matches_finite_elements(spin):
    # Timoshenko FE elements (Przemieniecki) converge as h**2 here (the element shear
    # parameter grows as 1/h**2): measured 4e-6 (mode 1) to 6.7e-4 (mode 6) at 40
    # elements, 16x less at 160. Same root count; 1e-4 at 160 elements.
    base = one_piece_shaft(1.4, 0.0762, 0.0729, E, RHO, 2.5, 0.004, 0.002, 1e7)
    d = Driveline([ShaftSegment(1.4, 0.0762, 0.0729, E, RHO, shear=True)], base.masses, base.bearings)
    lam = fem.whirl_frequencies(d, spin, 160)
    fe_f, fe_b = lam[lam > 1e-6], -lam[lam < -1e-6][::-1]
    wf = d.whirl_frequencies(spin, w_max=0.5 * (fe_f[5] + fe_f[6]))
    assert wf.forward.size == 6
    np.testing.assert_allclose(wf.forward, fe_f[:6], rtol=1e-4, atol=0.0)
    np.testing.assert_allclose(wf.backward, fe_b[: wf.backward.size], rtol=1e-4, atol=0.0)


def test_shear_lowers_the_tube_critical_speeds():
    # The measurement with ROSS (shear on, Cowper): -0.78 %, -0.39 %, -0.17 %.
    rayleigh = one_piece_shaft(1.4, 0.0762, 0.0729, E, RHO, 2.5, 0.004, 0.002, 1e7, shear=False)
    shear = one_piece_shaft(1.4, 0.0762, 0.0729, E, RHO, 2.5, 0.004, 0.002, 1e7)  # the default
    change = shear.critical_speeds(3) / rayleigh.critical_speeds(3) - 1
    np.testing.assert_allclose(change, [-0.0078, -0.0039, -0.0017], atol=5e-5)


def test_shear_keys_in_the_layout():
    text = "[[segments]]\nlength = 1.0\nouter_diameter = 0.04\nyoungs_modulus = 2.1e11\ndensity = 7850.0\n"
    d = loads_driveline(text + "shear = true\npoisson_ratio = 0.28\n")
    assert d.segments[0].shear and d.segments[0].poisson_ratio == 0.28
    with pytest.raises(ValueError, match=r"segments\[0\].poisson_ratio"):
        loads_driveline(text + "poisson_ratio = 0.5\n")
    with pytest.raises(ValueError, match=r"segments\[0\].shear"):
        loads_driveline(text + "shear = 1\n")
