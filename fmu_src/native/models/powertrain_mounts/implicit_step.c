/* A step of the powertrain on progressive mounts (port of driveline/mounts/implicit_step.py): the implicit
 * midpoint rule with the discrete gradient of the mounts' elastic energy (I1), the Maxwell branches' forces
 * linear in the step's dq, the six equations left in dq solved by Newton's method with their exact Jacobian
 * 2 M / h^2 + dE/dQ1 + C / h + R^T diag(g / (2 + h / tau)) R, its factors kept while the corrections shrink
 * tenfold (what depends on h alone: StepMatrices). */
#include "mounts.h"

#include <math.h>

void implicit_matrices(const StepSystem *s, double h, StepMatrices *out)
{
    const Branches *b = s->branches;
    int n, i, j;
    out->h = h;
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            out->resistance[i][j] = s->damping[i][j] / h;
        }
    }
    for (n = 0; n < b->count; n++) {
        double shrink = 0.5 * h / b->times[n];
        out->keep[n] = (1.0 - shrink) / (1.0 + shrink);
        out->gain[n] = b->gains[n] / (1.0 + shrink);
        for (i = 0; i < 6; i++) {
            for (j = 0; j < 6; j++) {
                out->resistance[i][j] += b->rows[n][i] * (0.5 * out->gain[n] * b->rows[n][j]);
            }
        }
    }
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            out->jacobian[i][j] = 2.0 * s->mass[i][j] / (h * h) + out->resistance[i][j];
        }
    }
}

ErrorKind implicit_step(const StepSystem *s, const StepMatrices *m, const double *state, const double f0[6],
                        const double f1[6], double *next, const char **message)
{
    const Branches *b = s->branches;
    const double *q0 = state, *v0 = state + 6, *z0 = state + 12, h = m->h;
    double load[6], z_keep[MOUNTS_MAX_BRANCHES], big_q0[6], dq[6], moved[6], factors[6][6];
    double previous = HUGE_VAL;
    int pivots[6], fresh = 1, iteration, n, i, j;
    for (i = 0; i < 36; i++) { /* implicit_step.TOO_SHORT: the residual's terms would overflow in an order of their sum */
        if (!isfinite(m->jacobian[i / 6][i % 6])) {
            *message = "the step is too short for the implicit step (2 M / h^2 is beyond the range of numbers)";
            return ERROR_ARITHMETIC;
        }
    }
    for (n = 0; n < b->count; n++) {
        z_keep[n] = m->keep[n] * z0[n];
    }
    for (i = 0; i < 6; i++) { /* the load less the branches' forces held from z0: R^T (z0 + keep z0) / 2 */
        double held = 0.0;
        for (n = 0; n < b->count; n++) {
            held += b->rows[n][i] * (0.5 * (z0[n] + z_keep[n]));
        }
        load[i] = f0[i] + 0.5 * h * f1[i] + s->weight[i] - held;
        big_q0[i] = s->weight_sag[i] + q0[i];
        dq[i] = h * v0[i];
        moved[i] = big_q0[i] + dq[i];
    }
    for (iteration = 0; iteration < MOUNTS_FORCES_MAX_NEWTON; iteration++) {
        double elastic[6], correction[6], size;
        forces_mean_elastic_load(s->layout, s->maps, big_q0, moved, elastic, fresh ? factors : NULL);
        for (i = 0; i < 6; i++) {
            double inertia = 0.0, resisted = 0.0;
            for (j = 0; j < 6; j++) {
                inertia += s->mass[i][j] * (2.0 * dq[j] / h - 2.0 * v0[j]);
                resisted += m->resistance[i][j] * dq[j];
            }
            correction[i] = -(inertia / h - load[i] + elastic[i] + resisted);
            if (!isfinite(correction[i])) {
                *message = "the step's motion is beyond the range of numbers (a load near 1e300)";
                return ERROR_ARITHMETIC;
            }
        }
        if (fresh) {
            for (i = 0; i < 6; i++) {
                for (j = 0; j < 6; j++) {
                    factors[i][j] = m->jacobian[i][j] + factors[i][j];
                }
            }
            if (!dense_factor(&factors[0][0], pivots, 6)) {
                *message = "Singular matrix";
                return ERROR_VALUE;
            }
        }
        dense_substitute(&factors[0][0], pivots, correction, 6, 1);
        for (i = 0; i < 6; i++) {
            dq[i] += correction[i];
            moved[i] = big_q0[i] + dq[i];
        }
        size = dense_largest(correction, 6);
        if (size <= MOUNTS_FORCES_NEWTON_STEP * fmax(dense_largest(moved, 6), 1e-300)) {
            for (n = 0; n < b->count; n++) { /* z1 = keep z0 + gain (R dq) */
                double rate = 0.0;
                for (i = 0; i < 6; i++) {
                    rate += b->rows[n][i] * dq[i];
                }
                next[12 + n] = z_keep[n] + m->gain[n] * rate;
            }
            for (i = 0; i < 6; i++) {
                next[i] = q0[i] + dq[i];
                next[6 + i] = 2.0 * dq[i] / h - v0[i];
            }
            return ERROR_NONE;
        }
        fresh = !(size <= MOUNTS_FORCES_NEWTON_CONTRACTION * previous); /* a slow contraction: the Jacobian again */
        previous = size;
    }
    *message = "the implicit step did not converge in " MOUNTS_NEWTON_TEXT " Newton iterations";
    return ERROR_ARITHMETIC;
}
