"""PowertrainMounts' continuous-time right-hand side (Model Exchange's): the ODE whose solution the steps take.

``MountSystem.derivatives`` is checked against the two steppers, which never call it: integrated by scipy's
DOP853 it gives the exponential's exact step on linear rubber mounts, and the implicit scheme's steps on the
progressive rubber layout converge to its solution at second order. Its Jacobian ``derivative_jacobian``
is checked against central differences of it.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from driveline.mounts.exact_step import Propagator
from driveline.mounts.forces import BRANCH_SLOTS
from driveline.mounts.implicit_step import implicit_step
from driveline.mounts.layout import shipped_layout
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rubber import BRANCHES
from driveline.mounts.spec import BRANCH_NOMINAL, TRANSLATION_NOMINAL

RUBBER = "transverse_fwd_powertrain_rubber"
#: A generalised load (N, N.m) that moves the body some millimetres, onto the stops of the rubber layout
LOAD = np.array([900.0, -600.0, 1500.0, 120.0, -700.0, 80.0])


def _system(layout: str, T_mean: float = 0.0):
    model = PowertrainMountsModel()
    model.layout, model.T_mean = layout, T_mean
    assert model.initialize(0.0) == []
    return model._system


def _linear_rubber(tmp_path) -> str:
    """The rubber layout without its snubbers: linear rates, the Maxwell branches kept."""
    text = shipped_layout(RUBBER).read_text()
    path = tmp_path / "rubber_linear.toml"
    path.write_text("\n".join(line for line in text.splitlines() if not line.startswith(("gap", "stop_rate"))))
    return str(path)


def _start(system, rng) -> np.ndarray:
    """A state off equilibrium: millimetres, tens of mm/s, branch forces of tens of N."""
    size = len(system.branches)
    return np.concatenate([rng.uniform(-2e-3, 2e-3, 6), rng.uniform(-5e-2, 5e-2, 6), rng.uniform(-50, 50, size)])


def test_integrated_it_gives_the_exact_step_on_linear_rubber(tmp_path):
    """From a state off equilibrium under a held load, 50 ms (a quarter period of the lowest mode): DOP853 at
    rtol 1e-12 on the right-hand side against the exponential's exact step, within 1e-10 of each part's
    largest value (the integrator's tolerance times the 10 to 100 error growth of its steps; measured 5.1e-14,
    2026-12-07)."""
    system = _system(_linear_rubber(tmp_path))
    assert not system.progressive and len(system.branches) == 36
    state = _start(system, np.random.default_rng(7))
    h = 0.05
    exact = Propagator.build(system.a, system.b, h).step(state, LOAD, np.zeros(6))
    found = solve_ivp(lambda t, s: system.derivatives(s, LOAD), (0.0, h), state, method="DOP853",
                      rtol=1e-12, atol=1e-18).y[:, -1]
    for part in (slice(0, 6), slice(6, 12), slice(12, None)):
        assert np.max(np.abs(found[part] - exact[part])) < 1e-10 * np.max(np.abs(exact[part]))


def test_the_implicit_steps_converge_to_its_solution_at_second_order():
    """The progressive rubber layout under the drive reaction (on its stops), 20 ms from a state off
    equilibrium: the implicit scheme's error against DOP853 (rtol 1e-12) of the right-hand side falls by 4
    (3.8 to 4.2: a second-order scheme's ratio, its h^3 terms some 1/20 of its h^2 ones at these steps, 1/40 of
    the highest mode's period) as the step halves from 1 ms to 0.5 ms to 0.25 ms (measured 3.992 and 3.998, the
    errors 5.8e-6 m to 3.6e-7 m); a scheme solving another ODE would stall at that ODE's distance."""
    system = _system(RUBBER, 1100.0)
    assert system.progressive
    state = _start(system, np.random.default_rng(11))
    force = LOAD + np.array([0.0, 0.0, 0.0, 0.0, -1100.0, 0.0])
    span = 0.02
    reference = solve_ivp(lambda t, s: system.derivatives(s, force), (0.0, span), state, method="DOP853",
                          rtol=1e-12, atol=1e-18).y[:, -1]
    errors = []
    for steps in (20, 40, 80):
        s = state
        for _ in range(steps):
            s, _ = implicit_step(system.body.layout, system.body.mass, system.body.damping, system.branches,
                                 system.weight, system.weight_sag, s, force, np.zeros(6), span / steps)
        errors.append(np.max(np.abs(s[:6] - reference[:6])))
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.8) & (ratios < 4.2)), ratios


@pytest.mark.parametrize("layout, torque", [("linear", 0.0), (RUBBER, 0.0), (RUBBER, 1100.0)])
def test_its_jacobian_is_exact(tmp_path, layout, torque):
    """``derivative_jacobian`` against central differences of ``derivatives`` (relative step 1e-6 of each
    state's part: 1e-9 m, 1e-8 m/s, 1e-5 N), within 1e-7 of each row's largest entry times its column's
    step: the differences' rounding, some eps |s'| / (row's entry times step), 1e-10 to 1e-8 of it (the
    accelerations sum forces 10 to 100 times their result), truncation step^2 |s'''| / 6, where a stop's blend
    (2 mm) bends the rate, step^2 / blend^2 = 2.5e-13 (measured 1.6e-9, 5.1e-9 and 8.6e-10, 2026-12-07); and
    the velocities' and branches' columns exactly ``a``'s."""
    system = _system(_linear_rubber(tmp_path) if layout == "linear" else layout, torque)
    sag = system.static_sag(9.81, torque) - system.weight_sag
    state = np.concatenate([sag, np.zeros(6 + len(system.branches))]) + 0.3 * _start(system, np.random.default_rng(3))
    exact = system.derivative_jacobian(state)
    scale = np.concatenate([np.full(6, 1e-3), np.full(6, 1e-2), np.full(len(system.branches), 10.0)])
    differences = np.empty_like(exact)
    for j, size in enumerate(1e-6 * scale):
        step = np.eye(len(state))[j] * size
        differences[:, j] = (system.derivatives(state + step, LOAD)
                             - system.derivatives(state - step, LOAD)) / (2 * size)
    bound = 1e-7 * np.max(np.abs(exact) * scale, axis=1, keepdims=True) / scale
    assert np.all(np.abs(exact - differences) <= bound)
    assert np.array_equal(exact[:, 6:], system.a[:, 6:])


def test_the_branch_slots_are_mount_axis_branch():
    """Model Exchange's slot of each branch: 3 axes of BRANCHES branches a mount, the layout's mounts in order,
    distinct and within the declared count."""
    system = _system(RUBBER)
    layout = system.body.layout
    expected = [(3 * n + k) * BRANCHES + j for n, m in enumerate(layout.mounts) if len(m.branches)
                for k in range(3) for j in range(BRANCHES)]
    assert list(system.branches.slots) == expected
    assert len(set(expected)) == len(expected) and max(expected) < BRANCH_SLOTS


def test_the_branch_states_nominal_is_a_branch_s_force_at_the_nominal_deflection():
    """``BRANCH_NOMINAL``: the decade of the rubber layout's mean branch force at the translations' nominal deflection
    (its rate w_j k times 1 mm), as the motion's nominals are the default layout's sag (State.nominal)."""
    gains = _system(RUBBER).branches.gains
    assert BRANCH_NOMINAL == 10.0 ** np.floor(np.log10(np.mean(gains) * TRANSLATION_NOMINAL))
