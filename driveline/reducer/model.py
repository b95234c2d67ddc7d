"""Time stepping of the universal reducer: integrates phi_in; ratio and strength are algebraic.

The input speed is held over each step, so phi_in grows by ``omega_in * h`` and
``phi_out = phi_in / i`` follows exactly, whatever the intersection angle does between or within steps
(the RCRCR kinematics do not depend on it). The loads are the seed's quasi-static
relations at its critical position, evaluated at the current intersection angle and torque.
"""

from __future__ import annotations

from ..model import DrivenShaftModel
from .mechanics import connecting_shaft_loads, cylinder_slide, shaft_stress, transmission_ratio
from .spec import SPEC


class UniversalReducerModel(DrivenShaftModel):
    """The ``UniversalReducer`` co-simulation model (inputs held constant over a step)."""

    spec = SPEC

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in and inputs."""
        i = transmission_ratio(self.z1, self.z2)
        self.speed_ratio = 1.0 / i
        self.phi_out = self.phi_in / i
        self.omega_out = self.omega_in / i
        self.T_in = self.T_load / i
        self.s_b = float(cylinder_slide(self.phi_in, self.intersection_angle, self.e))
        geometry = (self.intersection_angle, self.z1, self.z2, self.module, self.e, self.L1)
        loads = connecting_shaft_loads(self.T_in, *geometry)
        stress = shaft_stress(loads.M_C, loads.M_C1, self.r_shaft)
        self.M_E, self.M_C1 = float(loads.M_E), float(loads.M_C1)
        self.M_B, self.M_C = float(loads.M_B), float(loads.M_C)
        self.sigma_bend, self.tau_torsion = float(stress.sigma), float(stress.tau)
        self.sigma_eq = float(stress.sigma_eq)
        self.utilisation = self.sigma_eq / self.sigma_allow
        unit = connecting_shaft_loads(1.0, *geometry)
        self.T_in_allow = self.sigma_allow / float(shaft_stress(unit.M_C, unit.M_C1, self.r_shaft).sigma_eq)
