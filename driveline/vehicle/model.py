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
    # rolling slowly on a grade with every input set: the road load (rolling resistance within its
    # regularisation, v_low) and the halfshafts act
    dependency_points = ({"v_start": 0.05, "grade": 0.05, "T_motor": 120.0, "T_in_left": 300.0, "T_in_right": -280.0,
                          "phi_out_left": 0.3, "phi_out_right": -0.2, "omega_out_left": 25.0,
                          "omega_out_right": -27.0},)

    native_constants = {"TOO_LONG": dynamics.TOO_LONG}
    # 100 steps of 1 ms, within the step limit (1.04 ms with the defaults: dynamics.divergence_step_limit)
    scenario_stop_time = 0.1

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

    def step_size_errors(self, step_size: float) -> list[str]:
        return dynamics.step_limit_errors(self._drive(), step_size)

    def step_notice(self, step_size: float) -> str | None:
        return dynamics.step_limit_notice(self._drive(), step_size)

    def start(self, start_time: float) -> None:
        drive, joints = self._drive(), self._joints()
        self._state = dynamics.start_state(drive, self.v_start, joints)
        self._evaluate(drive, joints, 0.0)

    def advance(self, current_time: float, step_size: float) -> None:
        drive, joints = self._drive(), self._joints()
        self._state = dynamics.advance(drive, self._state, self.T_motor, joints, step_size)
        self._evaluate(drive, joints, step_size)

    def evaluate(self, time: float) -> None:
        """Model Exchange (the native FMU's ``evaluate_now``): the outputs, the states' derivatives among
        them, at the states the solver holds in the outputs that are states (the case's and the
        differential's speeds from the side gears') and this instant's inputs; autonomous, whatever ``time``."""
        left, right = self.omega_in_left, self.omega_in_right
        self._state = ((left - right) / 2.0, (left + right) / 2.0, self.phi_wheel_left, self.omega_wheel_left,
                       self.phi_wheel_right, self.omega_wheel_right, self.v_x, self.x, self.slip_left, self.slip_right)
        self._evaluate(self._drive(), self._joints(), 0.0)

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
        self.phi_wheel_left, self.phi_wheel_right = state[dynamics.PHI_WHEEL_LEFT], state[dynamics.PHI_WHEEL_RIGHT]
        self.alpha_wheel_left, self.alpha_wheel_right = rate[dynamics.WHEEL_LEFT], rate[dynamics.WHEEL_RIGHT]
        self.slip_dot_left, self.slip_dot_right = rate[dynamics.SLIP_LEFT], rate[dynamics.SLIP_RIGHT]

    def rounding_scales(self) -> dict[str, float]:
        """The slips' rates start as r_wheel (v_start / r_wheel) - v_start, zero but for rounding (eq V6)."""
        scale = 2.0 * abs(self.v_start) / self.sigma_slip
        return {"slip_dot_left": scale, "slip_dot_right": scale}
