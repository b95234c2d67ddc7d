"""PowertrainMounts' exact time stepping against scipy's solve_ivp and against its energy balance.

The reference integrates ``M q'' + C q' + K q = f(t)`` with matrices assembled independently
(the energy Hessians of tests/support/mount_layouts.py) by DOP853 at rtol 1e-11, one solve per
step so that the kinks of the piecewise-linear force lie on its step ends; the model steps
through the same force, its inputs F_x..M_z and their rates (first-order hold).
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.polynomial.legendre import leggauss
from scipy.integrate import solve_ivp

from driveline.mounts.exact_step import MAX_SQUARINGS, Propagator, state_matrices, work_error
from driveline.mounts.layout import loads_layout
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES, RigidBody
from driveline.mounts.spec import LOAD_INPUTS, derivative_name
from support.mount_layouts import random_layout, reference_matrices

STEPS = 120


def _forces(rng: np.random.Generator, steps: int) -> np.ndarray:
    """Random knot values of the generalised force: up to 2 kN and 300 N m."""
    return rng.uniform(-1.0, 1.0, (steps + 1, 6)) * np.array([2e3, 2e3, 2e3, 3e2, 3e2, 3e2])


def _model(tmp_path, text: str) -> PowertrainMountsModel:
    path = tmp_path / "layout.toml"
    path.write_text(text)
    model = PowertrainMountsModel()
    model.layout = str(path)
    return model


def _set_inputs(model: PowertrainMountsModel, force: np.ndarray, rate: np.ndarray) -> None:
    for name, value, slope in zip(LOAD_INPUTS, force, rate):
        setattr(model, name, float(value))
        setattr(model, derivative_name(name), float(slope))


@pytest.mark.parametrize("seed, h", [(0, 1e-3), (1, 1e-3), (2, 5e-4), (3, 1e-4), (4, None)])
def test_transient_agrees_with_solve_ivp(tmp_path, seed, h):
    """Within 1e-8 of the largest displacement (first-order hold; measured 9.2e-14 at most, the
    reference's own error at rtol 1e-11 well below the bound). ``h`` None: every step of a random
    size from 1e-4 to 1e-3 s, so that the propagator is built again at each."""
    rng = np.random.default_rng(seed)
    sizes = rng.uniform(1e-4, 1e-3, STEPS) if h is None else np.full(STEPS, h)
    text, points, masses, mounts = random_layout(rng, int(rng.integers(3, 9)))
    mass, stiffness, damping = reference_matrices(points, masses, mounts)
    forces = _forces(rng, STEPS)
    model = _model(tmp_path, text)
    _set_inputs(model, forces[0], np.zeros(6))
    assert model.initialize(0.0) == []
    state = np.concatenate([np.linalg.solve(stiffness, forces[0]), np.zeros(6)])
    inverse = np.linalg.inv(mass)
    found, expected = [], []
    for k, h in enumerate(sizes):
        slope = (forces[k + 1] - forces[k]) / h
        _set_inputs(model, forces[k], slope)
        assert model.step(float(np.sum(sizes[:k])), float(h)) == []

        def rhs(t, s, f0=forces[k], f1=slope):
            q, v = s[:6], s[6:]
            return np.concatenate([v, inverse @ (f0 + f1 * t - damping @ v - stiffness @ q)])

        state = solve_ivp(rhs, (0.0, h), state, method="DOP853", rtol=1e-11, atol=1e-16).y[:, -1]
        found.append([getattr(model, name) for name in COORDINATES])
        expected.append(state[:6])
    found, expected = np.array(found), np.array(expected)
    scale = np.max(np.abs(expected), axis=0)
    assert np.max(np.abs(found - expected) / scale) < 1e-8


@pytest.mark.parametrize("seed", range(3))
def test_energy_balance(seed):
    """Input work = stored energy + dissipated energy within 1e-9 relative: the work and the
    dissipation integrated along the propagated motion itself (10 Gauss-Legendre points per step,
    the state at each from a propagator of that sub-step), zero- then first-order hold; measured
    3.1e-15 at most."""
    rng = np.random.default_rng(100 + seed)
    text, *_ = random_layout(rng, 4)
    body = RigidBody.of(loads_layout(text))
    a, b = state_matrices(body)
    h = 1e-3
    nodes, weights = leggauss(10)
    taus, weights = 0.5 * h * (nodes + 1.0), 0.5 * h * weights
    inner = [Propagator.build(a, b, tau) for tau in taus]
    whole = Propagator.build(a, b, h)
    forces = _forces(rng, STEPS)

    def energy(s):
        return 0.5 * s[6:] @ body.mass @ s[6:] + 0.5 * s[:6] @ body.stiffness @ s[:6]

    for hold in (0.0, 1.0):
        state = rng.normal(size=12) * 1e-3
        start, work, dissipated = energy(state), 0.0, 0.0
        for k in range(STEPS):
            f0, f1 = forces[k], hold * (forces[k + 1] - forces[k]) / h
            for tau, weight, propagator in zip(taus, weights, inner):
                v = propagator.step(state, f0, f1)[6:]
                work += weight * (f0 + f1 * tau) @ v
                dissipated += weight * v @ body.damping @ v
            state = whole.step(state, f0, f1)
        assert abs(energy(state) - start + dissipated - work) < 1e-9 * max(abs(work), dissipated)


def test_a_step_beyond_the_work_bound_is_refused():
    """A step needing more than MAX_SQUARINGS squarings is refused with the reason; a long one within is taken."""
    body = RigidBody.of(loads_layout(random_layout(np.random.default_rng(7), 3)[0]))
    a, b = state_matrices(body)
    assert work_error(a, b, 10.0) is None
    message = work_error(a, b, 1e12)
    assert f"more than the {MAX_SQUARINGS} accepted" in message
    assert work_error(a, b, 1e305) == "a step of 1e+305 s overflows the matrix exponential's norm: take shorter steps"
