"""CardanJoint's input alpha_in (d(omega_in)/dt, declared as omega_in's derivative), through the FMUs
of both families and both FMI versions: on a speed ramp 50 rad/s + 400 rad/s2 t, bent 0.5 rad,
host step 1e-4 s, inputs set at the start of each step (so each row after the first holds the
outputs at the step's end from the speed set at its start). The reference is the seed's (C4)
evaluated here (driveline.cardan.kinematics) at the FMU's own phi_in."""

from __future__ import annotations

import numpy as np

from driveline.cardan import kinematics
from driveline.cardan.model import ACCELERATION_ESTIMATED

OMEGA_0, RAMP, BETA, STEP, STEPS = 50.0, 400.0, 0.5, 1e-4, 500


def speed(t: float) -> float:
    return OMEGA_0 + RAMP * t


def run(family, fmi: str, acceleration: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray, list]:
    """phi_in, the held omega_in and alpha_out at the start and after each step, and the log;
    ``acceleration``: the host sets alpha_in besides omega_in."""
    phi, held, alpha_out = [], [], []
    with family.open("CardanJoint", fmi) as fmu:

        def inputs(t: float) -> None:
            fmu.set({"omega_in": speed(t), "beta": BETA, **({"alpha_in": RAMP} if acceleration else {})})
            held.append(speed(t))

        def read() -> None:
            got = fmu.get(("phi_in", "alpha_out"))
            phi.append(got[0])
            alpha_out.append(got[1])

        fmu.enter_initialization({})
        inputs(0.0)
        fmu.exit_initialization()
        read()
        for k in range(STEPS):
            inputs(k * STEP)
            fmu.step(STEP)
            read()
        return np.array(phi), np.array(held), np.array(alpha_out), [(r.status, r.message) for r in fmu.log]


def c4(phi: np.ndarray, omega: np.ndarray, alpha_in: np.ndarray | float) -> np.ndarray:
    return kinematics.output_acceleration(phi, BETA, omega, alpha_in)


def test_alpha_in_set_gives_the_exact_output_acceleration_from_the_start(family, fmi):
    """With alpha_in set, alpha_out is (C4) with a_1 = alpha_in at every row, the first included:
    within 1e-12 of the largest |alpha_out| (the two cores' sin and cos a few ulps apart), where
    the estimate has no acceleration at the start and over the first step (measured: those rows
    differ by 456 rad/s2, a_1 cos b / D). No warning: the host gave the acceleration."""
    phi, held, alpha_out, log = run(family, fmi, True)
    exact = c4(phi, held, RAMP)
    scale = np.abs(exact).max()
    np.testing.assert_allclose(alpha_out, exact, rtol=0.0, atol=1e-12 * scale)
    assert np.abs(alpha_out[:2] - c4(phi[:2], held[:2], 0.0)).min() > 0.5 * RAMP
    assert log == []


def test_omega_in_alone_keeps_the_backward_difference(family, fmi):
    """A host that sets omega_in alone gets the answer of before alpha_in was an input: a_1 = 0 at
    the start and over the first step (no interval yet), then the backward difference of the last
    two speed samples, which on the ramp is its slope to round-off (1e-9 of it); the log says so
    once, at initialisation."""
    phi, held, alpha_out, log = run(family, fmi, False)
    estimate = np.where(np.arange(len(phi)) < 2, 0.0, RAMP)
    expected = c4(phi, held, estimate)
    np.testing.assert_allclose(alpha_out, expected, rtol=0.0, atol=1e-9 * np.abs(expected).max())
    assert log == [("OK", ACCELERATION_ESTIMATED)]
