"""Interface of the ``TorqueSource`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

from ..variables import DefaultExperiment, ModelSpec, Variable

SPEC = ModelSpec(
    name="TorqueSource",
    description=(
        "Motor torque source: T_start until t_ramp, then a straight ramp over ramp_time to T_level, held "
        "after (a launch). Drives VehicleDriveline's T_motor in system simulations."
    ),
    variables=(
        Variable("T_start", "parameter", 0.0, "Torque before the ramp", "N.m"),
        Variable("T_level", "parameter", 140.0, "Torque reached at the ramp's end and held (half the peak of "
                 "VehicleDriveline's default car)", "N.m"),
        Variable("t_ramp", "parameter", 0.0, "Time the ramp starts", "s"),
        Variable("ramp_time", "parameter", 0.5, "Duration of the ramp (0: a step at t_ramp)", "s", min=0.0),
        Variable("T_motor", "output", 0.0, "Motor torque at the time reached", "N.m"),
    ),
    default_experiment=DefaultExperiment(0.0, 2.0, 1e-3),
)
