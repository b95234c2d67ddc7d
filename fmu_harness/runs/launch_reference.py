"""The vehicle launch as one ODE, the monolithic reference of its co-simulation (docs/vehicle_launch.md).

The physics cores of the launch's components called directly, with the parameters of
:func:`.system.vehicle_launch`: TorqueSource's ramp, VehicleDriveline's equations (eqs V1-V8), both
TripodCouplings' exact kinematics and reactions with friction, PowertrainMounts' equations of motion
(``M q'' + C q' + K q = G u`` on linear mounts; on the rubber default the characteristics' forces and the
Maxwell branches' forces as states, ``MountSystem.derivatives``); integrated together by ``scipy.integrate.solve_ivp`` at a tight
tolerance. The joints have no state beyond their input angle, so each side gear's angle joins the
drive's state. A joint's ``T_in`` depends on its input acceleration (the plungers' inertia) and the side
gears' accelerations on both ``T_in``: that algebraic loop, which the co-simulation breaks by a
communication step, is solved at each evaluation by successive substitution (a contraction of rate
about ``3 m r^2 / J_side`` = 0.03).

Usage: ``python -m fmu_harness.runs.launch_reference [--models models] [--stop-time 0.5]`` after
``python build_fmu.py`` prints the co-simulation's error against the reference at each communication
step of :data:`STEPS` (native package, the project's Jacobi master) as a Markdown table; with
``--gauss-seidel`` at each step of :data:`GAUSS_SEIDEL_STEPS` in the Gauss-Seidel master.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES
from driveline.mounts.spec import INPUTS as MOUNT_INPUTS
from driveline.torque.model import TorqueSourceModel
from driveline.tripod.outputs import coupling_outputs
from driveline.tripod import plane_solver
from driveline.tripod.plane_solver import Solution
from driveline.tripod.spec import SPEC as TRIPOD
from driveline.vehicle import dynamics
from driveline.vehicle.dynamics import Joints
from driveline.vehicle.model import VehicleDrivelineModel

from . import system
from ..console import summary

#: The compared signals: co-simulation column and its meaning.
SIGNALS = {
    "drive.v_x": "vehicle speed",
    "drive.T_load_left": "left halfshaft torque",
    "joint_left.Rz_in": "left generated axial force `Rz_in`",
    "mounts.pitch_ddot": "powertrain pitch acceleration",
}
#: Communication steps of the convergence table [s] (Jacobi diverges at 5e-4 s, Gauss-Seidel at 1e-3 s).
STEPS = (4e-4, 2e-4, 1e-4)
GAUSS_SEIDEL_STEPS = (8e-4, 4e-4, 2e-4, 1e-4)
#: solve_ivp's tolerances: relative, and absolute on states of order 1 (angles, speeds) down to 1e-3 m.
RTOL, ATOL = 1e-10, 1e-12
#: The algebraic loop is solved when the side gears' accelerations change by less than this share (the
#: friction balance of each joint settles to 1e-13 of its forces, which the loop amplifies).
LOOP_TOLERANCE = 1e-11
MAX_LOOP_ITERATIONS = 50
DRIVE_STATES = dynamics.STATE_SIZE
PHI_IN = (DRIVE_STATES, DRIVE_STATES + 1)  # left and right joints' input angle, each in its own frame
MOUNTS_START = DRIVE_STATES + 2  # the mounts' state (q, q', the branches' forces) from here to the end


def _configured(model_class, parameters: Mapping[str, object]):
    model = model_class()
    for name, value in parameters.items():
        setattr(model, name, value)
    return model


@dataclass
class LaunchEquations:
    """The launch's equations, from the component parameters ``{component: {name: value}}``."""

    parameters: Mapping[str, Mapping[str, object]]

    def __post_init__(self) -> None:
        self.motor = _configured(TorqueSourceModel, self.parameters["motor"])
        self.drive = _configured(VehicleDrivelineModel, self.parameters["drive"])._drive()
        self.v_start = float(self.parameters["drive"].get("v_start", 0.0))
        tripod = {v.name: v.start for v in TRIPOD.of("parameter")}
        self.joints = {side: tripod | dict(self.parameters[f"joint_{side}"]) for side in system.SIDES}
        mounts = _configured(PowertrainMountsModel, self.parameters["mounts"])
        errors = mounts.extra_parameter_errors()
        if errors:
            raise ValueError("; ".join(errors))
        self.mounts = mounts._system
        self.mounts_state = slice(MOUNTS_START, MOUNTS_START + self.mounts.size)
        self._warm: dict[str, Solution | None] = {side: None for side in system.SIDES}
        self._alpha = [0.0, 0.0]

    def motor_torque(self, t: float) -> float:
        self.motor.at_time(t)
        return float(self.motor.T_motor)

    def _joint(self, side: str, phi_in: float, omega_in: float, alpha_in: float, T_load: float) -> dict:
        p = self.joints[side]
        values, self._warm[side] = coupling_outputs(
            phi_in, p["beta"], omega_in, T_load, p["r"], p["l"], p["m_plunger"], p["kinematics"], self._warm[side],
            alpha_in, p["seed_reactions"], p["mu"], p["v_slip"], tripod_type=p["tripod_type"], mu_roll=p["mu_roll"],
            roller_radius=p["roller_radius"], roller_bore_radius=p["roller_bore_radius"])
        return values

    def _kinematics(self, side: str, phi_in: float) -> tuple[float, float]:
        """The joint's output angle and speed ratio (exact kinematics)."""
        p = self.joints[side]
        phi_out, ratio, self._warm[side] = plane_solver.solve(phi_in, p["beta"], p["r"], p["l"], self._warm[side])
        return phi_out, ratio

    def evaluate(self, t: float, y: np.ndarray) -> dict:
        """Everything at ``(t, y)``: the drive's rates, both joints' outputs (own frames), the motor torque."""
        state = tuple(float(v) for v in y[:DRIVE_STATES])
        case, diff = state[dynamics.CASE], state[dynamics.DIFF]
        omega = (case + diff, -(case - diff))  # each side gear in its joint's frame
        T_motor = self.motor_torque(t)
        kinematic = [self._kinematics(side, float(y[PHI_IN[i]])) for i, side in enumerate(system.SIDES)]
        placed = Joints(0.0, 0.0, kinematic[0][0], -kinematic[1][0], omega[0] * kinematic[0][1],
                        -omega[1] * kinematic[1][1])
        T_left, T_right = dynamics.halfshaft_torques(self.drive, state, placed, 0.0)
        loads = (T_left, -T_right)
        alpha = list(self._alpha)
        for _ in range(MAX_LOOP_ITERATIONS):
            joints = [self._joint(side, float(y[PHI_IN[i]]), omega[i], alpha[i], loads[i])
                      for i, side in enumerate(system.SIDES)]
            rates = dynamics.rates(self.drive, state, T_motor, placed._replace(
                T_in_left=joints[0]["T_in"], T_in_right=-joints[1]["T_in"]), 0.0)
            new = [rates[dynamics.CASE] + rates[dynamics.DIFF], -(rates[dynamics.CASE] - rates[dynamics.DIFF])]
            change = max(abs(a - b) for a, b in zip(new, alpha))
            alpha = new
            if change <= LOOP_TOLERANCE * max(1.0, *map(abs, new)):
                break
        else:
            raise ArithmeticError("the joints' algebraic loop did not converge")
        self._alpha = alpha
        placed = placed._replace(T_in_left=joints[0]["T_in"], T_in_right=-joints[1]["T_in"])
        reaction = dynamics.reaction_torque(self.drive, placed, rates[dynamics.CASE])
        force = self.mounts.inputs @ self.mount_loads(joints, reaction)
        mount_state = np.asarray(y[self.mounts_state], dtype=float)
        return {"drive_rates": rates, "omega_in": omega, "joints": joints, "T_motor": T_motor, "loads": loads,
                "placed": placed, "force": force, "reaction": reaction,
                "mount_rates": self.mounts.derivatives(mount_state, force),
                "mount_accelerations": self.mounts.accelerations(mount_state, force)}

    @staticmethod
    def mount_loads(joints: list[dict], reaction: float) -> np.ndarray:
        """PowertrainMounts' inputs: both joints' housing forces and bending moments, the drive's ``reaction``
        (its T_reaction) about y (its own T_motor and the other load inputs 0)."""
        values = dict.fromkeys(MOUNT_INPUTS, 0.0)
        for side, joint in zip(system.SIDES, joints):
            values.update({f"{name}_{side}": joint[name] for name in system.HOUSING_LOADS})
        values["M_y"] = reaction
        return np.array([values[name] for name in MOUNT_INPUTS])

    def rates(self, t: float, y: np.ndarray) -> np.ndarray:
        found = self.evaluate(t, y)
        return np.concatenate([found["drive_rates"], found["omega_in"], found["mount_rates"]])

    def start(self) -> np.ndarray:
        """At rest (or rolling at v_start) with untwisted halfshafts, the powertrain in its static equilibrium."""
        phi = [float(self.joints[side]["phi_in_start"]) for side in system.SIDES]
        placed = Joints(0.0, 0.0, self._kinematics("left", phi[0])[0], -self._kinematics("right", phi[1])[0], 0.0, 0.0)
        drive = dynamics.start_state(self.drive, self.v_start, placed)
        y = np.concatenate([drive, phi, np.zeros(self.mounts.size)])
        found = self.evaluate(0.0, y)
        force = self.mounts.inputs @ self.mount_loads(found["joints"], found["reaction"])
        y[MOUNTS_START:MOUNTS_START + 6] = self.mounts.start_displacement(force)
        return y

    def signals(self, t: float, y: np.ndarray) -> dict[str, float]:
        """The co-simulation's columns of :data:`SIGNALS` (and a few more) at ``(t, y)``."""
        found = self.evaluate(t, y)
        pitch = COORDINATES.index("pitch")
        return {"drive.v_x": float(y[dynamics.SPEED]), "drive.T_load_left": found["loads"][0],
                "joint_left.Rz_in": found["joints"][0]["Rz_in"], "joint_right.Rz_in": found["joints"][1]["Rz_in"],
                "mounts.pitch_ddot": float(found["mount_accelerations"][pitch])}


