"""Time stepping of the speed source: closed-form speed, angle and acceleration at each time."""

from __future__ import annotations

import math

from ..model import TimeSourceModel
from .spec import SPEC


class SpeedSourceModel(TimeSourceModel):
    """The ``SpeedSource`` co-simulation model: outputs are exact functions of time."""

    spec = SPEC

    def at_time(self, t: float) -> None:
        w = 2.0 * math.pi * self.sine_frequency
        a = self.sine_amplitude
        self.omega_out = self.omega_out_start + self.ramp_rate * t + a * math.sin(w * t)
        self.alpha_out = self.ramp_rate + a * w * math.cos(w * t)
        oscillation = a * (1.0 - math.cos(w * t)) / w if w > 0.0 else 0.0
        self.phi_out = self.phi_out_start + self.omega_out_start * t + 0.5 * self.ramp_rate * t * t + oscillation
