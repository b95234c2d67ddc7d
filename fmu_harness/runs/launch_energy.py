"""Energy balance of the closed launch loop, from the monolithic reference (:mod:`.launch_reference`).

The motor's work goes into the kinetic energy of the drive's rotating parts, the wheels and the car
(eqs V1, V4, V7), the halfshafts' twist, the plungers' motion and the tyres' deflection (the slip's
relaxation, eq V6, stores ``sigma (L^2 / C) ln cosh(C s / L)`` with ``F = L tanh(C s / L)``), and is
dissipated by the halfshafts' damping, the joints' friction (``P_friction``), the tyres' slip
(``F (|v| + v_low) s``) and the road load. The powertrain on its mounts has its own balance: the
work of the joints' housing loads and of the drive's reaction torque (``T_reaction``) goes into its
kinetic and elastic energy and the mounts' damping. That balance is the linear mounts' (``K``, ``C``): the
launch runs here on the linear layout (``transverse_fwd_powertrain``), not PowertrainMounts' rubber default,
whose snubbers' and Maxwell branches' energy tests/core/test_mounts_rubber.py balances on its own.
The dissipated powers are integrated with the state (quadrature states), so the balance holds to the
integration's tolerance, not a quadrature rule's.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from driveline.mounts.rigid_body import COORDINATES
from driveline.mounts.spec import REACTIONS, SHARED_LAYOUT
from driveline.tripod.exact import exact_pose
from driveline.vehicle import dynamics
from driveline.vehicle.dynamics import Joints

from . import system
from .launch_reference import ATOL, PHI_IN, RTOL, LaunchEquations, launch_parameters

#: The integrated powers (quadrature states), in this order.
POWERS = ("motor work", "halfshaft damping", "joint friction", "tyre slip", "road load", "housing loads' work",
          "mount damping")
#: Step of the central difference of the plungers' travel in phi_in [rad] (error ~1e-12 of the speed).
TRAVEL_STEP = 1e-6


def _linear(overrides: dict | None = None) -> dict:
    """``overrides`` with the mounts on the linear layout (unless they name one)."""
    found = {name: dict(values) for name, values in (overrides or {}).items()}
    found["mounts"] = {"layout": SHARED_LAYOUT} | found.get("mounts", {})
    return found


def powers(equations: LaunchEquations, y: np.ndarray, found: dict) -> list[float]:
    """The powers of :data:`POWERS` at the state ``y`` [W]."""
    drive, state, placed = equations.drive, y, found["placed"]
    case = state[dynamics.CASE]
    slip_speed = abs(state[dynamics.SPEED]) + drive.v_low
    damping = (drive.c_left * (placed.omega_out_left - state[dynamics.WHEEL_LEFT]) ** 2
               + drive.c_right * (placed.omega_out_right - state[dynamics.WHEEL_RIGHT]) ** 2)
    tyres = sum(dynamics.tyre_force(drive, state[slip], mu) * slip_speed * state[slip]
                for slip, mu in ((dynamics.SLIP_LEFT, drive.mu_road_left), (dynamics.SLIP_RIGHT, drive.mu_road_right)))
    mounts = equations.mounts
    velocity = y[equations.mounts_state][6:]
    return [found["T_motor"] * drive.ratio * case, damping, sum(j["P_friction"] for j in found["joints"]), tyres,
            dynamics.road_load(drive, state[dynamics.SPEED]) * state[dynamics.SPEED],
            float(found["force"] @ velocity), float(velocity @ mounts.body.damping @ velocity)]


def stored(equations: LaunchEquations, y: np.ndarray, found: dict) -> dict[str, float]:
    """Energies stored in the loop and in the powertrain's mounting at the state ``y`` [J]."""
    drive, placed = equations.drive, found["placed"]
    case, diff = y[dynamics.CASE], y[dynamics.DIFF]
    kinetic = (0.5 * dynamics.case_inertia(drive) * case**2 + drive.J_side * diff**2
               + 0.5 * drive.J_wheel * (y[dynamics.WHEEL_LEFT] ** 2 + y[dynamics.WHEEL_RIGHT] ** 2)
               + 0.5 * dynamics.equivalent_mass(drive) * y[dynamics.SPEED] ** 2)
    twist = (placed.phi_out_left - y[dynamics.PHI_WHEEL_LEFT], placed.phi_out_right - y[dynamics.PHI_WHEEL_RIGHT])
    springs = 0.5 * (drive.k_left * twist[0] ** 2 + drive.k_right * twist[1] ** 2)
    tyres = 0.0
    for slip, mu in ((dynamics.SLIP_LEFT, drive.mu_road_left), (dynamics.SLIP_RIGHT, drive.mu_road_right)):
        limit = mu * dynamics.wheel_load(drive)
        tyres += drive.sigma_slip * limit * limit / drive.C_slip * math.log(math.cosh(drive.C_slip * y[slip] / limit))
    plungers = 0.0
    for i, side in enumerate(system.SIDES):
        p, omega = equations.joints[side], found["omega_in"][i]
        phi = y[PHI_IN[i]] + np.array([-TRAVEL_STEP, TRAVEL_STEP])
        travel = exact_pose(phi, np.full(2, p["beta"]), p["r"], p["l"]).plunger_positions
        zdot = omega * (travel[1] - travel[0]) / (2.0 * TRAVEL_STEP)
        plungers += 0.5 * p["m_plunger"] * (3.0 * (omega * p["r"]) ** 2 + float(zdot @ zdot))
    body = equations.mounts.body
    q, velocity = y[equations.mounts_state][:6], y[equations.mounts_state][6:]
    mounts = 0.5 * float(velocity @ body.mass @ velocity + q @ body.stiffness @ q)
    return {"drive": kinetic, "halfshafts": springs, "tyres": tyres, "plungers": plungers, "mounts": mounts}


