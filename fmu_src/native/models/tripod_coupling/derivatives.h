/* The exact partial derivatives of the native TripodCoupling FMU's outputs (its ``jacobian`` hook; the step
 * is tripod_coupling.c next to this folder), by forward-mode automatic differentiation (lib/dual.h, one
 * partial derivative per Jacobian column, COLUMN_<name>; the dual values are not the step's bit for bit, the
 * outputs come from the step, only their derivatives are used):
 *   closure_derivatives.c    the exact kinematics (plane_solver.py) by the implicit function theorem
 *   reaction_derivatives.c   the exact reactions (reactions.py, rollers.py), the friction balances' fixed points
 *   output_derivatives.c     the Jacobian of the outputs (outputs.py): modes, leading order, the seed's eqs
 */
#ifndef TRIPOD_DERIVATIVES_H
#define TRIPOD_DERIVATIVES_H

#include "fmi/fmu_instance.h"

#define DUAL_SIZE MODEL_COLUMN_COUNT
#include "lib/dual.h"

/* ---- closure_derivatives.c ------------------------------------------------------------------ */

/* The closure at its solution: the output shaft's axis (x, y), arg(alpha) (phi_out - phi_in) and
 * d(phi_out)/d(phi_in), with their partial derivatives. */
typedef struct {
    Dual x, y, twist, ratio;
} DualClosure;

/* The closure's partial derivatives at the solution (x, y) that plane_solve found for phi_in and beta
 * (cos, sin of beta: cb, sb). */
DualClosure closure_derivatives(double x, double y, Dual phi_in, Dual cb, Dual sb, double r, double l);

/* ---- reaction_derivatives.c ----------------------------------------------------------------- */

/* The step's Load in dual numbers (cb, sb: cos, sin of beta; phi_in from the bend plane, as step.h's Load) */
typedef struct {
    Dual phi_in, cb, sb, omega, omega_dot, T_load, beta_dot, beta_ddot, psi_dot, psi_ddot, plunge_dot;
    double r, l, m, friction, slip_speed;
    int tripod_type;               /* 0 plain, 1 single roller, 2 double roller */
    double mu_roll, roller_radius; /* the roller tripods' rolling resistance and rollers' outer radius */
    double roller_bore_radius;     /* the rollers' bore radius: the double roller's needles run on it */
} DualLoad;

/* The step's Reactions in dual numbers */
typedef struct {
    Dual Rx_in, Ry_in, Mx_in, My_in, T_in, Rx_out, Ry_out, Rz_out, F_arm[3], F_plunger[3], a_plunger_sum;
    Dual omega_spin, Rz_in, P_friction;
} DualReactions;

/* reactions.exact_reactions for the axis (x, y) of the closure, with friction when load->friction > 0;
 * an ArithmeticError when the friction balance's derivatives do not settle. */
Failure reaction_derivatives(const DualLoad *load, Dual x, Dual y, DualReactions *out);

/* ---- output_derivatives.c ------------------------------------------------------------------- */

/* The model's ``jacobian`` hook at the point ``data`` holds, whose outputs the step has just computed
 * from the reset internal state; ``axis``: the exact closure's solution (x, y) there, NULL in the
 * closed form. */
Failure tripod_jacobian(const ModelData *data, const double *axis, double partial[]);

#endif
