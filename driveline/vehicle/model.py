"""Time stepping of the vehicle driveline: the state integrated over each step, outputs at its end."""

from __future__ import annotations

from ..model import SteppedModel
from . import dynamics
from .dynamics import Drive, Joints
from .spec import SPEC


class VehicleDrivelineModel(SteppedModel):
    """The ``VehicleDriveline`` co-simulation model: inputs held from a communication point (the joints'
    output angles moving at their output speeds), the state moved by :func:`dynamics.advance`. Each
    joint's quantities are in its own frame, Z' from the differential towards its wheel: forward, the
    left joint turns positively and the right one negatively (ISO 8855, y to the left)."""

    spec = SPEC

    native_constants = {"TOO_LONG": dynamics.TOO_LONG}

    def reset_internal_state(self) -> None:
        self._state: tuple[float, ...] = (0.0,) * dynamics.STATE_SIZE

    def internal_from_saved(self, state: dict) -> dict:
        saved = state["_state"]
        if not (isinstance(saved, tuple) and len(saved) == dynamics.STATE_SIZE
                and all(isinstance(value, float) for value in saved)):
            raise ValueError(f"the saved state of the drive is not {dynamics.STATE_SIZE} floats")
        return {}

    def _drive(self) -> Drive:
        return Drive(*(getattr(self, name) for name in Drive._fields))

    def _joints(self) -> Joints:
        """The joints' inputs in the drive's sense (each joint's own frame has Z' towards its wheel:
        the right joint's quantities change sign)."""
        return Joints(self.T_in_left, -self.T_in_right, self.phi_out_left, -self.phi_out_right,
                      self.omega_out_left, -self.omega_out_right)

    def start(self, start_time: float) -> None:
        drive, joints = self._drive(), self._joints()
        self._state = dynamics.start_state(drive, self.v_start, joints)
        self._evaluate(drive, joints, 0.0)

    def advance(self, current_time: float, step_size: float) -> None:
        drive, joints = self._drive(), self._joints()
        self._state = dynamics.advance(drive, self._state, self.T_motor, joints, step_size)
        self._evaluate(drive, joints, step_size)

    def _evaluate(self, drive: Drive, joints: Joints, elapsed: float) -> None:
        """Outputs at the state reached ``elapsed`` after the inputs' communication point."""
        state = self._state
        rate = dynamics.rates(drive, state, self.T_motor, joints, elapsed)
        case, diff = state[dynamics.CASE], state[dynamics.DIFF]
        self.omega_in_left, self.omega_in_right = case + diff, -(case - diff)
        self.alpha_in_left = rate[dynamics.CASE] + rate[dynamics.DIFF]
        self.alpha_in_right = -(rate[dynamics.CASE] - rate[dynamics.DIFF])
        T_left, T_right = dynamics.halfshaft_torques(drive, state, joints, elapsed)
        self.T_load_left, self.T_load_right = T_left, -T_right
        self.T_reaction = dynamics.reaction_torque(drive, joints, rate[dynamics.CASE])
        self.omega_motor = drive.ratio * case
        self.omega_wheel_left, self.omega_wheel_right = state[dynamics.WHEEL_LEFT], state[dynamics.WHEEL_RIGHT]
        self.slip_left, self.slip_right = state[dynamics.SLIP_LEFT], state[dynamics.SLIP_RIGHT]
        self.F_x_left = dynamics.tyre_force(drive, self.slip_left, drive.mu_road_left)
        self.F_x_right = dynamics.tyre_force(drive, self.slip_right, drive.mu_road_right)
        self.v_x, self.a_x, self.x = state[dynamics.SPEED], rate[dynamics.SPEED], state[dynamics.TRAVEL]
