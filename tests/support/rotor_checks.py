"""Reference solutions shared by the rotor tests."""

from __future__ import annotations

import dataclasses

import numpy as np
from hypothesis import strategies as st

from driveline.rotor import Bearing, ConcentratedMass, Driveline, ShaftSegment


def rigid_body_whirl(stiffness: np.ndarray, mass: float, diametral: float, polar: float, spin: float
                     ) -> tuple[np.ndarray, np.ndarray]:
    """(forward, backward) whirl frequencies of a 2-dof body q = [U, psi] on springs:
    ``(K + w Omega G - w^2 M) q = 0`` with M = diag(m, Jd), G = diag(0, Jp), as the real
    eigenvalues of its first-order form; both ascending, in rad/s."""
    inverse_mass = np.linalg.inv(np.diag([mass, diametral]))
    gyroscopic = np.diag([0.0, polar])
    system = np.block([[np.zeros((2, 2)), np.eye(2)], [inverse_mass @ stiffness, spin * inverse_mass @ gyroscopic]])
    eigenvalues = np.sort(np.linalg.eigvals(system).real)
    return eigenvalues[eigenvalues > 0], -eigenvalues[eigenvalues < 0][::-1]


def damped_transfer_chain(driveline, w: complex, spin: float, force: tuple[int, complex] | None = None
                          ) -> tuple[np.ndarray, list[np.ndarray]]:
    """Transfer-matrix reference for the damped analyses (free ends, no hinges): the 8x8 complex
    chain on ``[s_a, conj(s_b)]`` at the complex whirl frequency ``w``, plain products of
    ``expm`` field matrices (low modes only). Returns the end-condition minor ``C_R P B_L`` (4x4)
    and, with ``force = (node, F)`` (a forward point force ``F`` at ``w = spin``), the states at every node."""
    from scipy.linalg import expm

    def field(segment, freq: complex) -> np.ndarray:
        rho_i = segment.density * segment.second_moment
        couple = rho_i * (freq * freq - 2.0 * spin * freq)
        a = np.zeros((4, 4), dtype=complex)
        a[0, 1], a[1, 2], a[2, 1], a[2, 3] = 1.0, 1.0 / segment.bending_stiffness, -couple, 1.0
        a[3, 0] = segment.mass_per_length * freq * freq
        if segment.shear:
            a[0, 3] = -1.0 / segment.shear_stiffness
        return expm(a * segment.length)

    def points(node: int) -> np.ndarray:
        p = np.eye(8, dtype=complex)
        for mass in (m for m in driveline.masses if m.node == node):
            for offset, freq in ((0, w), (4, -w)):
                q = np.eye(8, dtype=complex)
                q[offset + 3, offset] = mass.mass * freq * freq
                q[offset + 2, offset + 1] = -(mass.diametral_inertia * freq * freq - mass.polar_inertia * spin * freq)
                p = q @ p
        for bearing in (b for b in driveline.bearings if b.node == node):
            p = bearing.damped_transfer_matrix_pair(w)[0] @ p
        return p

    basis = np.zeros((9, 5), dtype=complex)  # columns: U, psi of both components at the left end; the load
    basis[[0, 1, 4, 5], [0, 1, 2, 3]] = 1.0
    basis[8, 4] = 1.0
    states = []
    for node in range(len(driveline.segments) + 1):
        step = np.eye(9, dtype=complex)
        step[:8, :8] = points(node)
        if force is not None and force[0] == node:
            step[3, 8] = force[1]
        basis = step @ basis
        states.append(basis)
        if node < len(driveline.segments):
            seg = driveline.segments[node]
            step = np.eye(9, dtype=complex)
            step[:4, :4], step[4:8, 4:8] = field(seg, w), field(seg, -w)
            basis = step @ basis
    minor = basis[[2, 3, 6, 7], :4]
    if force is None:
        return minor, []
    coefficients = np.append(np.linalg.solve(minor, -basis[[2, 3, 6, 7], 4]), 1.0)
    return minor, [s @ coefficients for s in states]


def response_peaks(rotor, spins: np.ndarray, position: float) -> tuple[np.ndarray, np.ndarray]:
    """Speeds and values of the local maxima of the orbit's major semi-axis at ``position`` for the
    driveline's unbalances (``rotor``: a ``DampedRotor``), found on ``spins`` and refined to 1e-9."""
    from scipy.optimize import minimize_scalar

    major = rotor.unbalance_response(spins, positions=[position]).major[:, 0]
    inner = np.flatnonzero((major[1:-1] > major[:-2]) & (major[1:-1] >= major[2:])) + 1

    def negative(spin: float) -> float:
        return -rotor.unbalance_response([spin], positions=[position]).major[0, 0]

    found = [minimize_scalar(negative, bracket=tuple(spins[i - 1: i + 2]), tol=1e-9) for i in inner]
    return np.array([f.x for f in found]), -np.array([f.fun for f in found])


def rayleigh(driveline):
    """``driveline`` with Rayleigh segments (no shear): its FE error falls as h**4, not h**2."""
    return dataclasses.replace(driveline, segments=[dataclasses.replace(s, shear=False) for s in driveline.segments])


@st.composite
def drivelines(draw: st.DrawFn) -> Driveline:
    """Random layouts of one to three segments, masses at random nodes, bearings at both ends (no
    rigid-body modes at zero frequency) and at random inner nodes."""
    n_seg = draw(st.integers(1, 3))
    segs = []
    for _ in range(n_seg):
        od = draw(st.floats(0.02, 0.12))
        segs.append(ShaftSegment(draw(st.floats(0.15, 1.6)), od, od * draw(st.floats(0.0, 0.95))))
    nodes = range(n_seg + 1)
    masses = [
        ConcentratedMass(n, draw(st.floats(0.0, 10.0)), draw(st.floats(0.0, 0.05)), draw(st.floats(0.0, 0.05)))
        for n in nodes if draw(st.booleans())
    ]
    bearings = [Bearing(0, draw(st.floats(1e5, 1e9))), Bearing(n_seg, draw(st.floats(1e5, 1e9)))]
    bearings += [Bearing(n, draw(st.floats(1e4, 1e9))) for n in range(1, n_seg) if draw(st.booleans())]
    return Driveline(segs, masses, bearings)
