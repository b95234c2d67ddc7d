/* UniversalReducer: few-teeth-difference planetary gear through an RCRCR mechanism, seed 004
 * (Gu, Chen 2016; port of driveline/reducer/). phi_out = phi_in / i (eq 17) at any alpha; the
 * loads are the seed's quasi-static relations (eqs 18-21) and the third strength theory at C.
 */
#include <math.h>

#include "fmi/fmu_instance.h"

#define INTEGER(name) (data->int_value[V_##name])

typedef struct {
    double moment_E, moment_C1, moment_B, moment_C; /* eqs 19-21 (math.h may define M_E) */
    double sigma, tau, sigma_eq;
} Loads;

/* Eqs 18-21 for input torque M_in, then the stresses of the solid shaft at C (bent by M_C,
 * twisted by M_C1): sigma = M/W, tau = T/(2W), sigma_eq = sqrt(sigma^2 + 4 tau^2), W = pi r^3/4. */
static void connecting_shaft(const ModelData *data, double M_in, double i, double cube, Loads *loads)
{
    double half = 0.5 * VALUE(intersection_angle), M_out = i * M_in, F_B = M_in / VALUE(e);
    double F_t = 2.0 * M_out / (VALUE(module) * INTEGER(z1)), shared, section_modulus;
    loads->moment_E = 2.0 * F_B * VALUE(L1) * sin(half);
    loads->moment_C1 = F_t * 0.5 * VALUE(module) * INTEGER(z2);
    shared = loads->moment_E / (2.0 * sin(half));
    loads->moment_B = loads->moment_C1 / sin(VALUE(intersection_angle)) + shared;
    loads->moment_C = loads->moment_C1 * cos(VALUE(intersection_angle)) / sin(VALUE(intersection_angle)) + shared;
    section_modulus = 0.25 * FMU_PI * cube;
    loads->sigma = loads->moment_C / section_modulus;
    loads->tau = loads->moment_C1 / (2.0 * section_modulus);
    loads->sigma_eq = sqrt(loads->sigma * loads->sigma + 4.0 * (loads->tau * loads->tau));
}

static Failure evaluate(ModelData *data, double input_time UNUSED)
{
    double i = (double)INTEGER(z1) / (double)(INTEGER(z1) - INTEGER(z2)); /* eqs 4, 17 */
    double half = 0.5 * VALUE(intersection_angle), cube = pow(VALUE(r_shaft), 3.0);
    Loads loads, unit;
    if (isinf(cube)) {
        return FAILURE(ERROR_OVERFLOW, "(34, 'Numerical result out of range')"); /* Python's float ** says so */
    }
    VALUE(speed_ratio) = 1.0 / i;
    VALUE(phi_out) = VALUE(phi_in) / i;
    VALUE(omega_out) = VALUE(omega_in) / i;
    VALUE(T_in) = VALUE(T_load) / i;                                        /* eq 18, lossless */
    VALUE(s_b) = VALUE(e) * cos(half) / sin(half) * sin(VALUE(phi_in)); /* eq 15 */
    connecting_shaft(data, VALUE(T_in), i, cube, &loads);
    VALUE(M_E) = loads.moment_E;
    VALUE(M_C1) = loads.moment_C1;
    VALUE(M_B) = loads.moment_B;
    VALUE(M_C) = loads.moment_C;
    VALUE(sigma_bend) = loads.sigma;
    VALUE(tau_torsion) = loads.tau;
    VALUE(sigma_eq) = loads.sigma_eq;
    VALUE(utilisation) = loads.sigma_eq / VALUE(sigma_allow);
    connecting_shaft(data, 1.0, i, cube, &unit);
    if (unit.sigma_eq == 0.0) {
        return FAILURE(ERROR_ZERO_DIVISION, "float division by zero");
    }
    VALUE(T_in_allow) = VALUE(sigma_allow) / unit.sigma_eq;
    return NO_FAILURE;
}

