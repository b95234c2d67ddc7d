"""Hinge element (moment-free joint, optionally a rotational spring): closed forms, FE, limits, FMU."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from driveline.rotor import (
    Driveline,
    Hinge,
    ShaftSegment,
    example_path,
    fem,
    load_driveline,
)
from fmu_harness.runs.runner import simulate

from support.rotor_checks import rayleigh

E, RHO, D, L = 2.1e11, 7850.0, 0.040, 1.0
A = math.pi / 4 * D**2
I = math.pi / 64 * D**4
#: Roots beta*l of a cantilever (clamped-free) and of a clamped-pinned beam.
CANTILEVER = [1.875104068711961, 4.694091132974175, 7.854757438237613]
CLAMPED_PINNED = [3.926602312047919, 7.068582745628732]


def half_span() -> ShaftSegment:
    return ShaftSegment(L / 2, D, 0.0, E, RHO, rotary_inertia=False, gyroscopic=False)


def clamped_hinge_clamped(stiffness: float = 0.0) -> Driveline:
    return Driveline([half_span(), half_span()], left="clamped", right="clamped", joints=[Hinge(1, stiffness)])


def hinged_two_piece() -> Driveline:
    return load_driveline(example_path("two_piece_propshaft_hinged"))


def positive_fe(d: Driveline, spin: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    lam = fem.whirl_frequencies(d, spin, 40)
    return lam[lam > 1e-6][:n], -lam[lam < -1e-6][::-1][:n]


def test_clamped_hinge_clamped_beam_matches_closed_form():
    # Symmetric modes: M = V = 0 at the hinge, each half a cantilever; antisymmetric
    # modes: U = M = 0, each half clamped-pinned. Exact transfer matrices: round-off
    # plus brentq's tolerance (measured <= 1.4e-15); 1e-12.
    beta_half = np.sort(CANTILEVER + CLAMPED_PINNED)
    exact = (beta_half / (L / 2)) ** 2 * math.sqrt(E * I / (RHO * A))
    got = clamped_hinge_clamped().whirl_frequencies(0.0, 5).forward
    np.testing.assert_allclose(got, exact, rtol=1e-12, atol=0.0)


def test_first_mode_of_each_half_is_the_cantilever_shape():
    d = clamped_hinge_clamped()
    w1 = d.whirl_frequencies(0.0, 1).forward[0]
    shape = d.mode_shape(w1, 0.0, points_per_segment=16)
    bl = CANTILEVER[0]
    sigma = (math.cosh(bl) + math.cos(bl)) / (math.sinh(bl) + math.sin(bl))
    x = bl * np.minimum(shape.z, L - shape.z) / (L / 2)  # symmetric about the hinge
    ref = np.cosh(x) - np.cos(x) - sigma * (np.sinh(x) - np.sin(x))
    ref /= ref[np.argmax(np.abs(ref))]
    # both normalised to +1 at the hinge; 1e-8 from the root tolerance of w1
    np.testing.assert_allclose(shape.forward, ref, atol=1e-8)


@pytest.mark.parametrize("stiffness", [0.0, 1e2, 1e4, 1e6])
def test_spring_hinge_matches_finite_elements(stiffness):
    # FE: the node's slope split in two, joined by the spring. Cubic elements, 40 per
    # half: measured <= 6.8e-7 over these modes (mode 4; falls as h**4); 2e-6.
    d = clamped_hinge_clamped(stiffness)
    fe, _ = positive_fe(d, 0.0, 4)
    np.testing.assert_allclose(d.whirl_frequencies(0.0, 4).forward, fe, rtol=2e-6, atol=0.0)


def test_stiff_spring_tends_to_the_rigid_joint_and_soft_to_the_hinge():
    rigid = Driveline([half_span(), half_span()], left="clamped", right="clamped").whirl_frequencies(0.0, 3).forward
    free = clamped_hinge_clamped().whirl_frequencies(0.0, 3).forward
    previous = free
    for stiffness in (1e1, 1e3, 1e5, 1e7, 1e9, 1e11):
        got = clamped_hinge_clamped(stiffness).whirl_frequencies(0.0, 3).forward
        assert np.all(got >= previous - 1e-9 * got)  # a stiffer joint never lowers a frequency
        previous = got
    # the joint's compliance 1/k against the half-span's L/(2 EI) = 1.9e-5 rad/(N m):
    # measured 2.7e-7 at k = 1e11 N m/rad; 1e-6
    np.testing.assert_allclose(previous, rigid, rtol=1e-6)
    np.testing.assert_allclose(clamped_hinge_clamped(1e-6).whirl_frequencies(0.0, 3).forward, free, rtol=1e-9)


@pytest.mark.parametrize("spin", [0.0, 800.0, 2500.0])
def test_hinged_two_piece_matches_finite_elements(spin):
    # Spinning, with joint masses and bearings: same root count and values as the FE
    # model (measured <= 1.7e-8 for four modes of each sense at 40 elements; 1e-6), with
    # Rayleigh tubes (the FE check then converges as h**4).
    d = rayleigh(hinged_two_piece())
    wf = d.whirl_frequencies(spin, 4)
    fe_f, fe_b = positive_fe(d, spin, 4)
    np.testing.assert_allclose(wf.forward, fe_f, rtol=1e-6, atol=0.0)
    np.testing.assert_allclose(wf.backward, fe_b, rtol=1e-6, atol=0.0)


def test_anisotropic_path_with_a_hinge_reduces_to_isotropic():
    d = hinged_two_piece()
    d8 = Driveline(d.segments, d.masses, d.bearings, joints=d.joints)
    object.__setattr__(d8, "_chain", dataclasses.replace(d._chain, isotropic=False))
    w4, w8 = d.whirl_frequencies(800.0, 3), d8.whirl_frequencies(800.0, 3)
    # same exact roots from the 4x4 and 8x8 determinants: root tolerance plus margin, 1e-10
    np.testing.assert_allclose(w8.forward, w4.forward, rtol=1e-10)
    np.testing.assert_allclose(w8.backward, w4.backward, rtol=1e-10)


def test_hinge_lowers_the_critical_speeds_of_the_two_piece_shaft():
    rigid = load_driveline(example_path("two_piece_propshaft")).critical_speeds(3)
    hinged = hinged_two_piece().critical_speeds(3)
    assert np.all(hinged < rigid)


def test_hinge_validation():
    with pytest.raises(ValueError, match="inner node"):
        Driveline([half_span(), half_span()], joints=[Hinge(2)])
    with pytest.raises(ValueError, match="bending_stiffness"):
        Hinge(1, -1.0)
    with pytest.raises(ValueError, match="free hinge"):
        Hinge(1).transfer_matrix(100.0)



def test_fmu_analyses_a_hinged_layout(fmu_path, fmi):
    result = simulate(fmu_path("CriticalSpeeds", fmi), 0.02, 0.01, start_values={"layout": "two_piece_propshaft_hinged"})
    expected = hinged_two_piece().critical_speeds(3)
    # the same computation inside the FMU: identical numbers
    np.testing.assert_array_equal([result[f"omega_crit_{k}"][-1] for k in (1, 2, 3)], expected)
