/* The step of the native TripodCoupling FMU (tripod_coupling.c) and what its modules share: arithmetic that
 * fails as Python's does, the step's load, one arm of the exact balance and the reactions. Its module:
 *   rollers.c   the roller tripods' balance (rollers.py)
 */
#ifndef TRIPOD_STEP_H
#define TRIPOD_STEP_H

#include <math.h>

#include "fmi/fmu_instance.h"

#if defined(_MSC_VER) && !defined(__cplusplus) && !defined(inline)
#define inline __inline /* MSVC's C before C11 */
#endif

#define MATH_DOMAIN "math domain error"        /* ValueError */
#define ZERO_DIVISION "float division by zero"  /* ZeroDivisionError */

/* The first arithmetic failure of an evaluation, as Python would raise it. */
typedef struct {
    Failure failure;
} Guard;

/* Python's float division, math.sqrt, math.cos, math.sin and math.asin: where those raise, the
 * first failure is kept and the evaluation goes on with 0 (its results are then discarded). */
static inline double refuse(Guard *guard, ErrorKind kind, const char *why)
{
    if (guard->failure.kind == ERROR_NONE) {
        guard->failure = FAILURE(kind, why);
    }
    return 0.0;
}

static inline double divide(Guard *guard, double a, double b)
{
    return b != 0.0 ? a / b : refuse(guard, ERROR_ZERO_DIVISION, ZERO_DIVISION);
}

static inline double root(Guard *guard, double a)
{
    return a < 0.0 ? refuse(guard, ERROR_VALUE, MATH_DOMAIN) : sqrt(a);
}

/* ---- the exact balance ---------------------------------------------------------------------- */

typedef struct {
    double Rx_in, Ry_in, Mx_in, My_in, T_in, Rx_out, Ry_out, Rz_out;
    double F_arm[3], F_plunger[3], a_plunger_sum, omega_spin, Rz_in, P_friction;
} Reactions;

/* phi_in: the input angle from the bend plane; omega, omega_dot: the input shaft's speed and its rate in the
 * housing; psi_dot, psi_ddot: the bend plane's rates; plunge_dot: the spider's axial speed in the housing */
typedef struct {
    double phi_in, cb, sb, omega, omega_dot, T_load, r, l, m, friction, slip_speed; /* cb, sb: cos, sin of beta */
    double beta_dot, beta_ddot, psi_dot, psi_ddot, plunge_dot;
    int tripod_type;                /* 0 plain, 1 single roller, 2 double roller (spec.tripod_type) */
    double mu_roll, roller_radius;  /* the roller tripods' rolling resistance and rollers' outer radius */
    double roller_bore_radius;      /* the rollers' bore radius: the double roller's needles run on it */
} Load;

/* One arm of the exact balance: groove point g, ball height bz, arm vector e = b - P,
 * d = b - S, |n|^2 = ex^2 + ey^2 and k = d x n (a row of K). */
typedef struct {
    double gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2, k[3];
    double ax, ay, hx, hy, hz; /* groove point's acceleration (in the housing); whirl and Coriolis terms */
    double zdot, sigma, zddot;  /* plunger speed in the housing, sliding rate along the arm per |e|, acceleration */
} Arm;

/* Regularised sign u / sqrt(1 + u^2), u = speed / slip_speed (reactions.slip_sign). */
static inline double slip_sign(Guard *guard, double speed, double slip_speed)
{
    double u = divide(guard, speed, slip_speed);
    return divide(guard, u, sqrt(1.0 + u * u));
}

/* The frame and motion of the output shaft that the rollers' reactions need (exact_reactions' steps 1-3): the
 * angular velocity W relative to the housing. */
typedef struct {
    double U[3], E1[3], E2[3], W[3];
} Shaft;

/* rollers.roller_reactions: the roller tripods' balance by successive substitution from the frictionless
 * lambda_j, mu_j of the exact balance (arm, adj, inv_det), then their reactions into ``out``. */
void roller_reactions(Guard *guard, const Arm arm[3], const double adj[3][3], double inv_det, const Load *load,
                      const Shaft *shaft, double lam[3], double mu_q[3], Reactions *out);

#endif
