/* The single rollers' contact normals by the Illinois method (rollers._skewed_contact), shared by the step
 * (rollers.c, in values) and its derivatives (reaction_derivatives.c, in dual numbers), which differ only in
 * how they evaluate the miss of H's direction: each arm's angle bracketed within asin(mu + mu_roll) of H's,
 * all arms stepped together until each arm's bracket or smaller miss is within the tolerance, then the end
 * with the smaller miss. Header only (a static inline function). */
#ifndef TRIPOD_ILLINOIS_H
#define TRIPOD_ILLINOIS_H

#include <math.h>

#include "driveline_constants.h"

#if defined(_MSC_VER) && !defined(__cplusplus) && !defined(inline)
#define inline __inline /* MSVC's C before C11 */
#endif

/* The miss of H's direction for arm ``arm`` with the contact normal at ``angle`` [rad] */
typedef double (*MissAt)(void *context, int arm, double angle);

static inline double illinois_sign(double a)
{
    return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : 0.0);
}

/* The three arms' angles of the contact normal, around H's directions ``target`` [rad], for the friction
 * coefficients mu (sliding) and mu_roll (rolling) */
static inline void illinois_angles(MissAt miss_at, void *context, const double target[3], double mu, double mu_roll,
                                   double angle[3])
{
    double low[3], high[3], f_low[3], f_high[3];
    double share = mu + mu_roll;
    double spread = asin(share < TRIPOD_ROLLERS_FRICTION_SHARE_CAP ? share : TRIPOD_ROLLERS_FRICTION_SHARE_CAP)
                    + TRIPOD_ROLLERS_BRACKET_MARGIN;
    int side[3] = {0, 0, 0}, iteration, j;
    for (j = 0; j < 3; j++) {
        low[j] = target[j] - spread;
        high[j] = target[j] + spread;
        f_low[j] = miss_at(context, j, low[j]);
        f_high[j] = miss_at(context, j, high[j]);
    }
    for (iteration = 0; iteration < TRIPOD_ROLLERS_CONTACT_ITERATIONS; iteration++) {
        int done = 1;
        for (j = 0; j < 3; j++) {
            double least = fabs(f_low[j]) < fabs(f_high[j]) ? fabs(f_low[j]) : fabs(f_high[j]);
            done = done && (fabs(high[j] - low[j]) <= TRIPOD_ROLLERS_CONTACT_TOLERANCE
                            || least <= TRIPOD_ROLLERS_CONTACT_TOLERANCE);
        }
        if (done) {
            break;
        }
        for (j = 0; j < 3; j++) {
            double a = f_high[j] != f_low[j] ? (low[j] * f_high[j] - high[j] * f_low[j]) / (f_high[j] - f_low[j])
                                             : 0.5 * (low[j] + high[j]);
            double f_mid = miss_at(context, j, a);
            int lower = illinois_sign(f_mid) == illinois_sign(f_low[j]);
            double new_low = lower ? f_mid : f_low[j], new_high = lower ? f_high[j] : f_mid;
            if (lower) {
                low[j] = a;
            } else {
                high[j] = a;
            }
            /* Illinois: halve the value at the end that stays twice in a row */
            if (lower && side[j] == 1) {
                new_high = 0.5 * new_high;
            }
            if (!lower && side[j] == -1) {
                new_low = 0.5 * new_low;
            }
            side[j] = lower ? 1 : -1;
            f_low[j] = new_low;
            f_high[j] = new_high;
        }
    }
    for (j = 0; j < 3; j++) {
        angle[j] = fabs(f_low[j]) <= fabs(f_high[j]) ? low[j] : high[j];
    }
}

#endif
