"""Time stepping of the torque source: the torque is an exact function of time."""

from __future__ import annotations

from ..model import TimeSourceModel
from .spec import SPEC


def ramp_share(t: float, t_ramp: float, ramp_time: float) -> float:
    """How far the ramp has gone at ``t``: 0 before ``t_ramp``, 1 from ``t_ramp + ramp_time`` on,
    linear between (a step at ``t_ramp`` when ``ramp_time`` is 0)."""
    if t < t_ramp:
        return 0.0
    if t >= t_ramp + ramp_time:
        return 1.0
    return (t - t_ramp) / ramp_time


class TorqueSourceModel(TimeSourceModel):
    """The ``TorqueSource`` co-simulation model: the output at the time reached."""

    spec = SPEC

    def at_time(self, t: float) -> None:
        share = ramp_share(t, self.t_ramp, self.ramp_time)
        self.T_motor = self.T_start + (self.T_level - self.T_start) * share
