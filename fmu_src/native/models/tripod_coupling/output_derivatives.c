/* The Jacobian of the TripodCoupling outputs (outputs.coupling_outputs; the step's evaluate in
 * tripod_coupling.c) at one instant, in dual numbers seeded with the knowns omega_in, beta, alpha_in, T_load,
 * phi_in, beta_dot, beta_ddot and the housing's motion psi, psi_dot, psi_ddot, plunge_dot (always the inputs).
 *
 * The bend's rates: beta_rate = 0 reads them from the inputs; 1 estimates them from the bend samples, which
 * at one instant (internal state reset) are the current one alone: zero rates whatever the inputs, no
 * partial derivatives; 2 (automatic) reads the inputs once either is non-zero and estimates zero rates
 * while both are 0, which is what the inputs give there: the map is the inputs' everywhere, and so are its
 * partial derivatives. The efficiency's branch (drive, coast, 0 in between) is the step's, taken from its
 * outputs: at a change of branch the derivative is that of the branch taken (one-sided).
 */
#include "derivatives.h"

#include "driveline_constants.h"

#define INTEGER(name) (data->int_value[V_##name])
#define ROW(name, dual) dual_row(partial, ROW_##name, (dual))

/* reactions_closed_form.leading_order_reactions with A = 3/2 m r^2 tan(beta) / cos^2(beta), t = tan(beta / 2),
 * at the input speed relative to the bend plane */
static DualReactions leading_order(const DualLoad *load, Dual ratio, Dual pin)
{
    DualReactions out;
    double m = load->m, r = load->r, l = load->l;
    Dual cb = load->cb, tb = dual_div(load->sb, cb), half = dual_div(load->sb, dual_shift(cb, 1.0));
    Dual omega = dual_sub(load->omega, load->psi_dot), omega_dot = dual_sub(load->omega_dot, load->psi_ddot);
    Dual omega2 = dual_mul(omega, omega), T = load->T_load;
    Dual A = dual_div(dual_scale(tb, 1.5 * m * r * r), dual_mul(cb, cb));
    Dual A_omega2 = dual_mul(A, omega2);
    Dual ry_in = dual_scale(dual_mul2(T, half, dual_mul(A, omega_dot), cb), -1.0 / l);
    Dual bend = dual_div(dual_constant(m * r), dual_mul(cb, cb));
    Dual beta_dot2 = dual_mul(load->beta_dot, load->beta_dot);
    Dual bend_rates = dual_add(load->beta_ddot, dual_scale(dual_mul(tb, beta_dot2), 2.0));
    int j;
    for (j = 0; j < 3; j++) {
        Dual angle = dual_shift(load->phi_in, TRIPOD_GEOMETRY_THIRD_TURN * j), c = dual_cos(angle), s = dual_sin(angle);
        Dual inertia = dual_scale(dual_mul(tb, dual_mul2(omega2, c, omega_dot, s)), -m * r);
        Dual rates = dual_cross(c, bend_rates, dual_scale(dual_mul(omega, load->beta_dot), 2.0), s);
        out.F_plunger[j] = dual_add(inertia, dual_mul(bend, rates));
        out.F_arm[j] = pin;
    }
    out.Rx_in = dual_div(dual_neg(A_omega2), dual_scale(cb, l));
    out.Ry_in = ry_in;
    out.Mx_in = dual_sub(dual_neg(dual_mul(T, half)), dual_scale(dual_mul(tb, omega_dot), 1.5 * m * r * r));
    out.My_in = dual_neg(A_omega2);
    out.T_in = dual_add(dual_mul(T, ratio), dual_scale(dual_mul(dual_shift(dual_scale(dual_mul(tb, tb), 0.5), 1.0),
                                                                omega_dot), 3.0 * m * r * r));
    out.Rx_out = dual_scale(A_omega2, 1.0 / l);
    out.Ry_out = dual_neg(ry_in);
    out.Rz_out = dual_scale(dual_mul(A_omega2, tb), -1.0 / l);
    out.a_plunger_sum = dual_constant(0.0);
    out.Rz_in = out.P_friction = dual_constant(0.0);
    return out;
}