/* d/da of the loads of a unit input torque (a: the intersection angle), from eqs 19-21: M_E = 2 F_B L1 sin(a/2),
 * M_C1 = F_t r2 and M_E / (2 sin(a/2)) = F_B L1 do not depend on a beyond it, M_B = M_C1 / sin a + F_B L1,
 * M_C = M_C1 cot a + F_B L1, tau = M_C1 / (2 W); sigma_eq' = sigma sigma' / sigma_eq. */
static void unit_load_rates(const ModelData *data, const Loads *unit, double cube, Loads *rate)
{
    double angle = VALUE(intersection_angle), sine = sin(angle);
    rate->moment_E = VALUE(L1) * cos(0.5 * angle) / VALUE(e);
    rate->moment_C1 = 0.0;
    rate->moment_B = -unit->moment_C1 * cos(angle) / (sine * sine);
    rate->moment_C = -unit->moment_C1 / (sine * sine);
    rate->sigma = rate->moment_C / (0.25 * FMU_PI * cube);
    rate->tau = 0.0;
    rate->sigma_eq = unit->sigma * rate->sigma / unit->sigma_eq;
}

/* The loads are linear in the input torque M_in = T_load / i (sigma_eq in |M_in|: at T_load = 0 its
 * derivative for a growing T_load); phi_out, omega_out, T_in are the shafts' divided by i (eq 17), s_b eq 15's. */
static Failure jacobian(const ModelData *data, double partial[])
{
    double i = (double)INTEGER(z1) / (double)(INTEGER(z1) - INTEGER(z2));
    double half = 0.5 * VALUE(intersection_angle), cube = pow(VALUE(r_shaft), 3.0), torque = VALUE(T_in);
    double sign = torque < 0.0 ? -1.0 : 1.0;
    Loads unit, rate;
    connecting_shaft(data, 1.0, i, cube, &unit);
    unit_load_rates(data, &unit, cube, &rate);
    PARTIAL(phi_out, phi_in) = 1.0 / i;
    PARTIAL(omega_out, omega_in) = 1.0 / i;
    PARTIAL(T_in, T_load) = 1.0 / i;
    PARTIAL(s_b, phi_in) = VALUE(e) * cos(half) / sin(half) * cos(VALUE(phi_in));
    PARTIAL(s_b, intersection_angle) = -0.5 * VALUE(e) * sin(VALUE(phi_in)) / (sin(half) * sin(half));
    PARTIAL(M_E, T_load) = unit.moment_E / i;
    PARTIAL(M_E, intersection_angle) = torque * rate.moment_E;
    PARTIAL(M_C1, T_load) = unit.moment_C1 / i;
    PARTIAL(M_B, T_load) = unit.moment_B / i;
    PARTIAL(M_B, intersection_angle) = torque * rate.moment_B;
    PARTIAL(M_C, T_load) = unit.moment_C / i;
    PARTIAL(M_C, intersection_angle) = torque * rate.moment_C;
    PARTIAL(sigma_bend, T_load) = unit.sigma / i;
    PARTIAL(sigma_bend, intersection_angle) = torque * rate.sigma;
    PARTIAL(tau_torsion, T_load) = unit.tau / i;
    PARTIAL(sigma_eq, T_load) = sign * unit.sigma_eq / i;
    PARTIAL(sigma_eq, intersection_angle) = fabs(torque) * rate.sigma_eq;
    PARTIAL(utilisation, T_load) = PARTIAL(sigma_eq, T_load) / VALUE(sigma_allow);
    PARTIAL(utilisation, intersection_angle) = PARTIAL(sigma_eq, intersection_angle) / VALUE(sigma_allow);
    PARTIAL(T_in_allow, intersection_angle) = -VALUE(T_in_allow) * rate.sigma_eq / unit.sigma_eq;
    return NO_FAILURE;
}

DRIVEN_SHAFT_HOOKS(evaluate)

const ModelHooks model_hooks = {.start = start, .advance = advance, .evaluate = evaluate, .jacobian = jacobian};
