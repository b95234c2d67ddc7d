"""Time stepping of the tripod coupling: integrates phi_in, evaluates kinematics and forces."""

from __future__ import annotations

import math

import numpy as np

from ..model import DrivenShaftModel
from . import closed_form, dynamics
from .exact import exact_pose
from .geometry import TripodGeometry, orbit_radius
from .spec import EXACT, SPEC


class TripodCouplingModel(DrivenShaftModel):
    """The ``TripodCoupling`` co-simulation model (inputs held constant over a step)."""

    spec = SPEC

    def reset_internal_state(self) -> None:
        self._closure: np.ndarray | None = None  # warm start of the exact solver

    def extra_parameter_errors(self) -> list[str]:
        return TripodGeometry(self.r, self.l, self.m_plunger).errors()

    def extra_input_errors(self) -> list[str]:
        return self.angle_bound_errors("beta", "beta_max")

    def start(self, start_time: float) -> None:
        self._closure = None
        super().start(start_time)

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in and inputs."""
        phi, beta, omega = self.phi_in, self.beta, self.omega_in
        r, l, m = self.r, self.l, self.m_plunger
        rho = orbit_radius(beta, r)
        if self.kinematics == EXACT:
            pose = exact_pose(phi, beta, r, l, start=self._closure)
            self._closure = np.concatenate([[pose.phi_out], pose.swing])
            self.phi_out = float(pose.phi_out)
            ratio = float(pose.speed_ratio)
            self.theta = float(pose.cone_angle)
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