/* outputs.efficiency's partial derivatives on the step's branch (its values: output_power, total); where no
 * power flows (total 0 in drive) it is 1, a peak between drive and coast: derivatives 0 */
static Dual efficiency(Dual output_power, Dual total, double output_value, double total_value)
{
    if (output_value >= 0.0) {
        return total_value != 0.0 ? dual_div(output_power, total) : dual_constant(1.0);
    }
    return total_value / output_value > 0.0 ? dual_div(total, output_power) : dual_constant(0.0);
}

Failure tripod_jacobian(const ModelData *data, const double *axis, double partial[])
{
    int from_inputs = INTEGER(beta_rate) != RATES_FROM_SAMPLES;
    double r = VALUE(r), l = VALUE(l);
    Dual phi_in = dual_known(VALUE(phi_in), COLUMN_phi_in), beta = dual_known(VALUE(beta), COLUMN_beta);
    Dual omega = dual_known(VALUE(omega_in), COLUMN_omega_in), T_load = dual_known(VALUE(T_load), COLUMN_T_load);
    Dual psi = dual_known(VALUE(psi), COLUMN_psi), psi_dot = dual_known(VALUE(psi_dot), COLUMN_psi_dot);
    Dual phi = dual_sub(phi_in, psi), spin = dual_sub(omega, psi_dot); /* from the bend plane, relative to it */
    Dual cos_psi = dual_cos(psi), sin_psi = dual_sin(psi);
    Dual cb = dual_cos(beta), sb = dual_sin(beta), rho, pin, deviation, ratio, theta, omega_spin, output_power;
    double power_value = VALUE(T_load) * VALUE(omega_spin); /* the step's efficiency branch */
    DualLoad load;
    DualReactions forces;
    Failure failure = NO_FAILURE;
    load.phi_in = phi;
    load.psi_dot = psi_dot;
    load.psi_ddot = dual_known(VALUE(psi_ddot), COLUMN_psi_ddot);
    load.plunge_dot = dual_known(VALUE(plunge_dot), COLUMN_plunge_dot);
    load.cb = cb;
    load.sb = sb;
    load.omega = omega;
    load.omega_dot = dual_known(VALUE(alpha_in), COLUMN_alpha_in);
    load.T_load = T_load;
    load.beta_dot = from_inputs ? dual_known(VALUE(beta_dot), COLUMN_beta_dot) : dual_constant(0.0);
    load.beta_ddot = from_inputs ? dual_known(VALUE(beta_ddot), COLUMN_beta_ddot) : dual_constant(0.0);
    load.r = r;
    load.l = l;
    load.m = VALUE(m_plunger);
    load.friction = VALUE(mu);
    load.slip_speed = VALUE(v_slip);
    load.tripod_type = INTEGER(tripod_type);
    load.mu_roll = VALUE(mu_roll);
    load.roller_radius = VALUE(roller_radius);
    load.roller_bore_radius = VALUE(roller_bore_radius);
    rho = dual_div(dual_scale(dual_sub(dual_constant(1.0), cb), r), dual_scale(cb, 2.0));
    pin = dual_div(T_load, dual_scale(dual_shift(rho, r), 3.0));
    if (axis != NULL) {
        DualClosure closure = closure_derivatives(axis[0], axis[1], phi, cb, sb, r, l);
        deviation = closure.twist;
        ratio = closure.ratio;
        theta = dual_asin(dual_sqrt(dual_mul2(closure.x, closure.x, closure.y, closure.y)));
        failure = reaction_derivatives(&load, closure.x, closure.y, &forces);
        omega_spin = forces.omega_spin;
    } else {
        /* eq 18 with the seed's phi and its derivative */
        Dual amplitude = dual_mul(dual_div(dual_scale(dual_sub(dual_constant(1.0), cb), r),
                                           dual_scale(dual_shift(cb, 1.0), 2.0 * l)), dual_tan(beta));
        Dual phase = dual_scale(dual_shift(phi, TRIPOD_CLOSED_FORM_PAPER_PHASE), 3.0);
        deviation = dual_mul(amplitude, dual_cos(phase));
        ratio = dual_sub(dual_constant(1.0), dual_scale(dual_mul(amplitude, dual_sin(phase)), 3.0));
        theta = dual_asin(dual_scale(rho, 1.0 / l));
        forces = leading_order(&load, ratio, pin);
        omega_spin = dual_add(dual_mul(spin, ratio), psi_dot);
    }
    output_power = dual_mul(T_load, omega_spin);
    ROW(phi_out, dual_add(phi_in, deviation)); /* phi + deviation + psi (M2) */
    ROW(delta_phi, deviation);
    ROW(omega_out, dual_add(dual_mul(spin, ratio), psi_dot)); /* (M7) */
    ROW(omega_spin, omega_spin);
    ROW(T_in, forces.T_in);
    ROW(F_pin, pin);
    ROW(rho, rho);
    ROW(theta, theta);
    ROW(a_plunger_sum, forces.a_plunger_sum);
    ROW(Rz_out, forces.Rz_out);
    ROW(Rx_out, forces.Rx_out);
    ROW(Ry_out, forces.Ry_out);
    /* from the bend plane's frame into the housing's X'Y' (M8) */
    ROW(Rx_in, dual_cross(cos_psi, forces.Rx_in, sin_psi, forces.Ry_in));
    ROW(Ry_in, dual_mul2(sin_psi, forces.Rx_in, cos_psi, forces.Ry_in));
    ROW(Mx_in, dual_cross(cos_psi, forces.Mx_in, sin_psi, forces.My_in));
    ROW(My_in, dual_mul2(sin_psi, forces.Mx_in, cos_psi, forces.My_in));
    ROW(Rz_in, forces.Rz_in);
    ROW(P_friction, forces.P_friction);
    ROW(efficiency, efficiency(output_power, dual_add(output_power, forces.P_friction), power_value,
                               power_value + VALUE(P_friction)));
    ROW(F_arm1, forces.F_arm[0]);
    ROW(F_arm2, forces.F_arm[1]);
    ROW(F_arm3, forces.F_arm[2]);
    ROW(F_plunger1, forces.F_plunger[0]);
    ROW(F_plunger2, forces.F_plunger[1]);
    ROW(F_plunger3, forces.F_plunger[2]);
    if (INTEGER(seed_reactions)) {
        /* eqs 20, 30, 33, 34 as printed, with the seed's phi */
        double m = VALUE(m_plunger);
        Dual omega_squared = dual_mul(spin, spin), tan_beta = dual_tan(beta), seed_x, seed_y;
        Dual seed_phi = dual_shift(phi, TRIPOD_CLOSED_FORM_PAPER_PHASE), cos_3phi = dual_cos(dual_scale(seed_phi, 3.0));
        Dual orbit = dual_mul(dual_mul(omega_squared, rho), cos_3phi);
        Dual a_sum = dual_scale(dual_mul(orbit, sb), -6.0);
        Dual squared = dual_mul(dual_mul(dual_mul(rho, rho), omega_squared), tan_beta);
        ROW(a_plunger_sum, a_sum);                                                           /* eq 20 */
        ROW(Rz_out, dual_scale(dual_mul(orbit, tan_beta), -6.0 * m));                       /* eq 30 */
        seed_x = dual_scale(dual_mul(tan_beta, a_sum), m);                                     /* eq 33 */
        seed_y = dual_scale(dual_mul(squared, dual_sin(dual_scale(seed_phi, 6.0))), -3.0 * m / l); /* eq 34 */
        ROW(Rx_in, dual_cross(cos_psi, seed_x, sin_psi, seed_y));
        ROW(Ry_in, dual_mul2(sin_psi, seed_x, cos_psi, seed_y));
    }
    return failure;
}
