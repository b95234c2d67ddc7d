/* UniversalReducer: few-teeth-difference planetary gear through an RCRCR mechanism, seed 004
 * (Gu, Chen 2016; port of driveline/reducer/). phi_out = phi_in / i (eq 17) at any alpha; the
 * loads are the seed's quasi-static relations (eqs 18-21) and the third strength theory at C.
 */
#include <math.h>

#include "fmu_instance.h"

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

DRIVEN_SHAFT_HOOKS(evaluate)

const ModelHooks model_hooks = {.start = start, .advance = advance};
