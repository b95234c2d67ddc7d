"""Interface of the ``TripodCoupling`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..variables import SHAFT_ANGLE_NOMINAL, DefaultExperiment, ModelSpec, Relation, State, Variable

CLOSED_FORM, EXACT = 0, 1
PLAIN_TRIPOD, SINGLE_ROLLER, DOUBLE_ROLLER = 0, 1, 2  # tripod_type
#: Rolling resistance of a roller on its track, tangential force over normal force: a needle roller and cage
#: assembly's friction coefficient, 0.0020 to 0.0030 (JTEKT/Koyo rolling bearing catalogue, table of friction
#: coefficients; docs/tripod_coupling.md, "Roller tripods").
ROLLING_RESISTANCE = 0.0025
#: The largest bend angle the model accepts with any beta_max: the declared max of beta and of beta_max.
BETA_LIMIT = math.radians(60.0)
RATES_FROM_INPUTS, RATES_FROM_SAMPLES, RATES_AUTOMATIC = 0, 1, 2
# What the outputs are computed from (``depends_on``): the joint's position, the plungers' inertia,
# the rates of speed and bend, the plungers' forces and the forces with friction. An output's list is
# the union over the modes: the seed's eqs 20, 30, 33, 34 and the leading order need fewer, the exact
# reactions (a_plunger_sum, Rz_out, Rx_in, Ry_in with the bend's rates, the load and friction) more.
# The moving housing: psi turns the bend plane (the position), its rates the speeds and accelerations
# relative to that plane, plunge_dot the plungers' sliding speed in the grooves (the friction alone).
POSITION = ("phi_in", "beta", "psi", "r", "l", "kinematics")
PLUNGERS = (*POSITION, "omega_in", "m_plunger", "alpha_in", "beta_dot", "beta_ddot", "psi_dot", "psi_ddot",
            "beta_rate")
FORCES = (*PLUNGERS, "T_load", "mu", "v_slip", "tripod_type", "mu_roll", "roller_radius", "plunge_dot",
          "roller_bore_radius")
FRICTION = tuple(name for name in FORCES if name != "kinematics")  # zero without friction, which needs the exact
ARM_OUTPUTS = tuple(
    Variable(f"{name}{j}", "output", 0.0, f"{text} (arm {j}: groove at phi_in + {120 * (j - 1)} deg)", "N",
             depends_on=depends_on)
    for name, text, depends_on in (
        ("F_arm", "Force of the ball on tripod arm, in the tripod plane normal to the arm (the seed's F)", FORCES),
        ("F_plunger", "Axial force of the ball joint on its plunger along Z', m times its acceleration", PLUNGERS),
    )
    for j in (1, 2, 3)
)

SPEC = ModelSpec(
    name="TripodCoupling",
    description=(
        "Tripod sliding universal coupling with a self-aligning output bearing (Xiu, Chang, Ju, "
        "Zheng 2024): output angle, speed and torque, pin force and bearing reactions. Angles: "
        "phi_in = 0 with plunger groove 1 in the bend plane on the outer side of the bend when psi = 0; the "
        "housing's motion enters as the bend plane's angle psi about Z' with its rates and the plunge rate."
    ),
    variables=(
        Variable("r", "parameter", 0.026, "Groove radius r: plunger-groove axis to input axis (seed sec. 2)",
                 "m", "mm", min=0.0, min_exclusive=True),
        Variable("l", "parameter", 0.700, "Distance l from the tripod centre to the output self-aligning bearing centre",
                 "m", "mm", min=0.0),
        Variable("m_plunger", "parameter", 0.2, "Plunger (sliding pin) mass m, eqs 28-34", "kg", min=0.0),
        Variable("beta_max", "parameter", math.radians(45.0),
                 "Largest accepted bend angle beta (guard; the exact solver is verified up to 60 deg)",
                 "rad", "deg", min=0.0, max=BETA_LIMIT),
        Variable("kinematics", "parameter", CLOSED_FORM,
                 "Kinematics of phi_out: 0 = closed form (eq 18, small r/l), 1 = exact closed-loop solution",
                 type="Integer", min=CLOSED_FORM, max=EXACT),
        Variable("seed_reactions", "parameter", 0,
                 "1 = a_plunger_sum, Rz_out, Rx_in, Ry_in from the seed's eqs 20, 30, 33, 34 as printed "
                 "(for comparison with the paper); 0 = from the force balance",
                 type="Integer", min=0, max=1),
        Variable("mu", "parameter", 0.0,
                 "Coulomb friction coefficient of both sliding pairs per arm (plunger in groove, ball along arm); "
                 "exact kinematics only", "1", min=0.0),
        Variable("v_slip", "parameter", 1e-3,
                 "Slip speed of the friction's regularised sign u/sqrt(1 + u^2), u = sliding speed / v_slip",
                 "m/s", min=0.0, min_exclusive=True),
        Variable("phi_in_start", "parameter", 0.0, "Input shaft angle phi_in at the start time", "rad", "deg"),
        Variable("omega_in", "input", 2000.0 * math.pi / 30.0,
                 "Input shaft speed omega_1 at the step's start (rising at alpha_in over the step)",
                 "rad/s", "rpm"),
        Variable("beta", "input", math.radians(30.0),
                 "Bend angle beta between input and output axes, at most beta_max (start value 45 deg; the "
                 "declared max is beta_max's own); a start value beyond it is refused at initialisation",
                 "rad", "deg", min=0.0, max=BETA_LIMIT),
        Variable("alpha_in", "input", 0.0,
                 "Input shaft angular acceleration d(omega_in)/dt over the step: phi_in advances by "
                 "omega_in h + alpha_in h^2/2 and the outputs at the step's end use omega_in + alpha_in h",
                 "rad/s2", derivative="omega_in"),
        Variable("T_load", "input", 100.0,
                 "Load torque T0 on the output shaft, about its own axis, resisting its rotation (eq 22)", "N.m"),
        Variable("phi_in", "output", 0.0, "Input shaft angle phi_1, integrated from omega_in", "rad", "deg"),
        Variable("phi_out", "output", 0.0, "Output shaft angle phi_0 (eq 18 or exact kinematics)", "rad", "deg",
                 depends_on=POSITION),
        Variable("delta_phi", "output", 0.0, "Angular deviation phi_out - phi_in (eq 18)", "rad", "deg",
                 depends_on=POSITION),
        Variable("omega_out", "output", 0.0,
                 "Output shaft speed at the current bend, psi_dot + (omega_in - psi_dot) d(phi_out)/d(phi_in) "
                 "(derivative of eq 18 or of the exact kinematics); d(phi_out)/dt only while beta is constant: a "
                 "moving bend adds d(phi_out)/d(beta) beta_dot", "rad/s", "rpm",
                 depends_on=(*POSITION, "omega_in", "psi_dot")),
        Variable("omega_spin", "output", 0.0,
                 "Angular velocity of the output shaft about its own axis, relative to the housing (T_in omega_in "
                 "= T0 omega_spin + dKE/dt with the housing at rest); differs from omega_out by the cone's "
                 "geometric phase", "rad/s", "rpm",
                 depends_on=(*POSITION, "omega_in", "beta_dot", "psi_dot", "beta_rate")),
        Variable("T_in", "output", 0.0, "Driving torque on the input shaft about Z', plunger inertia included",
                 "N.m", depends_on=FORCES),
        Variable("F_pin", "output", 0.0, "Force F on each tripod arm, eq 24 with corrected eq 21: T0/(3r + 3rho)", "N",
                 depends_on=("T_load", "beta", "r")),
        Variable("rho", "output", 0.0, "Orbit radius rho of the tripod centre, r(1 - cos beta)/(2 cos beta)",
                 "m", "mm", depends_on=("beta", "r")),
        Variable("theta", "output", 0.0, "Cone angle theta of the output shaft about the bearing centre", "rad", "deg",
                 depends_on=POSITION),
        Variable("a_plunger_sum", "output", 0.0, "Sum a1 + a2 + a3 of the plungers' axial accelerations (eq 20)",
                 "m/s2", depends_on=(*POSITION, "omega_in", "alpha_in", "beta_dot", "beta_ddot", "psi_dot",
                                     "psi_ddot", "beta_rate", "seed_reactions")),
        Variable("Rz_out", "output", 0.0,
                 "Output self-aligning bearing on the output shaft: axial force R_z'' along the shaft (eq 30)", "N",
                 depends_on=(*FORCES, "seed_reactions")),
        Variable("Rx_out", "output", 0.0,
                 "Output bearing on the output shaft: radial force along E1 (in the bend plane, normal to the shaft)",
                 "N", depends_on=FORCES),
        Variable("Ry_out", "output", 0.0, "Output bearing on the output shaft: radial force along E2, the bend plane's normal swung with the shaft", "N",
                 depends_on=FORCES),
        Variable("Rx_in", "output", 0.0,
                 "Input bearing on the input shaft: force R_x' along the housing's X' (eq 33 at psi = 0)", "N",
                 depends_on=(*FORCES, "seed_reactions")),
        Variable("Ry_in", "output", 0.0,
                 "Input bearing on the input shaft: force R_y' along the housing's Y' (eq 34 at psi = 0)", "N",
                 depends_on=(*FORCES, "seed_reactions")),
        Variable("Mx_in", "output", 0.0, "Input bearing on the input shaft: moment about the housing's X' through the joint centre O",
                 "N.m", depends_on=FORCES),
        Variable("My_in", "output", 0.0, "Input bearing on the input shaft: moment about the housing's Y' through the joint centre O",
                 "N.m", depends_on=FORCES),
        Variable("Rz_in", "output", 0.0,
                 "Input bearing on the input shaft: axial force along Z'; the joint's generated axial force "
                 "on its housing is -Rz_in (friction only)", "N", depends_on=FRICTION),
        Variable("P_friction", "output", 0.0, "Power dissipated by friction in the six sliding pairs (sliding speeds relative to the housing)", "W",
                 depends_on=FRICTION),
        Variable("efficiency", "output", 1.0,
                 "Instantaneous efficiency, delivered over supplied power, with P_load = T_load omega_spin: drive "
                 "(P_load >= 0) P_load / (P_load + P_friction), 1 without power flow; coast (the load drives, "
                 "P_load + P_friction <= 0) (P_load + P_friction) / P_load; 0 in between (friction takes all)",
                 "1", depends_on=FRICTION),
        *ARM_OUTPUTS,
        # appended after every other variable: value references are positions, so those of
        # the variables above stay what hosts, SSP files and reference results know
        Variable("beta_dot", "input", 0.0,
                 "Bend angle rate d(beta)/dt over the step (read as beta_rate says): the moving output bearing's "
                 "terms in the force balance; beta at the step's end is beta + beta_dot h + beta_ddot h^2/2",
                 "rad/s", derivative="beta"),
        Variable("beta_ddot", "input", 0.0,
                 "Bend angle acceleration d(beta_dot)/dt over the step (read as beta_rate says)",
                 "rad/s2", derivative="beta_dot"),
        Variable("beta_rate", "parameter", RATES_AUTOMATIC,
                 "Source of the bend angle's rates: 0 = the inputs beta_dot and beta_ddot, 1 = estimated "
                 "from the last three beta samples (quadratic through them; beta_dot, beta_ddot ignored), "
                 "2 = automatic: the samples until the host sets beta_dot or beta_ddot non-zero (or their input "
                 "derivatives), the inputs from then on; an information line at the start while both are 0 "
                 "(the bend plane's rates psi_dot, psi_ddot are always the inputs)",
                 type="Integer", min=RATES_FROM_INPUTS, max=RATES_AUTOMATIC),
        Variable("tripod_type", "parameter", PLAIN_TRIPOD,
                 "Joint: 0 = plain tripod (plungers sliding in the grooves, the seed's), 1 = single roller (a roller "
                 "turning and sliding on each trunnion, rolling and skewing on its track), 2 = double roller (outer "
                 "roller kept parallel to its track on needles, inner ring sliding on the trunnion); the rollers' "
                 "friction needs the exact kinematics", type="Integer", min=PLAIN_TRIPOD, max=DOUBLE_ROLLER),
        Variable("mu_roll", "parameter", ROLLING_RESISTANCE,
                 "Rolling resistance of each roller on its track, tangential over normal force (roller tripods; "
                 "their sliding contacts take mu)", "1", min=0.0),
        Variable("roller_radius", "parameter", 0.0165,
                 "Outer radius R of the rollers: the track contact lies R from the roller's centre (roller tripods)",
                 "m", "mm", min=0.0, min_exclusive=True),
        Variable("roller_bore_radius", "parameter", 0.0115,
                 "Bore radius of the roller: the single roller's on the trunnion, needles included; the double "
                 "roller's outer roller's, on which the needles of its inner ring run (assembly check)", "m", "mm",
                 min=0.0, min_exclusive=True),
        Variable("trunnion_radius", "parameter", 0.009,
                 "Radius of the trunnions (tripod arms) that carry the rollers (assembly check)", "m", "mm",
                 min=0.0, min_exclusive=True),
        Variable("track_width", "parameter", 0.0331,
                 "Width of each roller track, flank to flank (assembly check)", "m", "mm", min=0.0,
                 min_exclusive=True),
        Variable("psi", "input", 0.0,
                 "Bend-plane angle psi: the bend plane's turn about the housing axis Z' from X'Z' (psi = 0: the "
                 "output shaft leans towards -X', 90 deg towards -Y'); the arms' phase from the bend plane is "
                 "phi_in - psi; psi at the step's end is psi + psi_dot h + psi_ddot h^2/2", "rad", "deg"),
        Variable("psi_dot", "input", 0.0,
                 "Bend-plane angle rate d(psi)/dt over the step: the input shaft turns at omega_in - psi_dot "
                 "relative to the bend plane", "rad/s", derivative="psi"),
        Variable("psi_ddot", "input", 0.0, "Bend-plane angle acceleration d(psi_dot)/dt over the step", "rad/s2",
                 derivative="psi_dot"),
        Variable("plunge_dot", "input", 0.0,
                 "Plunge rate: axial speed of the spider (tripod centre) relative to the housing along Z', positive "
                 "towards the output shaft; adds to every plunger's (roller's) sliding speed in its groove, which "
                 "the groove friction and the rollers' rolling take", "m/s"),
    ),
    default_experiment=DefaultExperiment(0.0, 0.1, 1e-4),
    relations=(
        Relation("l", ">", "r", reason="the bearing centre lies beyond the grooves"),
        Relation("beta", "<=", "beta_max"),
        Relation("roller_bore_radius", "<", "roller_radius", reason="the roller's bore lies inside the roller"),
        Relation("trunnion_radius", "<=", "roller_bore_radius",
                 reason="the trunnion fits in the roller's bore: no negative clearance"),
        Relation("track_width", ">=", "roller_radius", scale=2.0,
                 reason="the roller fits in its track: no negative clearance"),
    ),
    states=(State("phi_in", ("phi_in_start",), derivative="omega_in", nominal=SHAFT_ANGLE_NOMINAL),),
)
