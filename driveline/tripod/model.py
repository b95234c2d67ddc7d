"""Time stepping of the tripod coupling: integrates phi_in, evaluates kinematics and forces."""

from __future__ import annotations

import math

from ..model import DrivenShaftModel
from . import closed_form, dynamics, plane_solver
from .geometry import TripodGeometry, orbit_radius
from .spec import EXACT, SPEC


class TripodCouplingModel(DrivenShaftModel):
    """The ``TripodCoupling`` co-simulation model (inputs held constant over a step)."""

    spec = SPEC

    def reset_internal_state(self) -> None:
        self._axis: tuple[float, float] | None = None  # warm start of the exact solver

    def extra_parameter_errors(self) -> list[str]:
        return TripodGeometry(self.r, self.l, self.m_plunger).errors()

    def extra_input_errors(self) -> list[str]:
        return self.angle_bound_errors("beta", "beta_max")

    def start(self, start_time: float) -> None:
        self._axis = None
        super().start(start_time)

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in and inputs."""
        phi, beta, omega = self.phi_in, self.beta, self.omega_in
        r, l, m = self.r, self.l, self.m_plunger
        rho = orbit_radius(beta, r)
        if self.kinematics == EXACT:
            self.phi_out, ratio, self._axis = plane_solver.solve(phi, beta, r, l, self._axis)
            self.theta = math.asin(math.hypot(*self._axis))
        else:
            self.phi_out = phi + closed_form.angle_deviation(phi, beta, r, l)
            ratio = closed_form.speed_ratio(phi, beta, r, l)
            self.theta = math.asin(rho / l)
        self.delta_phi = self.phi_out - phi
        self.omega_out = omega * ratio
        self.T_in = dynamics.input_torque(self.T_load, ratio)
        self.rho = rho
        self.F_pin = dynamics.pin_force(self.T_load, beta, r)
        self.a_plunger_sum = dynamics.plunger_acceleration_sum(phi, beta, omega, r)
        self.Rz_out = dynamics.output_axial_reaction(phi, beta, omega, r, m)
        self.Rx_in = dynamics.input_reaction_x(phi, beta, omega, r, m)
        self.Ry_in = dynamics.input_reaction_y(phi, beta, omega, r, l, m)
