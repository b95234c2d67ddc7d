"""The mounts' forces on the powertrain: elastic characteristics, viscous dampers, Maxwell branches.

Mount i's axes see the deflection ``d_i = A_i T(p_i) Q`` (``Layout.maps``) of the body's displacement ``Q`` from the
unloaded mounts (:mod:`.rigid_body`). Its elastic force along them is the characteristic
``F_i(d_i)`` (:mod:`.characteristic`), its viscous force ``c_i d_i'``, its branches' forces
``sum_j z_ij`` (:mod:`.rubber`); the generalised force of the mounts on the body is
``-sum_i T_i^T A_i^T (F_i + c_i d_i' + sum_j z_ij)``.

The static equilibrium under a generalised load f solves ``sum_i T_i^T A_i^T F_i(A_i T_i Q) = f`` by
Newton's method with the exact Jacobian, the tangent stiffness
``K_t(Q) = sum_i T_i^T A_i^T diag(F_i'(d_i)) A_i T_i`` (positive definite when the mounts hold the
body and the characteristics are monotonic, so the root is unique), halving a step that does not
lower the residual.
"""

from __future__ import annotations

import numpy as np

from . import characteristic
from .layout import MAX_MOUNTS, Layout, Mount
from .rubber import BRANCHES, relaxation_times

#: Model Exchange's branch states: one slot a mount of the most a layout holds, an axis and a branch (mount, then
#: axis, then branch), those of mounts without rubber (or beyond the layout's) idle at 0
BRANCH_SLOTS = MAX_MOUNTS * 3 * BRANCHES

#: Newton's iterations at most, and the step (relative to the displacement) it stops at (the static
#: equilibrium here and the implicit step's, :mod:`.implicit_step`).
MAX_NEWTON = 60
NEWTON_STEP = 1e-14
#: The implicit step keeps its Jacobian's factors for the next iteration when a correction is at most this
#: fraction of the one before (the simplified Newton method's contraction), else computes it again.
NEWTON_CONTRACTION = 0.1


def _law(mount: Mount) -> tuple[np.ndarray, ...]:
    return mount.stiffness, mount.gap, mount.stop_rate, np.full(3, mount.stop_blend)


def elastic_forces(layout: Layout, q: np.ndarray) -> list[np.ndarray]:
    """Each mount's elastic force along its axes at the displacement ``q`` from the unloaded mounts."""
    return [characteristic.force(to_axes @ q, *_law(m)) for m, to_axes in zip(layout.mounts, layout.maps)]


def elastic_load(layout: Layout, q: np.ndarray) -> np.ndarray:
    """``sum_i T_i^T A_i^T F_i(d_i)``: the generalised elastic force of the mounts (against the body)."""
    return sum(to_axes.T @ f for to_axes, f in zip(layout.maps, elastic_forces(layout, q)))


def tangent_stiffness(layout: Layout, q: np.ndarray) -> np.ndarray:
    """``K_t(q)``, the derivative of :func:`elastic_load`."""
    found = np.zeros((6, 6))
    for m, to_axes in zip(layout.mounts, layout.maps):
        found += to_axes.T @ (characteristic.tangent(to_axes @ q, *_law(m))[:, None] * to_axes)
    return found


def elastic_energy(layout: Layout, q: np.ndarray) -> float:
    """The mounts' elastic energy at ``q`` (from the unloaded mounts)."""
    return float(sum(np.sum(characteristic.energy(to_axes @ q, *_law(m)))
                     for m, to_axes in zip(layout.mounts, layout.maps)))


