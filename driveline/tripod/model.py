"""Time stepping of the tripod coupling: integrates phi_in, evaluates kinematics and forces."""

from __future__ import annotations

from ..model import DrivenShaftModel
from .outputs import coupling_outputs
from .plane_solver import Solution
from .spec import CLOSED_FORM, EXACT, SPEC


class TripodCouplingModel(DrivenShaftModel):
    """The ``TripodCoupling`` co-simulation model (inputs held constant over a step)."""

    spec = SPEC

    def reset_internal_state(self) -> None:
        self._solution: Solution | None = None  # warm start of the exact solver

    def internal_from_saved(self, state: dict) -> dict:
        """The warm start of a saved state: five floats, or none."""
        saved = state["_solution"]
        if saved is None:
            return {}
        if not (isinstance(saved, tuple) and len(saved) == len(Solution._fields)
                and all(isinstance(value, float) for value in saved)):
            raise ValueError(f"the saved warm start of the solver is not {len(Solution._fields)} floats")
        return {"_solution": Solution(*saved)}

    extra_parameter_probes = {"friction_needs_exact": {"mu": 0.05, "kinematics": CLOSED_FORM}}

    def extra_parameter_errors(self) -> list[str]:
        if self.mu > 0.0 and self.kinematics != EXACT:
            return [f"friction mu = {self.mu!r} needs the exact kinematics (kinematics = {EXACT})"]
        return []

    def start(self, start_time: float) -> None:
        self._solution = None
        super().start(start_time)

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in and inputs."""
        values, self._solution = coupling_outputs(
            self.phi_in, self.beta, self.omega_in, self.T_load,
            self.r, self.l, self.m_plunger, self.kinematics, self._solution, self.alpha_in, self.seed_reactions,
            self.mu, self.v_slip,
        )
        self.__dict__.update(values)
