"""The frictionless tripod mechanism sampled over one turn, for the reaction and friction tests: the
Newton closure of driveline.tripod.exact differentiated spectrally (a second path to the reactions,
independent of driveline.tripod.reactions), and the exact reactions over the same samples."""

from __future__ import annotations

import math

import numpy as np

from driveline.tripod import exact, geometry, plane_solver
from driveline.tripod.reactions import exact_reactions

R, L, M = 0.026, 0.700, 0.2
OMEGA = 2000.0 * math.pi / 30.0
SAMPLES = 240
PHI = np.linspace(0.0, 2.0 * np.pi, SAMPLES, endpoint=False)
EZ = np.array([0.0, 0.0, 1.0])


def spectral_derivatives(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives in phi of 2 pi periodic samples (along axis 0)."""
    harmonic = np.fft.rfftfreq(len(values), d=1.0 / len(values))[:, None]
    spectrum = np.fft.rfft(values, axis=0)
    first = np.fft.irfft(1j * harmonic * spectrum, n=len(values), axis=0)
    return first, np.fft.irfft(-(harmonic**2) * spectrum, n=len(values), axis=0)


def reactions_over_a_turn(beta: float, omega: float, omega_dot: float, T_load: float, r: float = R, l: float = L):
    phi_out, ratio, solution = plane_solver.solve(PHI, np.full_like(PHI, beta), r, l)
    return exact_reactions(PHI, beta, omega, omega_dot, T_load, r, l, M, solution.x, solution.y)


class Mechanism:
    """Pose quantities from the Newton closure (exact.py), in the input frame."""

    def __init__(self, beta: float, r: float = R, l: float = L):
        pose = exact.exact_pose(PHI, beta, r, l)
        self.beta = beta
        angles = PHI[:, None] + geometry.THIRD_TURN * geometry.ARM_INDEX
        self.z = pose.plunger_positions
        self.dz, self.d2z = spectral_derivatives(self.z)
        self.balls = np.stack([r * np.cos(angles), r * np.sin(angles), self.z], axis=-1)
        self.S = l * np.array([-np.sin(beta), 0.0, np.cos(beta)])
        self.U = (self.S - pose.tripod_centre) / l
        nominal = np.tile(np.eye(3)[:2], (len(PHI), 1, 1))
        E = exact._bend_apply(np.full(len(PHI), beta), exact._swing_apply(pose.swing, nominal))
        self.E1, self.E2 = E[:, 0], E[:, 1]
        self.r = r

    def accelerations(self, omega: float, omega_dot: float) -> np.ndarray:
        """Ball-centre accelerations (samples, 3 arms, 3)."""
        radial = self.balls.copy()
        radial[..., 2] = 0.0
        tangential = np.cross(EZ, radial)
        axial = self.d2z * omega**2 + self.dz * omega_dot
        return -omega**2 * radial + omega_dot * tangential + axial[..., None] * EZ

    def kinetic_energy_rate(self, omega: float, omega_dot: float) -> np.ndarray:
        zdot = self.dz * omega
        zddot = self.d2z * omega**2 + self.dz * omega_dot
        return M * (3 * self.r**2 * omega * omega_dot + np.sum(zdot * zddot, axis=1))

    def output_bearing_force(self, f) -> np.ndarray:
        return f.Rx_out[:, None] * self.E1 + f.Ry_out[:, None] * self.E2 + f.Rz_out[:, None] * self.U
