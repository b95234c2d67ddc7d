/* A step of the powertrain on progressive mounts (port of driveline/mounts/implicit_step.py): the implicit
 * midpoint rule with the discrete gradient of the mounts' elastic energy (I1), the Maxwell branches' forces
 * linear in the step's dq, the six equations left in dq solved by Newton's method with their exact Jacobian
 * 2 M / h^2 + dE/dQ1 + C / h + R^T diag(g / (2 + h / tau)) R. */
#include "mounts.h"

#include <math.h>
#include <string.h>

/* z1 = z_keep + z_gain (R dq) */
static void branch_forces(const Branches *b, const double *keep, const double *gain, const double dq[6], double *z1)
{
    int n, i;
    for (n = 0; n < b->count; n++) {
        double rate = 0.0;
        for (i = 0; i < 6; i++) {
            rate += b->rows[n][i] * dq[i];
        }
        z1[n] = keep[n] + gain[n] * rate;
    }
}

ErrorKind implicit_step(const StepSystem *s, const double *state, const double f0[6], const double f1[6], double h,
                        double *next, const char **message)
{
    const Branches *b = s->branches;
    const double *q0 = state, *v0 = state + 6, *z0 = state + 12;
    double load[6], keep[MOUNTS_MAX_BRANCHES], gain[MOUNTS_MAX_BRANCHES], z1[MOUNTS_MAX_BRANCHES];
    double branch_jacobian[6][6] = {{0}}, big_q0[6], dq[6], moved[6];
    int iteration, n, i, j;
    for (i = 0; i < 6; i++) {
        load[i] = f0[i] + 0.5 * h * f1[i] + s->weight[i];
        big_q0[i] = s->weight_sag[i] + q0[i];
        dq[i] = h * v0[i];
    }
    for (n = 0; n < b->count; n++) {
        double shrink = 0.5 * h / b->times[n];
        keep[n] = z0[n] * (1.0 - shrink) / (1.0 + shrink);
        gain[n] = b->gains[n] / (1.0 + shrink);
        for (i = 0; i < 6; i++) {
            for (j = 0; j < 6; j++) {
                branch_jacobian[i][j] += b->rows[n][i] * (0.5 * gain[n] * b->rows[n][j]);
            }
        }
    }
    for (iteration = 0; iteration < MOUNTS_FORCES_MAX_NEWTON; iteration++) {
        double elastic[6], jacobian[6][6], correction[6];
        branch_forces(b, keep, gain, dq, z1);
        for (i = 0; i < 6; i++) {
            moved[i] = big_q0[i] + dq[i];
        }
        forces_mean_elastic_load(s->layout, s->maps, big_q0, moved, elastic, jacobian);
        for (i = 0; i < 6; i++) {
            double inertia = 0.0, viscous = 0.0, branches = 0.0;
            for (j = 0; j < 6; j++) {
                inertia += s->mass[i][j] * (2.0 * dq[j] / h - 2.0 * v0[j]);
                viscous += s->damping[i][j] * dq[j];
                jacobian[i][j] = 2.0 * s->mass[i][j] / (h * h) + jacobian[i][j] + s->damping[i][j] / h +
                                 branch_jacobian[i][j];
            }
            for (n = 0; n < b->count; n++) {
                branches += b->rows[n][i] * (0.5 * (z0[n] + z1[n]));
            }
            correction[i] = -(inertia / h - load[i] + elastic[i] + viscous / h + branches);
            if (!isfinite(correction[i])) {
                *message = "the step's motion is beyond the range of numbers (a load near 1e300)";
                return ERROR_ARITHMETIC;
            }
        }
        if (!dense_solve(&jacobian[0][0], correction, 6, 1)) {
            *message = "Singular matrix";
            return ERROR_VALUE;
        }
        for (i = 0; i < 6; i++) {
            dq[i] += correction[i];
            moved[i] = big_q0[i] + dq[i];
        }
        if (dense_largest(correction, 6) <= MOUNTS_FORCES_NEWTON_STEP * fmax(dense_largest(moved, 6), 1e-300)) {
            branch_forces(b, keep, gain, dq, z1);
            for (i = 0; i < 6; i++) {
                next[i] = q0[i] + dq[i];
                next[6 + i] = 2.0 * dq[i] / h - v0[i];
            }
            memcpy(next + 12, z1, b->count * sizeof *next);
            return ERROR_NONE;
        }
    }
    *message = "the implicit step did not converge in " MOUNTS_NEWTON_TEXT " Newton iterations";
    return ERROR_ARITHMETIC;
}
