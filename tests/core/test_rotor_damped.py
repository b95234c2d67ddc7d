"""Bearing damping: damped whirl and unbalance response (finite elements) against the exact
transfer-matrix determinant and forced chain (``rotor_checks.damped_transfer_chain``)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.optimize import newton

from driveline.rotor import Bearing, Driveline, ShaftSegment, Unbalance, one_piece_shaft
from driveline.rotor.damped import DampedRotor
from driveline.rotor.fem import elements_by_length

from support.rotor_checks import damped_transfer_chain, response_peaks

TUBE = dict(L_shaft=1.4, D_outer=0.0762, D_inner=0.0729, E=2.1e11, density=7850.0,
            m_joint=2.5, Jp_joint=0.004, Jd_joint=0.002, k_bearing=1e7)
SPIN = 600.0


def tube(bearings: list[Bearing], cut: float | None = None, shear: bool = False) -> Driveline:
    """Rotor (b), Rayleigh tube (the FE error falls as h**4), on ``bearings`` (nodes 0 and the right end), optionally cut in two at ``cut`` [m]."""
    d = one_piece_shaft(**TUBE, shear=shear)
    seg = d.segments[0]
    if cut is None:
        return dataclasses.replace(d, bearings=bearings)
    segments = [dataclasses.replace(seg, length=cut), dataclasses.replace(seg, length=seg.length - cut)]
    masses = [dataclasses.replace(m, node=2 * m.node) for m in d.masses]
    return Driveline(segments, masses, [dataclasses.replace(b, node=2 * b.node) for b in bearings])


ISOTROPIC = [Bearing(0, 1e6, cxx=2e3), Bearing(1, 1e6, cxx=2e3)]
GENERAL = [Bearing(0, 1e7, 2e6, cxx=300.0, cyy=100.0, kxy=1e5, kyx=-2e5, cxy=10.0, cyx=30.0),
           Bearing(1, 1e7, 2e6, cxx=300.0)]


def test_bearing_components_are_the_complex_force():
    b = GENERAL[0]
    x, y = 0.3 - 0.2j, -0.7 + 0.4j  # any complex amplitudes: the identity is linear
    for matrix, (a, c) in (([[b.kxx, b.kxy], [b.kyx, b.k_yy]], b.stiffness_components),
                           ([[b.cxx, b.cxy], [b.cyx, b.c_yy]], b.damping_components)):
        fx, fy = np.array(matrix) @ [x.real, y.real]
        u = x.real + 1j * y.real
        assert a * u + c * np.conj(u) == pytest.approx(fx + 1j * fy, rel=1e-15)


def test_undamped_modes_are_the_whirl_frequencies():
    d = tube([Bearing(0, 1e7), Bearing(1, 1e7)])
    modes = DampedRotor(d, 80).modes(SPIN, 4)
    whirl = d.whirl_frequencies(SPIN, 2)
    assert [m.whirl for m in modes] == ["backward", "forward", "backward", "forward"]
    np.testing.assert_allclose([m.frequency for m in modes], np.sort(whirl.all), rtol=1e-7)
    assert max(abs(m.damping_ratio) for m in modes) < 1e-9  # round-off of the eigensolver


@pytest.mark.parametrize("bearings", [ISOTROPIC, GENERAL], ids=["isotropic", "anisotropic_cross_coupled"])
def test_damped_eigenvalues_are_roots_of_the_transfer_determinant(bearings):
    """FE eigenvalues (50 elements) against the exact complex roots: measured <= 1e-8 (h**4)."""
    d = tube(bearings)
    for mode in DampedRotor(d, 50).modes(SPIN, 4):
        root = newton(lambda w: np.linalg.det(damped_transfer_chain(d, w, SPIN)[0]), -1j * mode.eigenvalue,
                      tol=1e-12, maxiter=50)
        assert abs(1j * root - mode.eigenvalue) <= 1e-8 * abs(mode.eigenvalue)
        assert mode.log_decrement == pytest.approx(2 * np.pi * mode.damping_ratio / np.sqrt(1 - mode.damping_ratio**2))


@pytest.mark.parametrize("bearings", [ISOTROPIC, GENERAL], ids=["isotropic", "anisotropic_cross_coupled"])
def test_unbalance_response_matches_the_transfer_chain(bearings):
    """Unbalance at an inner node, response at every node, bearing forces: measured <= 3e-9 (80 elements)."""
    d = tube(bearings, cut=0.5)
    unbalance = Unbalance(0.5, 2e-4, 0.7)
    spins = [300.0, 700.0, 1800.0]
    fe = DampedRotor(d, 80).unbalance_response(spins, [unbalance])
    for i, spin in enumerate(spins):
        force = unbalance.amount * spin**2 * np.exp(1j * unbalance.phase)
        _, states = damped_transfer_chain(d, spin, spin, (1, force))
        forward = np.array([s[0] for s in states])
        backward = np.array([s[4] for s in states]).conj()
        scale = np.max(np.abs(forward))
        np.testing.assert_allclose(fe.forward[i], forward, rtol=0, atol=1e-7 * scale)
        np.testing.assert_allclose(fe.backward[i], backward, rtol=0, atol=1e-7 * scale)
        for j, bearing in enumerate(d.bearings):
            jump = states[bearing.node]  # U is continuous across the node's point elements
            (ka, kb), (ca, cb) = bearing.stiffness_components, bearing.damping_components
            fa = (ka + 1j * spin * ca) * jump[0] + (kb + 1j * spin * cb) * jump[4]
            fq = (np.conj(kb) + 1j * spin * np.conj(cb)) * jump[0] + (np.conj(ka) + 1j * spin * np.conj(ca)) * jump[4]
            assert fe.bearing_forces[i, j] == pytest.approx(abs(fa) + abs(fq), rel=1e-7)


@pytest.mark.parametrize("kyy", [2e6, None], ids=["anisotropic", "isotropic"])
def test_critical_speeds_are_the_peaks_of_the_lightly_damped_response(kyy):
    """Rotor (b) on kxx = 1e7 N/m bearings, light damping (5 N s/m), unbalance off-centre: the
    response peaks at the critical speeds (anisotropic: 528.1, 653.3, 784.2, 1067.7 rad/s, of
    which the 0.5 forward-share rule kept only 653.3 and 1067.7). Measured: peaks within 2.2e-5
    (the damped peaks shift as c**2)."""
    bearings = [Bearing(n, 1e7, kyy, cxx=5.0) for n in (0, 1)]
    d = dataclasses.replace(tube(bearings), unbalances=[Unbalance(0.5, 1e-4)])
    critical = d.critical_speeds(4, spin_max=1200.0)
    peaks, _ = response_peaks(DampedRotor(d, 40), np.arange(300.0, 1200.0, 1.0), 0.3)
    np.testing.assert_allclose(peaks, critical, rtol=5e-5)
    if kyy:
        assert critical[0] == pytest.approx(528.1222, abs=1e-4)
        shares = [c.forward_share for c in d.unbalance_critical_speeds(4)]
        assert [c.whirl for c in d.unbalance_critical_speeds(4)] == ["backward", "forward", "backward", "forward"]
        assert min(shares) > 0.45


def test_short_segments_get_proportionally_fewer_elements():
    """A segment of half the length or longer gets the most, a shorter one a share (at least one),
    so a tube cut into 20 segments is meshed like a two-span shaft, not 20 times finer."""
    def tube(*lengths: float) -> Driveline:
        return Driveline([ShaftSegment(length, 0.0762, 0.0729) for length in lengths], [],
                         [Bearing(0, 1e7), Bearing(len(lengths), 1e7)])

    assert elements_by_length(tube(1.4), 16) == [16]
    assert elements_by_length(tube(*[0.07] * 20), 16) == [2] * 20
    assert elements_by_length(tube(0.7, 0.1, 0.8), 16) == [14, 2, 16]
    assert elements_by_length(tube(1.0, 1e-6), 16) == [16, 1]
