"""Interface of the ``CriticalSpeeds`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

from ..variables import DefaultExperiment, ModelSpec, Relation, Variable

STRUCTURE = "Driveline structure (tunable: a change is re-analysed at the next step)"
#: The parameters of the structure, what every output is computed from (``depends_on``)
SHAFT = ("L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint", "Jd_joint", "k_bearing", "shear",
         "layout")
WHIRL = (*SHAFT, "omega_in", "omega_in_max")
RESONANCE = (*WHIRL, "orders")
UNBALANCE = (*SHAFT, "omega_in", "c_bearing", "unbalance", "unbalance_position")
#: Smallest accepted omega_in_max [rad/s], far below any driveline speed and far above where the
#: whirl and damping tables' splines over [0, omega_in_max] overflow (their knot spacing squared).
OMEGA_IN_MAX_MIN = 1e-3

SPEC = ModelSpec(
    name="CriticalSpeeds",
    description=(
        "Bending critical speeds of a driveline shaft by the transfer matrix method (Hruby, Nahlik "
        "2021; exact Timoshenko- or Rayleigh-beam segments with gyroscopic coupling): critical speeds, "
        "whirl frequencies at the current speed, the nearest order resonance of the couplings, and the "
        "unbalance response with bearing damping (finite elements)."
    ),
    variables=(
        Variable("L_shaft", "parameter", 1.4, f"{STRUCTURE}: tube length", "m", "mm",
                 min=0.0, min_exclusive=True, variability="tunable"),
        Variable("D_outer", "parameter", 0.0762, f"{STRUCTURE}: tube outer diameter", "m", "mm",
                 min=0.0, min_exclusive=True, variability="tunable"),
        Variable("D_inner", "parameter", 0.0729, f"{STRUCTURE}: tube inner diameter, below D_outer", "m", "mm",
                 min=0.0, variability="tunable"),
        Variable("E", "parameter", 2.1e11, f"{STRUCTURE}: Young's modulus of the tube", "Pa", "MPa",
                 min=0.0, min_exclusive=True, variability="tunable"),
        Variable("density", "parameter", 7850.0, f"{STRUCTURE}: density of the tube", "kg/m3",
                 min=0.0, min_exclusive=True, variability="tunable"),
        Variable("m_joint", "parameter", 2.5, f"{STRUCTURE}: mass of the joint at each end", "kg", min=0.0,
                 variability="tunable"),
        Variable("Jp_joint", "parameter", 0.004, f"{STRUCTURE}: polar moment of inertia of each joint",
                 "kg.m2", min=0.0, variability="tunable"),
        Variable("Jd_joint", "parameter", 0.002, f"{STRUCTURE}: diametral moment of inertia of each joint",
                 "kg.m2", min=0.0, variability="tunable"),
        Variable("k_bearing", "parameter", 1e7, f"{STRUCTURE}: stiffness of the bearing at each end", "N/m",
                 min=0.0, min_exclusive=True, variability="tunable"),
        Variable("c_bearing", "parameter", 500.0, f"{STRUCTURE}: damping of the bearing at each end (the "
                 "unbalance response and damping_ratio; the critical speeds are those of the undamped shaft; "
                 "at most 1e9 N.s/m, far beyond any bearing or squeeze-film damper: the damped eigenproblem "
                 "of 1e300 spans more than double precision)",
                 "N.s/m", min=0.0, max=1e9, variability="tunable"),
        Variable("shear", "parameter", True, f"{STRUCTURE}: shear deformation of the tube (Timoshenko beam, "
                 "Cowper's coefficient); false: Rayleigh beam", type="Boolean", variability="tunable"),
        Variable("unbalance", "parameter", 1e-4, "Unbalance of the one-piece tube (mass x eccentricity; a "
                 "layout brings its own [[unbalances]])", "kg.m", "g.mm", min=0.0, variability="tunable"),
        Variable("unbalance_position", "parameter", 0.5,
                 "Axial position of the unbalance on the one-piece tube, as a fraction of its length", "1",
                 min=0.0, max=1.0, variability="tunable"),
        Variable("response_position", "parameter", 0.5,
                 "Axial position of unbalance_response, as a fraction of the driveline's length", "1",
                 min=0.0, max=1.0, variability="tunable"),
        Variable("layout", "parameter", "",
                 "Driveline description (TOML) replacing the one-piece tube above: a file path ending in "
                 "'.toml' (any case; a relative path is relative to the importing process's working "
                 "directory), or the name of a description shipped in the FMU ('two_piece_propshaft', or "
                 "'two_piece_propshaft_hinged' with its centre joint as a hinge); "
                 "empty = the one-piece tube", type="String", variability="tunable"),
        Variable("orders", "parameter", "1,2,3",
                 "Excitation orders watched for resonance (1, 2: Cardan joints; 3: tripod coupling)",
                 type="String", variability="tunable"),
        Variable("band", "parameter", 0.1,
                 "Warning band: resonance_warning when |omega_in - resonance speed| < band * resonance speed",
                 "1", min=0.0, variability="tunable"),
        Variable("omega_in_max", "parameter", 1500.0,
                 "Largest accepted |omega_in|; the whirl frequencies are tabulated up to it (at least "
                 f"{OMEGA_IN_MAX_MIN:g} rad/s: the splines of the whirl and damping tables over [0, omega_in_max] "
                 "overflow at tiny spans: 1e-140 rad/s measured)", "rad/s", "rpm",
                 min=OMEGA_IN_MAX_MIN, variability="tunable"),
        Variable("omega_in", "input", 300.0, "Current shaft speed (sign ignored)", "rad/s", "rpm"),
        Variable("omega_crit_1", "output", 0.0,
                 "First bending critical speed: synchronous whirl that unbalance excites (1e5 rad/s when none "
                 "lies below that search limit)", "rad/s", "rpm", depends_on=SHAFT),
        Variable("omega_crit_2", "output", 0.0, "Second bending critical speed (1e5 rad/s if missing)",
                 "rad/s", "rpm", depends_on=SHAFT),
        Variable("omega_crit_3", "output", 0.0, "Third bending critical speed (1e5 rad/s if missing)",
                 "rad/s", "rpm", depends_on=SHAFT),
        Variable("critical_speed_count", "output", 0,
                 "Number of critical speeds found below 1e5 rad/s, at most 3 (a short, stiff shaft has "
                 "fewer)", type="Integer", depends_on=SHAFT),
        Variable("whirl_forward_1", "output", 0.0, "First forward whirl frequency at the current speed",
                 "rad/s", "rpm", depends_on=WHIRL),
        Variable("whirl_forward_2", "output", 0.0, "Second forward whirl frequency at the current speed",
                 "rad/s", "rpm", depends_on=WHIRL),
        Variable("whirl_backward_1", "output", 0.0, "First backward whirl frequency at the current speed",
                 "rad/s", "rpm", depends_on=WHIRL),
        Variable("whirl_backward_2", "output", 0.0, "Second backward whirl frequency at the current speed",
                 "rad/s", "rpm", depends_on=WHIRL),
        Variable("speed_ratio", "output", 0.0, "|omega_in| / omega_crit_1", "1", depends_on=(*SHAFT, "omega_in")),
        Variable("resonance_order", "output", 0,
                 "Order k of the closest order resonance (k |omega_in| = whirl), closest by relative margin",
                 type="Integer", depends_on=RESONANCE),
        Variable("resonance_whirl", "output", 0,
                 "Whirl direction of the closest order resonance: 1 forward, -1 backward", type="Integer",
                 depends_on=RESONANCE),
        Variable("resonance_speed", "output", 0.0, "Shaft speed of the closest order resonance", "rad/s", "rpm",
                 depends_on=RESONANCE),
        Variable("resonance_margin", "output", 0.0,
                 "(|omega_in| - resonance_speed) / resonance_speed: negative below the resonance", "1",
                 depends_on=RESONANCE),
        Variable("resonance_count", "output", 0,
                 "Number of order resonances (all watched orders, both whirl directions) within the band",
                 type="Integer", depends_on=(*RESONANCE, "band")),
        Variable("resonance_warning", "output", False, "True when resonance_count > 0", type="Boolean",
                 depends_on=(*RESONANCE, "band")),
        Variable("unbalance_response", "output", 0.0,
                 "Unbalance response at response_position and the current speed: major semi-axis of the orbit",
                 "m", "mm", depends_on=(*UNBALANCE, "response_position")),
        Variable("bearing_force_max", "output", 0.0,
                 "Largest force a bearing transmits at the current speed (major semi-axis of its force orbit)", "N",
                 depends_on=UNBALANCE),
        Variable("damping_ratio", "output", 0.0,
                 "Damping ratio of the unbalance-excited whirl mode whose damped frequency is nearest |omega_in|", "1",
                 depends_on=(*WHIRL, "c_bearing")),
    ),
    default_experiment=DefaultExperiment(0.0, 1.0, 1e-2),
    relations=(
        Relation("D_inner", "<", "D_outer"),
        Relation("omega_in", "<=", "omega_in_max"),
        Relation("omega_in", ">=", "omega_in_max", scale=-1.0),
    ),
)