def balance(stop_time: float, overrides: dict | None = None) -> dict[str, float]:
    """The monolithic launch's energies at ``stop_time`` [J]: each integrated power of :data:`POWERS`,
    each stored energy's change, and the loop's and the mounting's residuals relative to the work put in."""
    equations = LaunchEquations(launch_parameters(_linear(overrides)))
    size = len(equations.start())

    def rates(t: float, y: np.ndarray) -> np.ndarray:
        found = equations.evaluate(t, y[:size])
        return np.concatenate([equations.rates(t, y[:size]), powers(equations, y[:size], found)])

    start = np.concatenate([equations.start(), np.zeros(len(POWERS))])
    solution = solve_ivp(rates, (0.0, stop_time), start, method="DOP853", rtol=RTOL, atol=ATOL)
    if not solution.success:
        raise ArithmeticError(f"the monolithic launch failed: {solution.message}")
    first, last = solution.y[:size, 0], solution.y[:size, -1]
    before = stored(equations, first, equations.evaluate(0.0, first))
    after = stored(equations, last, equations.evaluate(stop_time, last))
    return _residuals(dict(zip(POWERS, solution.y[size:, -1])), before, after)


def _residuals(found: dict[str, float], before: dict[str, float], after: dict[str, float]) -> dict[str, float]:
    """``found`` (the integrated powers) with the stored energies' changes and both balances' residuals."""
    found |= {f"change of {name}": after[name] - before[name] for name in after}
    loop = (found["change of drive"] + found["change of halfshafts"] + found["change of tyres"]
            + found["change of plungers"] + found["halfshaft damping"] + found["joint friction"]
            + found["tyre slip"] + found["road load"])
    found["loop residual"] = (found["motor work"] - loop) / found["motor work"]
    mounting = found["change of mounts"] + found["mount damping"]
    found["mounting residual"] = (found["housing loads' work"] - mounting) / found["housing loads' work"]
    return found


def _cosimulation_state(equations: LaunchEquations, row: dict[str, float]) -> tuple[np.ndarray, dict]:
    """The monolithic state and evaluation that the co-simulation's outputs at one instant give (the
    wheels' angles from the halfshafts' torques), for :func:`powers` and :func:`stored`."""
    drive = equations.drive
    sides = [{name: row[f"joint_{side}.{name}"] for name in ("phi_in", "phi_out", "omega_out", "P_friction",
                                                             *REACTIONS)} for side in system.SIDES]
    omega = (row["drive.omega_in_left"], row["drive.omega_in_right"])
    placed = Joints(sides[0]["T_in"], -sides[1]["T_in"], sides[0]["phi_out"], -sides[1]["phi_out"],
                    sides[0]["omega_out"], -sides[1]["omega_out"])
    y = np.zeros(len(equations.start()))
    y[dynamics.CASE], y[dynamics.DIFF] = 0.5 * (omega[0] - omega[1]), 0.5 * (omega[0] + omega[1])
    torques = (row["drive.T_load_left"], -row["drive.T_load_right"])
    for i, (phi, wheel, speed, k, c, outward, slip) in enumerate((
            (dynamics.PHI_WHEEL_LEFT, "left", placed.omega_out_left, drive.k_left, drive.c_left, placed.phi_out_left,
             dynamics.SLIP_LEFT),
            (dynamics.PHI_WHEEL_RIGHT, "right", placed.omega_out_right, drive.k_right, drive.c_right,
             placed.phi_out_right, dynamics.SLIP_RIGHT))):
        y[phi + 1] = row[f"drive.omega_wheel_{wheel}"]
        y[phi] = outward - (torques[i] - c * (speed - y[phi + 1])) / k
        y[slip] = row[f"drive.slip_{wheel}"]
        y[PHI_IN[i]] = sides[i]["phi_in"]
    y[dynamics.SPEED] = row["drive.v_x"]
    y[equations.mounts_state] = [row[f"mounts.{name}"] for name in (*COORDINATES, *(f"{c}_dot" for c in COORDINATES))]
    found = {"placed": placed, "T_motor": row["motor.T_motor"], "joints": sides, "omega_in": omega,
             "force": equations.mounts.inputs @ equations.mount_loads(sides, row["drive.T_reaction"])}
    return y, found


def cosimulation_balance(models: Path, natives: Path | None, step: float, stop_time: float) -> dict[str, float]:
    """:func:`balance` of the launch in the project's Jacobi master at ``step``: the stored energies from
    the outputs at ``stop_time``, the powers from the outputs at each communication point integrated by
    the trapezoidal rule (from the start, at rest)."""
    equations = LaunchEquations(launch_parameters(_linear()))
    launch = system.vehicle_launch(housing_motion=False)
    components = tuple(dataclasses.replace(c, parameters={**c.parameters, "layout": SHARED_LAYOUT})
                       if c.name == "mounts" else c for c in launch.components)
    launch = system.System(launch.name, components, launch.connections, stop_time, step)
    outputs = launch.outputs()
    rows = system.simulate(launch, models, outputs, natives=natives)
    start = equations.start()
    before = stored(equations, start, equations.evaluate(0.0, start))
    samples = [powers(equations, start, equations.evaluate(0.0, start))]
    for values in rows:
        y, found = _cosimulation_state(equations, dict(zip(outputs, values[1:])))
        samples.append(powers(equations, y, found))
    after = stored(equations, y, found)
    times = np.concatenate([[0.0], rows[:, 0]])
    found = dict(zip(POWERS, np.trapezoid(np.array(samples), times, axis=0)))
    return _residuals(found, before, after)