def mean_elastic_load(layout: Layout, q0: np.ndarray, q1: np.ndarray,
                      with_jacobian: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
    """The discrete gradient of the elastic energy between ``q0`` and ``q1`` (its generalised force,
    whose product with ``q1 - q0`` is the energy's change) and its Jacobian by ``q1`` (None unless
    ``with_jacobian``)."""
    load, jacobian = np.zeros(6), np.zeros((6, 6)) if with_jacobian else None
    for m, to_axes in zip(layout.mounts, layout.maps):
        d0, d1 = to_axes @ q0, to_axes @ q1
        mean, slope = characteristic.mean_force(d0, d1, *_law(m))
        load += to_axes.T @ mean
        if with_jacobian:
            jacobian += to_axes.T @ (slope[:, None] * to_axes)
    return load, jacobian


def equilibrium(layout: Layout, load: np.ndarray, linear_stiffness: np.ndarray) -> np.ndarray:
    """``Q`` with ``elastic_load(Q) = load`` (Newton from the linear rates' solution); ArithmeticError
    when it does not converge or leaves the range of numbers (numpy's overflow warnings are silenced
    here: the non-finite residual is the refusal's reason)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return _newton(layout, load, np.linalg.solve(linear_stiffness, load))


def _newton(layout: Layout, load: np.ndarray, q: np.ndarray) -> np.ndarray:
    residual = elastic_load(layout, q) - load
    for _ in range(MAX_NEWTON):
        if not np.all(np.isfinite(residual)):
            raise ArithmeticError("the static equilibrium is beyond the range of numbers (a load near 1e300)")
        step = np.linalg.solve(tangent_stiffness(layout, q), -residual)
        size = 1.0
        while True:
            trial = q + size * step
            trial_residual = elastic_load(layout, trial) - load
            if np.linalg.norm(trial_residual) < np.linalg.norm(residual) or size < 1e-6:
                break
            size *= 0.5
        q, residual = trial, trial_residual
        if np.max(np.abs(size * step)) <= NEWTON_STEP * max(np.max(np.abs(q)), 1e-300):
            return q
    raise ArithmeticError(f"no static equilibrium found in {MAX_NEWTON} Newton steps")


class BranchMap:
    """The Maxwell branches of the rubber mounts, one row each (mount, then axis, then branch):
    ``rows`` (n x 6) the deflection rate it sees from q', ``gains`` ``w_j F'(d_op)`` [N/m] (the weight
    times the tangent rate at the operating point ``operating``, Q from the unloaded mounts: the
    linear rate k without a stop), ``times`` tau_j [s]. Their forces ``z`` enter as ``-rows^T z``
    and move by ``z' = gains (rows q') - z / times``. ``slots``: each branch's place among Model
    Exchange's :data:`BRANCH_SLOTS` states (``(3 mount + axis) BRANCHES + branch``)."""

    def __init__(self, layout: Layout, operating: np.ndarray):
        rows, gains, times, slots = [], [], [], []
        tau = relaxation_times()
        for n, (m, to_axes) in enumerate(zip(layout.mounts, layout.maps)):
            if not len(m.branches):
                continue
            rates = characteristic.tangent(to_axes @ operating, *_law(m)) if m.progressive else m.stiffness
            for k in range(3):
                for j, weight in enumerate(m.branches):
                    rows.append(to_axes[k])
                    gains.append(weight * rates[k])
                    times.append(tau[j])
                    slots.append((3 * n + k) * BRANCHES + j)
        self.rows = np.array(rows).reshape(-1, 6)
        self.gains = np.array(gains)
        self.times = np.array(times)
        self.slots = np.array(slots, dtype=int)

    def __len__(self) -> int:
        return len(self.gains)

    def stiffness(self, frequency: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The branches' storage and loss stiffness matrices (6 x 6) at ``frequency`` [Hz], and the
        storage's slope ``w dK_s/dw`` (``x = w tau``: ``g x^2 / (1 + x^2)``, ``g x / (1 + x^2)``,
        ``2 g x^2 / (1 + x^2)^2``)."""
        x = 2.0 * np.pi * frequency * self.times
        storage = self.gains * x * x / (1.0 + x * x)
        loss = self.gains * x / (1.0 + x * x)
        slope = 2.0 * self.gains * x * x / (1.0 + x * x) ** 2
        return tuple(self.rows.T @ (part[:, None] * self.rows) for part in (storage, loss, slope))

    def per_mount(self, layout: Layout, z: np.ndarray) -> list[np.ndarray]:
        """Each mount's branch forces summed along its axes."""
        found, start = [], 0
        for m in layout.mounts:
            count = 3 * len(m.branches)
            found.append(z[start:start + count].reshape(3, -1).sum(axis=1) if count else np.zeros(3))
            start += count
        return found
