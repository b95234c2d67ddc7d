"""Time stepping of the Cardan joint: integrates phi_in and evaluates the exact kinematics.

The input speed is held over each step (zero-order hold), so the input angle grows by
``omega_in * h`` exactly. The seed's acceleration relation (C4) needs the input acceleration
a_1: the input ``alpha_in`` (d(omega_in)/dt, for example ``SpeedSource.alpha_out``) once the host
has set it non-zero. Until then a held signal has no acceleration of its own, yet a host that
samples a changing speed means one; the model then takes as a_1 the backward difference of
the last two samples, ``(omega_in(t_k) - omega_in(t_{k-1})) / (t_k - t_{k-1})``, which is exact
for a speed ramp a step late, and says so in the log at the start. A change made at the start
time itself (no interval yet) counts as a new initial condition: a_1 = 0.
"""

from __future__ import annotations

from ..model import DrivenShaftModel
from . import kinematics
from .spec import SPEC

ACCELERATION_ESTIMATED = ("alpha_in = 0 at the start: the input acceleration in alpha_out is the backward "
                          "difference of the last two omega_in samples until the host sets alpha_in non-zero (or "
                          "omega_in's input derivative), so alpha_out has none at the start and lags a step on a "
                          "ramp")


class CardanJointModel(DrivenShaftModel):
    """The ``CardanJoint`` co-simulation model (inputs held constant over a step)."""

    spec = SPEC
    dependency_points = ({"phase": 0.3, "phi_in_start": 0.2, "alpha_in": 30.0},)
    native_constants = {"ACCELERATION_ESTIMATED": ACCELERATION_ESTIMATED}

    def reset_internal_state(self) -> None:
        self._omega_sample = 0.0  # omega_in of the last evaluation [rad/s]
        self._sample_time: float | None = None  # time of that evaluation [s]
        self._acceleration_set = False  # the host has set alpha_in non-zero

    def internal_from_saved(self, state: dict) -> dict:
        """Whether the host set alpha_in (a bool)."""
        if not isinstance(state["_acceleration_set"], bool):
            raise ValueError("the saved choice of the input acceleration is not a bool")
        return {}

    def start_notice(self) -> str | None:
        """alpha_in left at 0: the host learns that a_1 is estimated, and how to give it."""
        return ACCELERATION_ESTIMATED if not self._acceleration_set else None

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in; a_1 the input alpha_in once set non-zero, else from this and
        the previous speed sample."""
        previous = self._sample_time
        elapsed = input_time - previous if previous is not None else 0.0
        self._acceleration_set = self._acceleration_set or self.alpha_in != 0.0
        if self._acceleration_set:
            alpha_in = self.alpha_in
        else:
            alpha_in = (self.omega_in - self._omega_sample) / elapsed if elapsed > 0.0 else 0.0
        self._omega_sample, self._sample_time = self.omega_in, input_time
        phi, beta, phase = self.phi_in, self.beta, self.phase
        ratio = float(kinematics.speed_ratio(phi, beta, phase))
        self.phi_out = float(kinematics.output_angle(phi, beta, phase))
        self.speed_ratio = ratio
        self.omega_out = self.omega_in * ratio
        self.alpha_out = float(kinematics.output_acceleration(phi, beta, self.omega_in, alpha_in, phase))
        self.T_in = self.T_load * ratio
        self.speed_fluctuation = float(kinematics.speed_fluctuation(beta))
