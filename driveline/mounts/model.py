"""Time stepping of the powertrain on its mounts: exact over each step (:mod:`.exact_step`).

The model starts at rest in the static equilibrium under the weight and the inputs at the
start time. A step moves the state ``(q, q')`` by the propagator of its size (built again only
when the size or a parameter changes) under the inputs at the step's start and their rates
(first-order hold; rates 0: zero-order hold); the accelerations and mount forces are those at
the step's end, under the inputs moved on by their rates.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..model import SteppedModel
from ..halfshaft.geometry import GeometryError
from .exact_step import Propagator, work_error
from .halfshafts import GEOMETRY, Halfshaft, values
from .implicit_step import StepMatrices, implicit_step
from .layout import MAX_MOUNTS, Layout, load_layout, shipped_layout
from .rigid_body import COORDINATES
from .spec import (AXES, BRANCH_FORCES, BRANCH_RATES, INPUTS, RUBBER_LAYOUT, SHARED_LAYOUT, SIDES, SPEC, VELOCITIES,
                   derivative_name)
from .system import MountSystem, Placement

RATES = tuple(derivative_name(name) for name in INPUTS)
ACCELERATIONS = tuple(f"{name}_ddot" for name in COORDINATES)


def read_layout(layout: str) -> Layout:
    """The layout: a file (a path ending in '.toml', any case) or a shipped name."""
    return load_layout(Path(layout) if layout.lower().endswith(".toml") else shipped_layout(layout))


class PowertrainMountsModel(SteppedModel):
    """The ``PowertrainMounts`` co-simulation model."""

    spec = SPEC
    # every input loaded, the joints' and motor's directions off the axes (a direction's part along
    # itself or along the shaft is dropped), a mean torque (the sag's motor axis)
    dependency_points = ({**{name: 100.0 * (-1) ** k * (1 + k % 5) for k, name in enumerate(INPUTS)},
                          "shaft_x_left": 0.1, "shaft_z_left": -0.05, "bend_x_left": 0.2, "shaft_x_right": -0.08,
                          "shaft_z_right": 0.04, "bend_y_right": 0.15, "motor_axis_x": 0.1, "motor_axis_z": 0.2,
                          "T_mean": 150.0},)
    derived_state = ("_system", "_built_for", "_propagator", "_step_matrices", "_shafts")
    #: the Maxwell branches' forces [N] (:mod:`.rubber`), a tuple of floats: part of the saved state
    resource_files = tuple(Path(__file__).parent / "data" / f"{name}.toml" for name in (SHARED_LAYOUT, RUBBER_LAYOUT))

    def reset_internal_state(self) -> None:
        self._system: MountSystem | None = None
        self._built_for: tuple | None = None
        self._propagator: Propagator | None = None
        self._step_matrices: StepMatrices | None = None
        self._shafts: dict[str, Halfshaft] = {}
        self._branch_forces: tuple[float, ...] = ()

    def _vector(self, template: str, side: str = "") -> np.ndarray:
        return np.array([float(getattr(self, template.format(axis=axis, side=side))) for axis in AXES])

    def extra_parameter_errors(self) -> list[str]:
        """Read the layout and build the system (refused: a layout that does not read, joint or
        motor directions that give no frame, mounts that leave the body free to move)."""
        key = tuple(getattr(self, name) for name in self._parameter_names)
        if key == self._built_for:
            return []
        try:
            placement = Placement.of(
                {side: self._vector("{axis}_joint_{side}", side) for side in SIDES},
                {side: self._vector("shaft_{axis}_{side}", side) for side in SIDES},
                {side: self._vector("bend_{axis}_{side}", side) for side in SIDES},
                self._vector("motor_axis_{axis}"))
            system = MountSystem.build(read_layout(self.layout), placement, self.g, self.T_mean)
        except (ValueError, ArithmeticError) as error:
            return [f"powertrain: {error}"]
        self._system, self._built_for, self._propagator, self._step_matrices = system, key, None, None
        self._shafts = {side: Halfshaft.of(placement.frames[side], placement.centres[side],
                                           system.body.layout.centre_of_gravity, getattr(self, f"l_{side}"),
                                           getattr(self, f"beta_design_{side}"), getattr(self, f"psi_design_{side}"),
                                           getattr(self, f"plunge_design_{side}"))
                        for side in SIDES}
        return []

    def _values(self, names: tuple[str, ...]) -> np.ndarray:
        return np.array([float(getattr(self, name)) for name in names])

    def internal_from_saved(self, state: dict) -> dict:
        """The branch forces of a saved state: a tuple of finite floats."""
        forces = state.get("_branch_forces", ())
        if not isinstance(forces, (tuple, list)) or not all(
                isinstance(v, float) and np.isfinite(v) for v in forces):
            raise ValueError("the saved state's branch forces are not a list of finite numbers")
        return {"_branch_forces": tuple(forces)}

    def _state(self) -> np.ndarray:
        """``(q, q', z)`` of the outputs and the branch forces."""
        return np.concatenate([self._values(COORDINATES + VELOCITIES), np.array(self._branch_forces, dtype=float)])

    def start(self, start_time: float) -> None:
        system = self._system
        force = system.inputs @ self._values(INPUTS)
        state = np.concatenate([system.start_displacement(force), np.zeros(system.size - 6)])
        self._show(state, force)
        for side in SIDES:
            reason = self._limit_error(side)
            if reason is not None:
                raise ValueError(reason)
        self._show_analysis()

    def _limit_error(self, side: str) -> str | None:
        """Why the ``side`` joint's start position lies beyond its bend or its stroke (the design geometry's
        own limits are the spec's relations)."""
        beta, plunge = getattr(self, f"beta_{side}"), getattr(self, f"plunge_{side}")
        low, high = getattr(self, f"plunge_min_{side}"), getattr(self, f"plunge_max_{side}")
        limit = getattr(self, f"beta_max_{side}")
        angle, length = SPEC[f"beta_max_{side}"], SPEC[f"plunge_max_{side}"]
        if beta > limit:
            return (f"the {side} joint's bend at the start, {angle.shown(beta)}, exceeds beta_max_{side} = "
                    f"{angle.shown(limit)}")
        if not low <= plunge <= high:
            bound, limit = ("min", low) if plunge < low else ("max", high)
            return (f"the {side} joint's plunge at the start, {length.shown(plunge)}, lies beyond "
                    f"plunge_{bound}_{side} = {length.shown(limit)} (the joint's stroke)")
        return None

    def rounding_scales(self) -> dict[str, float]:
        """The accelerations: zero in the equilibrium the model starts in, up to rounding; so are the halfshafts'
        rates, the second ones linear in the accelerations there (the first rates all zero): their scale is
        the sum over the accelerations of each one's scale times its partial derivative."""
        system = self._system
        scales = system.acceleration_scales(self._state(), system.inputs @ self._values(INPUTS))
        found = dict(zip(ACCELERATIONS, (float(scale) for scale in scales)))
        if self.housing_motion:
            q, zero = self._values(COORDINATES), np.zeros(6)
            for side, shaft in self._shafts.items():
                partials = np.array([values(shaft.geometry(q, zero, unit)) for unit in np.eye(6)])
                for name, column in zip(GEOMETRY, partials.T):
                    found[f"{name}_{side}"] = float(np.abs(column) @ scales)
        return found

    def advance(self, current_time: float, step_size: float) -> None:
        system = self._system
        held, rates = system.inputs @ self._values(INPUTS), system.inputs @ self._values(RATES)
        if system.progressive:
            matrices = self._step_matrices
            if matrices is None or matrices.h != step_size:
                matrices = StepMatrices.of(system.body.mass, system.body.damping, system.branches, step_size)
            state, _ = implicit_step(system.body.layout, system.body.mass, system.body.damping, system.branches,
                                     system.weight, system.weight_sag, self._state(), held, rates, step_size, matrices)
            self._step_matrices = matrices
            self._show(state, held + rates * step_size)
            return
        propagator = self._propagator
        if propagator is None or propagator.h != step_size:
            reason = work_error(system.a, system.b, step_size)
            if reason is not None:
                raise ValueError(reason)
            propagator = Propagator.build(system.a, system.b, step_size)
        state = propagator.step(self._state(), held, rates)
        self._propagator = propagator
        self._show(state, held + rates * step_size)

    def evaluate(self, time: float) -> None:
        """Model Exchange (the native FMUs): the state's derivatives, accelerations and mount forces at the
        current states (the branches' forces from their slots) under the inputs now (their rates are
        co-simulation's alone), the system built if needed."""
        errors = self.extra_parameter_errors()
        if errors:
            raise ValueError(errors[0])
        slots = self._values(BRANCH_FORCES)
        state = np.concatenate([self._values(COORDINATES + VELOCITIES), slots[self._system.branches.slots]])
        self._show(state, self._system.inputs @ self._values(INPUTS))

    def _show(self, state: np.ndarray, force: np.ndarray) -> None:
        """Motion, branch and mount-force outputs of ``state`` under the generalised ``force`` (the branches' forces
        and rates in their slots, the idle ones 0)."""
        system = self._system
        rates = system.derivatives(state, force)
        for name, value in zip(COORDINATES + VELOCITIES + ACCELERATIONS, np.concatenate([state[:12], rates[6:12]])):
            setattr(self, name, float(value))
        self._branch_forces = tuple(float(value) for value in state[12:])
        slots = np.zeros((2, len(BRANCH_FORCES)))
        slots[:, system.branches.slots] = state[12:], rates[12:]
        for force_name, rate_name, value, rate in zip(BRANCH_FORCES, BRANCH_RATES, *slots):
            setattr(self, force_name, float(value))
            setattr(self, rate_name, float(rate))
        self._show_halfshafts()
        forces = system.mount_forces(state)
        for i in range(MAX_MOUNTS):
            for k, axis in enumerate(AXES):
                setattr(self, f"F_{axis}_mount{i + 1}", float(forces[i, k]) if i < len(forces) else 0.0)

    def _show_halfshafts(self) -> None:
        """Each side's geometry at the motion shown (:mod:`.halfshafts`), or its design with the housings held; not
        a number where the motion is none (the motion's outputs then refuse the step)."""
        motion = [self._values(names) for names in (COORDINATES, VELOCITIES, ACCELERATIONS)]
        finite = all(np.isfinite(part).all() for part in motion)
        for side, shaft in self._shafts.items():
            if not self.housing_motion:
                found = values(shaft.design)
            elif not finite:
                found = (math.nan,) * len(GEOMETRY)
            else:
                try:
                    found = values(shaft.geometry(*motion))
                except GeometryError as error:
                    raise ValueError(f"the {side} joint: {error}") from None
            for name, value in zip(GEOMETRY, found):
                setattr(self, f"{name}_{side}", value)

    def _show_analysis(self) -> None:
        """Static sag, modal table and torque roll axis (fixed by the parameters)."""
        system = self._system
        sag = system.static_sag(self.g, self.T_mean)
        for name, value in zip(COORDINATES, sag):
            setattr(self, f"{name}_static", float(value))
        self.wind_up = system.wind_up(sag)
        found = system.operating_modes(sag)
        for j in range(6):
            setattr(self, f"f_mode_{j + 1}", float(found.frequencies[j]))
            setattr(self, f"zeta_mode_{j + 1}", float(found.damping_ratios[j]))
            dominant = int(found.dominant[j])
            setattr(self, f"mode_{j + 1}_coordinate", dominant + 1)
            setattr(self, f"mode_{j + 1}_share", float(found.shares[j, dominant]))
            for k, name in enumerate(COORDINATES):
                setattr(self, f"share_{j + 1}_{name}", float(found.shares[j, k]))
        for axis, value in zip(AXES, system.torque_roll_axis()):
            setattr(self, f"torque_roll_axis_{axis}", float(value))
        self.mount_count = len(system.body.layout.mounts)