def launch_parameters(overrides: Mapping[str, Mapping[str, object]] | None = None) -> dict[str, dict[str, object]]:
    """The component parameters of :func:`.system.vehicle_launch` without the housings' motion (the joints'
    bends bound), with ``overrides`` on top."""
    parameters = {c.name: dict(c.parameters) for c in system.vehicle_launch(housing_motion=False).components}
    parameters.setdefault("mounts", {})
    for name, values in (overrides or {}).items():
        parameters[name].update(values)
    return parameters


def reference(times: np.ndarray, parameters: Mapping[str, Mapping[str, object]] | None = None,
              rtol: float = RTOL) -> dict[str, np.ndarray]:
    """The monolithic launch at ``times`` (from 0): each signal of :meth:`LaunchEquations.signals`
    and the state ``"y"`` (rows)."""
    equations = LaunchEquations(parameters or launch_parameters())
    solution = solve_ivp(equations.rates, (0.0, float(times[-1])), equations.start(), method="DOP853",
                         t_eval=times, rtol=rtol, atol=ATOL)
    if not solution.success:
        raise ArithmeticError(f"the monolithic launch failed: {solution.message}")
    rows = [equations.signals(t, y) for t, y in zip(solution.t, solution.y.T)]
    found = {name: np.array([row[name] for row in rows]) for name in rows[0]}
    found["y"] = solution.y.T
    return found


