"""Gyroscopic coupling: sign and size, Campbell data, critical speeds, anisotropy."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.rotor import (
    Bearing,
    ConcentratedMass,
    Driveline,
    ShaftSegment,
    one_piece_shaft,
)

from support import rotor_checks


def tube() -> Driveline:
    return one_piece_shaft(1.4, 0.0762, 0.0729, 2.1e11, 7850.0, 2.5, 0.004, 0.002, 1e7)


def overhung_disk(Jp: float, Jd: float) -> Driveline:
    """Cantilever with a disk at its tip: the classic case with a strong gyroscopic effect."""
    seg = ShaftSegment(0.5, 0.03, 0.0, rotary_inertia=False, gyroscopic=False)
    return Driveline([seg], [ConcentratedMass(1, 5.0, Jp, Jd)], left="clamped", right="free")


def test_forward_rises_backward_falls_with_spin():
    d = tube()
    cd = d.campbell([0.0, 500.0, 1000.0, 2000.0, 4000.0], n_modes=4)
    # strictly monotone in spin for every mode (gyroscopic stiffening / softening)
    assert np.all(np.diff(cd.forward, axis=0) > 0)
    assert np.all(np.diff(cd.backward, axis=0) < 0)
    # at standstill both branches coincide
    assert np.array_equal(cd.forward[0], cd.backward[0])


def test_gyroscopic_size_overhung_disk():
    # Massless cantilever (stiffness matrix from EB beam) with a tip disk: the whirl
    # frequencies solve det(K - w^2 M + w Omega G) = 0 with q = [U, psi] at the tip.
    # A 2x2 problem, solved here in closed form: this checks the size of the
    # Jp*Omega*w term, not only its sign. Massless shaft -> exact up to round-off.
    Jp, Jd, m = 0.05, 0.025, 5.0
    seg = ShaftSegment(0.5, 0.03, 0.0, density=1e-9, rotary_inertia=False, gyroscopic=False)
    EI, L = seg.bending_stiffness, seg.length
    # tip flexibility of a cantilever: [[L^3/3, L^2/2], [L^2/2, L]] / EI
    K = np.linalg.inv(np.array([[L**3 / 3, L**2 / 2], [L**2 / 2, L]]) / EI)
    d = Driveline([seg], [ConcentratedMass(1, m, Jp, Jd)], left="clamped", right="free")
    for spin in (0.0, 300.0, 1500.0):
        forward, backward = rotor_checks.rigid_body_whirl(K, m, Jd, Jp, spin)
        wf = d.whirl_frequencies(spin, 2)
        # 1e-7: the 1e-9 kg/m3 shaft density adds mass of ~1e-12 relative.
        assert np.allclose(wf.forward, forward, rtol=1e-7)
        assert np.allclose(wf.backward, backward, rtol=1e-7)


def test_gyroscopic_term_sign_via_polar_inertia_only():
    # With Jd = 0 the disk moment is -Jp*Omega*w*psi: forward (w > 0) stiffens,
    # backward (w < 0) softens. Doubling Jp must widen the split.
    split = []
    for Jp in (0.02, 0.04):
        wf = overhung_disk(Jp, 0.0).whirl_frequencies(800.0, 2)
        assert np.all(wf.forward > wf.backward)
        split.append(wf.forward[0] - wf.backward[0])
    assert split[1] > split[0] > 0


def test_synchronous_forward_critical_lies_on_forward_branch():
    # critical speed = spin speed where the forward branch crosses w = Omega;
    # 1e-9: both are brentq roots of exact determinants.
    d = tube()
    for cs in d.critical_speeds(2):
        wf = d.whirl_frequencies(cs, 4)
        assert np.min(np.abs(wf.forward - cs)) <= 1e-9 * cs


def test_backward_critical_lies_on_backward_branch():
    d = tube()
    for cs in d.critical_speeds(2, whirl="backward"):
        wf = d.whirl_frequencies(cs, 4)
        assert np.min(np.abs(wf.backward - cs)) <= 1e-9 * cs


def test_thin_disk_limit_rayleigh_matches_seed_mass_matrix():
    # For Jp = 2 Jd (the only case the seed's Eq. 25 covers) our point matrix
    # reduces to the seed's: M+ - M- = -(Jd w^2 - 2 Jd Omega w) psi.
    m = ConcentratedMass(0, 1.0, 0.004, 0.002)
    w, spin = 321.0, 123.0
    P = m.transfer_matrix(w, spin)[0]
    # the same arithmetic: equal to round-off (1e-15)
    assert P[2, 1] == pytest.approx(-(0.002 * w * w - 0.004 * spin * w), rel=1e-15)


# -- anisotropic bearings (8x8 forward/backward state) ---------------------------
def test_anisotropic_at_standstill_splits_into_two_planes():
    # At Omega = 0 the x and y planes decouple: the frequencies are those of the
    # isotropic rotor with k = kxx together with those with k = kyy (1e-10).
    seg = ShaftSegment(1.4, 0.0762, 0.0729)
    masses = [ConcentratedMass(0, 2.5, 0.004, 0.002), ConcentratedMass(1, 2.5, 0.004, 0.002)]
    aniso = Driveline([seg], masses, [Bearing(0, 1e7, 3e6), Bearing(1, 1e7, 3e6)])
    assert not aniso.is_isotropic
    x = Driveline([seg], masses, [Bearing(0, 1e7), Bearing(1, 1e7)]).whirl_frequencies(0.0, 4).forward
    y = Driveline([seg], masses, [Bearing(0, 3e6), Bearing(1, 3e6)]).whirl_frequencies(0.0, 4).forward
    got = aniso.whirl_frequencies(0.0, 6).forward
    assert np.allclose(got, np.sort(np.r_[x, y])[:6], rtol=1e-10)


def test_anisotropic_path_reduces_to_isotropic():
    # kxx = kyy through the 8x8 path (forced) equals the 4x4 forward/backward results.
    import dataclasses

    d = tube()
    d8 = Driveline(d.segments, d.masses, d.bearings)
    object.__setattr__(d8, "_chain", dataclasses.replace(d._chain, isotropic=False))
    spin = 900.0
    w4, w8 = d.whirl_frequencies(spin, 3), d8.whirl_frequencies(spin, 3)
    # same exact roots from two determinants: root tolerance plus margin, 1e-10
    assert np.allclose(w4.forward, w8.forward, rtol=1e-10)
    assert np.allclose(w4.backward, w8.backward, rtol=1e-10)
    assert np.allclose(d.critical_speeds(2), d8.critical_speeds(2), rtol=1e-10)


def test_anisotropic_modes_are_classified():
    seg = ShaftSegment(1.4, 0.0762, 0.0729)
    masses = [ConcentratedMass(0, 2.5, 0.004, 0.002), ConcentratedMass(1, 2.5, 0.004, 0.002)]
    d = Driveline([seg], masses, [Bearing(0, 1e7, 9e6), Bearing(1, 1e7, 9e6)])
    wf = d.whirl_frequencies(3000.0, 2)
    assert wf.forward.size == 2 and wf.backward.size == 2
    for w in wf.forward:
        assert d.mode_shape(w, 3000.0).forward_fraction > 0.5
    for w in wf.backward:
        assert d.mode_shape(w, 3000.0).forward_fraction < 0.5


def test_mode_shape_of_pinned_beam_is_a_sine():
    seg = ShaftSegment(1.0, 0.04, 0.0)
    d = Driveline([seg], left="pinned", right="pinned")
    w2 = d.whirl_frequencies(500.0, 2).forward[1]
    ms = d.mode_shape(w2, 500.0, points_per_segment=20)
    ref = np.sin(2 * math.pi * ms.z / seg.length)
    sign = np.sign(np.dot(ms.forward, ref))
    # normalised shapes; 1e-8 from the root tolerance of w2
    assert np.allclose(sign * ms.forward, ref, atol=1e-8)
    assert ms.forward_fraction == 1.0
