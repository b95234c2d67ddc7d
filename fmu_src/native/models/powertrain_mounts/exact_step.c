/* Exact time stepping of M q'' + C q' + K q = f(t) with f held or linear over a step (port of
 * driveline/mounts/exact_step.py): the first-order system s' = A s + B f of the state (q, q', z), z the Maxwell
 * branches' forces, and the propagator of a step size (Phi, Gamma0, Gamma1: one exponential of the augmented
 * matrix, Van Loan 1978; Pade 13 with scaling and squaring, Higham 2005). */
#include "mounts.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_STATE MOUNTS_MAX_STATE

int exact_state_matrices(double mass[6][6], double stiffness[6][6], double damping[6][6],
                         const Branches *branches, double (*a)[MAX_STATE], double (*b)[6])
{
    double inverse[6][6] = {{0}}, product[6][6], copy[6][6];
    int n = 12 + branches->count, i, j, k;
    memcpy(copy, mass, sizeof copy);
    for (i = 0; i < 6; i++) {
        inverse[i][i] = 1.0;
    }
    if (!dense_solve(&copy[0][0], &inverse[0][0], 6, 6)) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        memset(a[i], 0, n * sizeof a[i][0]);
        memset(b[i], 0, 6 * sizeof b[i][0]);
    }
    for (i = 0; i < 6; i++) {
        a[i][6 + i] = 1.0;
    }
    dense_multiply(&inverse[0][0], &stiffness[0][0], &product[0][0], 6, 6, 6);
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            a[6 + i][j] = -product[i][j];
            b[6 + i][j] = inverse[i][j];
        }
    }
    dense_multiply(&inverse[0][0], &damping[0][0], &product[0][0], 6, 6, 6);
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            a[6 + i][6 + j] = -product[i][j];
        }
    }
    for (k = 0; k < branches->count; k++) { /* -M^-1 R^T, diag(g) R, -diag(1 / tau) */
        for (i = 0; i < 6; i++) {
            double sum = 0.0;
            for (j = 0; j < 6; j++) {
                sum += inverse[i][j] * branches->rows[k][j];
            }
            a[6 + i][12 + k] = -sum;
            a[12 + k][6 + i] = branches->gains[k] * branches->rows[k][i];
        }
        a[12 + k][12 + k] = -(1.0 / branches->times[k]);
    }
    return 1;
}

/* exact_step.augmented: Z h ((n + 12) x (n + 12)) */
static void augmented(const double (*a)[MAX_STATE], const double (*b)[6], int n, double h, double *z)
{
    int m = n + 12, i, j;
    memset(z, 0, (size_t)m * m * sizeof *z);
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            z[i * m + j] = a[i][j] * h;
        }
        for (j = 0; j < 6; j++) {
            z[i * m + n + j] = b[i][j] * h;
        }
    }
    for (i = 0; i < 6; i++) {
        z[(n + i) * m + n + 6 + i] = h;
    }
}

/* exact_step.squarings: -1 where the norm is not finite (no count of squarings scales it) */
static int squarings(const double *z, int m)
{
    double norm = 0.0;
    int i, j;
    for (j = 0; j < m; j++) {
        double sum = 0.0;
        for (i = 0; i < m; i++) {
            sum += fabs(z[i * m + j]);
        }
        norm = fmax(norm, sum);
    }
    if (!isfinite(norm)) {
        return -1;
    }
    /* a finite norm needs at most log2(DBL_MAX / THETA_13) + 1 = 1022 squarings: an int holds the count */
    return norm > MOUNTS_EXACT_STEP_THETA_13 ? (int)fmax(0.0, ceil(log2(norm / MOUNTS_EXACT_STEP_THETA_13))) : 0;
}

int exact_propagator(const double (*a)[MAX_STATE], const double (*b)[6], int n, double h, Propagator *p, char *failure,
                     size_t size)
{
    int m = n + 12, count, i, j;
    double *z = malloc(2 * (size_t)m * m * sizeof *z), *e;
    char step[40];
    if (z == NULL) {
        snprintf(failure, size, "out of memory");
        return 0;
    }
    e = z + m * m;
    augmented(a, b, n, h, z);
    count = squarings(z, m);
    python_float_repr(h, step, sizeof step);
    if (count < 0) {
        snprintf(failure, size, "a step of %s s overflows the matrix exponential's norm: take shorter steps", step);
        free(z);
        return 0;
    }
    if (count > MOUNTS_EXACT_STEP_MAX_SQUARINGS) {
        snprintf(failure, size, "a step of %s s would take %d squarings of the matrix exponential, more than the %d "
                 "accepted: take shorter steps", step, count, MOUNTS_EXACT_STEP_MAX_SQUARINGS);
        free(z);
        return 0;
    }
    if (!dense_exponential(z, m, count, e)) {
        snprintf(failure, size, "out of memory");
        free(z);
        return 0;
    }
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            p->phi[i][j] = e[i * m + j];
        }
        for (j = 0; j < 6; j++) {
            p->gamma0[i][j] = e[i * m + n + j];
            p->gamma1[i][j] = e[i * m + n + 6 + j];
        }
    }
    p->h = h;
    p->n = n;
    free(z);
    return 1;
}

void exact_step(const Propagator *p, const double *state, const double f0[6], const double f1[6], double *next)
{
    int i, k;
    for (i = 0; i < p->n; i++) {
        double sum = 0.0, loads = 0.0;
        for (k = 0; k < p->n; k++) {
            sum += p->phi[i][k] * state[k];
        }
        for (k = 0; k < 6; k++) {
            loads += p->gamma0[i][k] * f0[k] + p->gamma1[i][k] * f1[k];
        }
        next[i] = sum + loads;
    }
}
