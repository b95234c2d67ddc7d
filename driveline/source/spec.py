"""Interface of the ``SpeedSource`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..variables import SHAFT_ANGLE_NOMINAL, DefaultExperiment, ModelSpec, State, Variable

RPM = math.pi / 30.0
SPEED = ("omega_out_start", "ramp_rate", "sine_amplitude", "sine_frequency")

SPEC = ModelSpec(
    name="SpeedSource",
    description=(
        "Shaft speed source: omega_out(t) = omega_out_start + ramp_rate t + sine_amplitude sin(2 pi sine_frequency t), "
        "with the shaft angle phi_out integrated exactly. Drives the other FMUs in system simulations."
    ),
    variables=(
        Variable("omega_out_start", "parameter", 500.0 * RPM, "Speed at t = 0", "rad/s", "rpm"),
        Variable("ramp_rate", "parameter", 2500.0 * RPM, "Slope of the speed ramp", "rad/s2"),
        Variable("sine_amplitude", "parameter", 50.0 * RPM, "Amplitude of the superposed speed oscillation",
                 "rad/s", "rpm", min=0.0),
        Variable("sine_frequency", "parameter", 5.0, "Frequency of the superposed speed oscillation", "Hz", min=0.0),
        Variable("phi_out_start", "parameter", 0.0, "Shaft angle at t = 0", "rad", "deg"),
        Variable("omega_out", "output", 0.0, "Shaft speed omega_out(t)", "rad/s", "rpm", depends_on=SPEED),
        Variable("phi_out", "output", 0.0, "Shaft angle, the exact integral of omega_out from t = 0", "rad", "deg"),
        Variable("alpha_out", "output", 0.0, "Shaft acceleration d(omega_out)/dt", "rad/s2", depends_on=SPEED[1:]),
    ),
    default_experiment=DefaultExperiment(0.0, 1.0, 1e-3),
    states=(State("phi_out", ("phi_out_start", *SPEED), derivative="omega_out",
                  nominal=SHAFT_ANGLE_NOMINAL),),
)