def errors(cosimulation: Mapping[str, np.ndarray], times: np.ndarray, monolithic: Mapping[str, np.ndarray]) -> dict:
    """Largest difference of each signal of :data:`SIGNALS` over ``times`` relative to the reference's
    largest magnitude; ``cosimulation`` holds ``"t"`` and the signals at its own communication points."""
    index = np.searchsorted(cosimulation["t"], times - 1e-12)
    return {name: float(np.abs(cosimulation[name][index] - monolithic[name]).max() / np.abs(monolithic[name]).max())
            for name in SIGNALS}


def cosimulate(models: Path, natives: Path | None, step: float, stop_time: float,
               order: tuple[str, ...] | None = None) -> dict[str, np.ndarray]:
    """The launch in the project's master at ``step`` (:func:`.system.component_fmus` of ``models`` and
    ``natives``), Jacobi or Gauss-Seidel in ``order``: ``"t"`` and :data:`SIGNALS`; the package without the
    housings' motion, as the reference."""
    launch = system.vehicle_launch(housing_motion=False)
    launch = system.System(launch.name, launch.components, launch.connections, stop_time, step)
    rows = system.simulate(launch, models, list(SIGNALS), natives=natives, order=order)
    return {"t": rows[:, 0], **{name: rows[:, i + 1] for i, name in enumerate(SIGNALS)}}


def convergence_table(models: Path, stop_time: float, steps: tuple[float, ...] = STEPS,
                      order: tuple[str, ...] | None = None) -> str:
    """Markdown table: each step's relative error of each signal against the reference, at the
    coarsest step's instants, and the order between successive steps (Jacobi, or Gauss-Seidel in ``order``)."""
    times = np.arange(1, int(round(stop_time / max(steps))) + 1) * max(steps)
    monolithic = reference(times)
    found = [errors(cosimulate(models, models, step, stop_time, order), times, monolithic) for step in steps]
    lines = ["| step [s] | " + " | ".join(SIGNALS.values()) + " |", "|---" * (len(SIGNALS) + 1) + "|"]
    lines += [f"| {step:.0e} | " + " | ".join(f"{row[name]:.1e}" for name in SIGNALS) + " |"
              for step, row in zip(steps, found)]
    orders = {name: [math.log(a[name] / b[name]) / math.log(h / k)
                     for a, b, h, k in zip(found, found[1:], steps, steps[1:])] for name in SIGNALS}
    lines.append("| order | " + " | ".join(", ".join(f"{o:.2f}" for o in orders[name]) for name in SIGNALS) + " |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs (native/ below)")
    parser.add_argument("--stop-time", type=float, default=0.5, help="length of the compared launch [s]")
    parser.add_argument("--gauss-seidel", action="store_true",
                        help=f"the Gauss-Seidel master in the order {', '.join(system.LAUNCH_ORDER)}")
    args = parser.parse_args(argv)
    if args.gauss_seidel:
        print(convergence_table(args.models, args.stop_time, GAUSS_SEIDEL_STEPS, system.LAUNCH_ORDER))
    else:
        print(convergence_table(args.models, args.stop_time))


if __name__ == "__main__":
    main()
