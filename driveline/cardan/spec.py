"""Interface of the ``CardanJoint`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..variables import SHAFT_ANGLE_NOMINAL, DefaultExperiment, ModelSpec, Relation, State, Variable

JOINT = ("phi_in", "beta", "phase")  # the joint's position

SPEC = ModelSpec(
    name="CardanJoint",
    description=(
        "Cardan (Hooke) joint, exact kinematics (seed 003): output angle, speed, acceleration "
        "and input torque of a lossless joint. Angles: the input yoke lies in the bend plane at "
        "phi_in = phase, where phi_out = phi_in."
    ),
    variables=(
        Variable("beta_max", "parameter", math.radians(45.0),
                 "Largest accepted bend angle beta (guard, below 90 deg)", "rad", "deg",
                 min=0.0, max=0.5 * math.pi, max_exclusive=True),
        Variable("phase", "parameter", 0.0,
                 "Yoke phase: input angle phi_in at which the input yoke lies in the bend plane "
                 "(seed's gamma_1 = phi_in - phase)", "rad", "deg"),
        Variable("phi_in_start", "parameter", 0.0, "Input shaft angle phi_in at the start time", "rad", "deg"),
        Variable("omega_in", "input", 1000.0 * math.pi / 30.0,
                 "Input shaft speed omega_1 (held over a step)", "rad/s", "rpm"),
        Variable("beta", "input", math.radians(20.0),
                 "Bend angle beta between the axles (seed's beta; 0 = straight through)", "rad", "deg",
                 min=0.0, max=0.5 * math.pi),
        Variable("T_load", "input", 100.0, "Load torque acting on the output shaft", "N.m"),
        Variable("phi_in", "output", 0.0, "Input shaft angle, integrated from omega_in", "rad", "deg"),
        Variable("phi_out", "output", 0.0,
                 "Output shaft angle: phase + gamma_2 with tan gamma_1 = cos beta tan gamma_2 (C2), unwrapped",
                 "rad", "deg", depends_on=JOINT),
        Variable("omega_out", "output", 0.0,
                 "Output shaft speed omega_2 = omega_1 cos beta / (1 - sin^2 beta cos^2 gamma_1) (C3)",
                 "rad/s", "rpm", depends_on=(*JOINT, "omega_in")),
        Variable("alpha_in", "input", 0.0,
                 "Input shaft angular acceleration a_1 = d(omega_in)/dt, used in alpha_out (C4); until the host "
                 "sets it non-zero (or omega_in's input derivative), the backward difference of the last two "
                 "omega_in samples instead, said in the log at the start", "rad/s2", derivative="omega_in"),
        Variable("alpha_out", "output", 0.0,
                 "Output shaft acceleration a_2 (C4) with a_1 = alpha_in (or its estimate while alpha_in is 0)",
                 "rad/s2", depends_on=(*JOINT, "omega_in", "alpha_in")),
        Variable("T_in", "output", 0.0,
                 "Input torque from the power balance T_in omega_1 = T_load omega_2", "N.m",
                 depends_on=(*JOINT, "T_load")),
        Variable("speed_ratio", "output", 1.0, "Kinematic ratio omega_2 / omega_1 (C3)", "1", depends_on=JOINT),
        Variable("speed_fluctuation", "output", 0.0,
                 "Output-speed fluctuation (max - min) / mean = tan beta sin beta at the current beta (C5)", "1",
                 depends_on=("beta",)),
    ),
    default_experiment=DefaultExperiment(0.0, 0.12, 1e-4),
    relations=(Relation("beta", "<=", "beta_max"),),
    states=(State("phi_in", ("phi_in_start",), derivative="omega_in", nominal=SHAFT_ANGLE_NOMINAL),),
)
