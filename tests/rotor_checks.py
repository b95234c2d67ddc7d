"""Reference solutions shared by the rotor tests."""

from __future__ import annotations

import numpy as np


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
