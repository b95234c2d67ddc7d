"""Random PowertrainMounts layouts for the tests: a cloud of point masses and random mounts."""

from __future__ import annotations

import numpy as np
from scipy.stats import special_ortho_group


def _toml_list(values) -> str:
    return "[" + ", ".join(repr(float(v)) for v in values) + "]"


def random_layout(rng: np.random.Generator, mounts: int) -> tuple[str, np.ndarray, np.ndarray, list]:
    """TOML text of a random layout, with its point masses and mounts for the reference."""
    points = rng.uniform(-0.4, 0.4, (7, 3)) + rng.uniform(-1.0, 1.0, 3)
    masses = rng.uniform(5.0, 50.0, 7)
    centre = masses @ points / masses.sum()
    rel = points - centre
    moment = lambda a, b: float(np.sum(masses * rel[:, a] * rel[:, b]))  # noqa: E731
    Ixx, Iyy, Izz = (moment(1, 1) + moment(2, 2), moment(0, 0) + moment(2, 2), moment(0, 0) + moment(1, 1))
    inertia = [Ixx, Iyy, Izz, moment(0, 1), moment(0, 2), moment(1, 2)]  # products: int x y dm
    text = [f"mass = {float(masses.sum())!r}", f"centre_of_gravity = {_toml_list(centre)}",
            f"inertia = {_toml_list(inertia)}"]
    table = []
    for _ in range(mounts):
        position = centre + rng.uniform(-0.6, 0.6, 3)
        stiffness = rng.uniform(2e4, 4e5, 3)
        axes = special_ortho_group.rvs(3, random_state=rng)
        damping = rng.uniform(0.0, 800.0, 3)
        table.append((position, stiffness, axes, damping))
        text += ["[[mounts]]", f"position = {_toml_list(position)}", f"stiffness = {_toml_list(stiffness)}",
                 "orientation = [" + ", ".join(_toml_list(row) for row in axes) + "]",
                 f"damping = {_toml_list(damping)}"]
    return "\n".join(text), points, masses, table


def _hessian(energy, n: int = 6) -> np.ndarray:
    """Matrix of the quadratic form ``energy`` (= v^T H v / 2) by polarisation."""
    e = np.eye(n)
    h = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            h[i, j] = energy(e[i] + e[j]) - energy(e[i]) - energy(e[j]) if i != j else 2.0 * energy(e[i])
    return h


def reference_matrices(points, masses, mounts) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mass, stiffness and damping matrices of a :func:`random_layout` as the Hessians of the kinetic
    energy of its points, the mounts' potential energy and their dissipation function, each mount's
    displacement ``t + theta x (p - c)`` from the cross product."""
    centre = masses @ points / masses.sum()

    def kinetic(v):
        return sum(0.5 * m * np.sum((v[:3] + np.cross(v[3:], p - centre)) ** 2) for m, p in zip(masses, points))

    def mount_form(index):
        def form(q):
            total = 0.0
            for mount in mounts:
                position, axes, rates = mount[0], mount[2], mount[index]
                moved = q[:3] + np.cross(q[3:], position - centre)
                total += 0.5 * sum(k * (axis @ moved) ** 2 for k, axis in zip(rates, axes))
            return total
        return form

    return _hessian(kinetic), _hessian(mount_form(1)), _hessian(mount_form(3))
