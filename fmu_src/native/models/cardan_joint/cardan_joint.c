/* CardanJoint: exact kinematics of a Cardan (Hooke) joint, seed 003 (port of driveline/cardan/).
 *
 * (C1)-(C5) are the labels of docs/cardan_joint.md. g1 = phi_in - phase; the input speed is held
 * over a step, so phi_in grows by omega_in h; a_1 is the input alpha_in once the host set it non-zero,
 * the backward difference of the last two omega_in samples until then (driveline/cardan/model.py).
 */
#include <math.h>

#include "fmi/fmu_instance.h"

#define OMEGA_SAMPLE (data->internal[0]) /* omega_in of the last evaluation [rad/s] */
#define SAMPLE_TIME (data->internal[1])  /* time of that evaluation [s] */
#define HAS_SAMPLE (data->internal[2])   /* 1 once there was an evaluation */
#define ACCELERATION_SET (data->internal[3]) /* 1 once the host set alpha_in non-zero */
#define ACCELERATION_USED (data->internal[4]) /* a_1 of the last evaluation [rad/s2] */

static void reset_internal(ModelData *data)
{
    OMEGA_SAMPLE = 0.0;
    SAMPLE_TIME = 0.0;
    HAS_SAMPLE = 0.0;
    ACCELERATION_SET = 0.0;
    ACCELERATION_USED = 0.0;
}

/* Outputs at the current phi_in; input_time is the communication point of the inputs. */
static Failure evaluate(ModelData *data, double input_time)
{
    double elapsed = HAS_SAMPLE != 0.0 ? input_time - SAMPLE_TIME : 0.0;
    double alpha_in;
    double gamma1 = VALUE(phi_in) - VALUE(phase), beta = VALUE(beta), cos_beta = cos(beta);
    double sin_cos = sin(beta) * cos(gamma1), denominator = 1.0 - sin_cos * sin_cos;
    /* (C2) unwrapped: g1 = n pi + r with |r| <= pi/2, g2 = n pi + atan2(sin r, cos b cos r) */
    double half_turns = nearbyint(gamma1 / FMU_PI), rest = gamma1 - half_turns * FMU_PI;
    double ratio = cos_beta / denominator; /* (C3) */
    ACCELERATION_SET = ACCELERATION_SET != 0.0 || VALUE(alpha_in) != 0.0;
    alpha_in = ACCELERATION_SET != 0.0 ? VALUE(alpha_in)
               : elapsed > 0.0         ? (VALUE(omega_in) - OMEGA_SAMPLE) / elapsed
                                       : 0.0;
    ACCELERATION_USED = alpha_in;
    OMEGA_SAMPLE = VALUE(omega_in);
    SAMPLE_TIME = input_time;
    HAS_SAMPLE = 1.0;
    VALUE(phi_out) = VALUE(phase) + (half_turns * FMU_PI + atan2(sin(rest), cos_beta * cos(rest)));
    VALUE(speed_ratio) = ratio;
    VALUE(omega_out) = VALUE(omega_in) * ratio;
    /* (C4): a2 = a1 cos b / D - omega_1^2 cos b sin^2 b sin 2 g1 / D^2 */
    VALUE(alpha_out) = alpha_in * cos_beta / denominator - VALUE(omega_in) * VALUE(omega_in) * cos_beta *
                                                               (1.0 - cos_beta * cos_beta) * sin(2.0 * gamma1) /
                                                               (denominator * denominator);
    VALUE(T_in) = VALUE(T_load) * ratio;
    VALUE(speed_fluctuation) = tan(beta) * sin(beta); /* (C5) */
    return NO_FAILURE;
}

/* The exact partial derivatives of the outputs with respect to phi_in, beta, omega_in, alpha_in, T_load, from
 * (C2)-(C5) differentiated: with D = 1 - sin^2 b cos^2 g1 and the ratio r = cos b / D (C3),
 * d phi_out / d g1 = r, d phi_out / d b = sin b sin 2 g1 / (2 D), a2 = a1 r + omega_1^2 d r / d g1 (C4);
 * a1 is the input alpha_in (d a2 / d a1 = r), or, until the host sets it, the estimate from the speed
 * samples, held (history, not a function of the inputs). */
static Failure jacobian(const ModelData *data, double partial[])
{
    double gamma1 = VALUE(phi_in) - VALUE(phase), beta = VALUE(beta), omega = VALUE(omega_in);
    double s = sin(beta), c = cos(beta), cos_g = cos(gamma1), sin_2g = sin(2.0 * gamma1);
    double d = 1.0 - s * s * cos_g * cos_g, ratio = c / d;
    double d_g = s * s * sin_2g, d_gg = 2.0 * s * s * cos(2.0 * gamma1); /* derivatives of D */
    double d_b = -2.0 * s * c * cos_g * cos_g, d_gb = 2.0 * s * c * sin_2g;
    double ratio_g = -c * d_g / (d * d), ratio_b = -s / d - c * d_b / (d * d);
    double ratio_gg = -c * (d_gg / (d * d) - 2.0 * d_g * d_g / (d * d * d));
    double ratio_gb = s * d_g / (d * d) - c * d_gb / (d * d) + 2.0 * c * d_g * d_b / (d * d * d);
    PARTIAL(phi_out, phi_in) = ratio;
    PARTIAL(phi_out, beta) = s * sin_2g / (2.0 * d);
    PARTIAL(speed_ratio, phi_in) = ratio_g;
    PARTIAL(speed_ratio, beta) = ratio_b;
    PARTIAL(omega_out, phi_in) = omega * ratio_g;
    PARTIAL(omega_out, beta) = omega * ratio_b;
    PARTIAL(omega_out, omega_in) = ratio;
    PARTIAL(alpha_out, phi_in) = ACCELERATION_USED * ratio_g + omega * omega * ratio_gg;
    PARTIAL(alpha_out, beta) = ACCELERATION_USED * ratio_b + omega * omega * ratio_gb;
    PARTIAL(alpha_out, alpha_in) = ratio;
    PARTIAL(alpha_out, omega_in) = 2.0 * omega * ratio_g;
    PARTIAL(T_in, phi_in) = VALUE(T_load) * ratio_g;
    PARTIAL(T_in, beta) = VALUE(T_load) * ratio_b;
    PARTIAL(T_in, T_load) = ratio;
    PARTIAL(speed_fluctuation, beta) = s / (c * c) + s; /* d (tan b sin b) / d b */
    return NO_FAILURE;
}

DRIVEN_SHAFT_HOOKS(evaluate)

/* CardanJointModel.start_notice: alpha_in left at 0 is estimated, and the log says so. */
static const char *start_notice(const ModelData *data)
{
    return ACCELERATION_SET == 0.0 ? ACCELERATION_ESTIMATED : NULL;
}

const ModelHooks model_hooks = {.reset_internal = reset_internal, .start = start, .advance = advance,
                                .evaluate = evaluate, .start_notice = start_notice,
                                .jacobian = jacobian};
