"""Interface of the ``UniversalReducer`` FMU: the single source for the FMI 2.0 and 3.0 builds."""

from __future__ import annotations

import math

from ..variables import SHAFT_ANGLE_NOMINAL, DefaultExperiment, ModelSpec, Relation, State, Variable

SINGULAR = "eq 21 is singular at 0 and 180 deg"
#: Largest stress [Pa] of the connecting shaft an output may report: ten times the tensile strength of
#: the strongest shaft steels (about 1 GPa). Beyond it no shaft carries the load and the rigid-body
#: statics of eqs 18-21 describe nothing; near an intersection angle of 180 deg eq 21 gave 3.2e19 Pa with status OK.
MAX_STRESS = 1e10
RATIO = ("z1", "z2")
#: The connecting shaft's bending at C and E (eqs 19, 21): load, intersection angle and geometry
BENDING = ("T_load", "intersection_angle", *RATIO, "e", "L1")

SPEC = ModelSpec(
    name="UniversalReducer",
    description=(
        "Universal reducer (Gu, Chen 2016): few-teeth-difference planetary gear driven through an "
        "RCRCR mechanism, ratio z1/(z1 - z2) at any shaft intersection angle; lossless torques and the "
        "seed's strength check of the connecting shaft (eqs 18-21). Angles: intersection_angle = 180 deg is coaxial "
        "shafts; phi_in = 0 with the eccentric normal to the bend plane."
    ),
    variables=(
        Variable("z1", "parameter", 34, "Centre (internal) gear teeth z1 (table 1)", type="Integer", min=1),
        Variable("z2", "parameter", 29, "Planet gear teeth z2, below z1 (table 1)", type="Integer", min=1),
        Variable("module", "parameter", 0.002, "Gear module m (table 1; eq 20)", "m", "mm",
                 min=0.0, min_exclusive=True),
        Variable("e", "parameter", 0.005,
                 "Eccentricity: offset r = h1 of the connecting shaft from the input and output axes "
                 "(table 1; eqs 15, 19)", "m", "mm", min=0.0, min_exclusive=True),
        Variable("L1", "parameter", 0.020,
                 "Distance L1 from B and from C to E on the connecting shafts (eq 19); the seed gives no "
                 "value, the start value is a placeholder", "m", "mm", min=0.0),
        Variable("r_shaft", "parameter", 0.015,
                 "Radius of the connecting shaft checked at C (seed sec. 4.1: 15 mm)", "m", "mm",
                 min=0.0, min_exclusive=True),
        Variable("sigma_allow", "parameter", 60e6,
                 "Allowable stress [sigma] of the connecting shaft (seed: 45 steel, 60 MPa)", "Pa", "MPa",
                 min=0.0, min_exclusive=True),
        Variable("intersection_angle_min", "parameter", math.radians(90.0),
                 "Smallest accepted intersection angle (guard, above 0 deg)", "rad", "deg",
                 min=0.0, max=math.pi, min_exclusive=True),
        Variable("intersection_angle_max", "parameter", math.radians(170.0),
                 "Largest accepted intersection angle (guard, below 180 deg where eq 21 is singular)",
                 "rad", "deg", min=0.0, max=math.pi, max_exclusive=True),
        Variable("phi_in_start", "parameter", 0.0, "Input shaft angle phi_in at the start time", "rad", "deg"),
        Variable("omega_in", "input", 1000.0 * math.pi / 30.0,
                 "Input (carrier) speed omega_H (held over a step)", "rad/s", "rpm"),
        Variable("intersection_angle", "input", math.radians(160.0),
                 "Intersection angle between the input and output axes, the seed's alpha (= alpha_40); 180 deg = coaxial",
                 "rad", "deg", min=0.0, max=math.pi),
        Variable("T_load", "input", 68.0,
                 "Load torque M_out acting on the output shaft (eq 18); the start value, input torque 10 N.m, "
                 "passes the strength check (utilisation 0.83)", "N.m"),
        Variable("phi_in", "output", 0.0, "Input shaft angle, integrated from omega_in", "rad", "deg"),
        Variable("phi_out", "output", 0.0, "Output (centre gear) angle phi_in / i (eq 17)", "rad", "deg",
                 depends_on=("phi_in", *RATIO)),
        Variable("omega_out", "output", 0.0, "Output speed omega_1 = omega_H / i (eq 17)", "rad/s", "rpm",
                 depends_on=("omega_in", *RATIO)),
        Variable("speed_ratio", "output", 0.0, "Speed ratio omega_1 / omega_H = 1 / i = (z1 - z2) / z1", "1",
                 depends_on=RATIO),
        Variable("T_in", "output", 0.0, "Input torque M_in = M_out / i (eq 18, lossless)", "N.m",
                 depends_on=("T_load", *RATIO)),
        Variable("s_b", "output", 0.0,
                 "Slide of the connecting shaft in the cylindrical pair b, e cot(a/2) sin phi_in with a the intersection "
                 "angle (eq 15)", "m", "mm", depends_on=("phi_in", "intersection_angle", "e")),
        Variable("M_E", "output", 0.0, "Moment M_E = 2 F_B L1 sin(a/2) at E, a the intersection angle (eq 19)", "N.m",
                 depends_on=BENDING),
        Variable("M_C1", "output", 0.0, "Torque M_C1 = F_t r2 on the connecting shaft at C (eq 20)", "N.m",
                 depends_on=("T_load", *RATIO, "module")),
        Variable("M_B", "output", 0.0, "Moment M_B at B from the balance eq 21", "N.m",
                 depends_on=(*BENDING, "module")),
        Variable("M_C", "output", 0.0, "Bending moment M_C at C from the balance eq 21", "N.m", depends_on=BENDING),
        Variable("sigma_bend", "output", 0.0, "Bending stress of the connecting shaft at C, M_C / W", "Pa", "MPa",
                 min=-MAX_STRESS, max=MAX_STRESS, depends_on=(*BENDING, "r_shaft")),
        Variable("tau_torsion", "output", 0.0, "Torsional stress of the connecting shaft at C, M_C1 / W_t",
                 "Pa", "MPa", min=-MAX_STRESS, max=MAX_STRESS, depends_on=("T_load", *RATIO, "r_shaft")),
        Variable("sigma_eq", "output", 0.0,
                 "Equivalent stress at C, third strength theory sqrt(sigma^2 + 4 tau^2)", "Pa", "MPa",
                 max=MAX_STRESS, depends_on=(*BENDING, "r_shaft")),
        Variable("utilisation", "output", 0.0, "sigma_eq / sigma_allow (at most 1 to pass the seed's check)", "1",
                 depends_on=(*BENDING, "r_shaft", "sigma_allow")),
        Variable("T_in_allow", "output", 0.0,
                 "Input torque at which sigma_eq reaches sigma_allow at the current intersection angle", "N.m",
                 depends_on=(*BENDING[1:], "module", "r_shaft", "sigma_allow")),
    ),
    default_experiment=DefaultExperiment(0.0, 0.5, 1e-3),
    relations=(
        Relation("z1", ">", "z2", reason="i = z1 / (z1 - z2)"),
        Relation("intersection_angle_min", "<=", "intersection_angle_max"),
        Relation("intersection_angle", ">=", "intersection_angle_min", reason=SINGULAR),
        Relation("intersection_angle", "<=", "intersection_angle_max", reason=SINGULAR),
    ),
    states=(State("phi_in", ("phi_in_start",), derivative="omega_in", nominal=SHAFT_ANGLE_NOMINAL),),
)
