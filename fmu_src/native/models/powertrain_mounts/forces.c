/* The mounts' forces on the powertrain (port of driveline/mounts/forces.py): the elastic characteristics'
 * generalised force and its tangent stiffness, the discrete gradient of their energy, the static equilibrium
 * by Newton's method with the exact Jacobian (halving a step that does not lower the residual), and the
 * Maxwell branches' map. ``maps[i]`` is mount i's A_i T(p_i) (3 x 6). */
#include "mounts.h"

#include <math.h>
#include <string.h>

static void deflections(const double map[3][6], const double q[6], double d[3])
{
    int k, i;
    for (k = 0; k < 3; k++) {
        d[k] = 0.0;
        for (i = 0; i < 6; i++) {
            d[k] += map[k][i] * q[i];
        }
    }
}

void forces_elastic(const Layout *layout, const double maps[][3][6], int n, const double q[6], double out[3])
{
    double d[3];
    int k;
    deflections(maps[n], q, d);
    for (k = 0; k < 3; k++) {
        out[k] = characteristic_force(&layout->mounts[n], k, d[k]);
    }
}

void forces_generalised(const Layout *layout, const double maps[][3][6], const double forces[][3], double out[6])
{
    int n, i, k;
    memset(out, 0, 6 * sizeof *out);
    for (n = 0; n < layout->count; n++) {
        for (i = 0; i < 6; i++) {
            double sum = 0.0;
            for (k = 0; k < 3; k++) {
                sum += maps[n][k][i] * forces[n][k];
            }
            out[i] += sum;
        }
    }
}

void forces_elastic_load(const Layout *layout, const double maps[][3][6], const double q[6], double out[6])
{
    double f[MOUNTS_LAYOUT_MAX_MOUNTS][3];
    int n;
    for (n = 0; n < layout->count; n++) {
        forces_elastic(layout, maps, n, q, f[n]);
    }
    forces_generalised(layout, maps, (const double(*)[3])f, out);
}

/* sum_i T_i^T A_i^T diag(rates_i) A_i T_i into ``out`` (6 x 6), the rates of mount i in rates[3 i ...] */
static void congruence(const Layout *layout, const double maps[][3][6], const double *rates, double out[6][6])
{
    int n, i, j, k;
    memset(out, 0, 36 * sizeof out[0][0]);
    for (n = 0; n < layout->count; n++) {
        for (i = 0; i < 6; i++) {
            for (j = 0; j < 6; j++) {
                double sum = 0.0;
                for (k = 0; k < 3; k++) {
                    sum += maps[n][k][i] * (rates[3 * n + k] * maps[n][k][j]);
                }
                out[i][j] += sum;
            }
        }
    }
}

void forces_tangent_stiffness(const Layout *layout, const double maps[][3][6], const double q[6], double out[6][6])
{
    double rates[3 * MOUNTS_LAYOUT_MAX_MOUNTS], d[3];
    int n, k;
    for (n = 0; n < layout->count; n++) {
        deflections(maps[n], q, d);
        for (k = 0; k < 3; k++) {
            rates[3 * n + k] = characteristic_tangent(&layout->mounts[n], k, d[k]);
        }
    }
    congruence(layout, maps, rates, out);
}

double forces_elastic_energy(const Layout *layout, const double maps[][3][6], const double q[6])
{
    double total = 0.0, d[3];
    int n, k;
    for (n = 0; n < layout->count; n++) {
        deflections(maps[n], q, d);
        for (k = 0; k < 3; k++) {
            total += characteristic_energy(&layout->mounts[n], k, d[k]);
        }
    }
    return total;
}

void forces_mean_elastic_load(const Layout *layout, const double maps[][3][6], const double q0[6], const double q1[6],
                              double load[6], double jacobian[6][6])
{
    double slopes[3 * MOUNTS_LAYOUT_MAX_MOUNTS], d0[3], d1[3], mean[3];
    int n, i, k;
    memset(load, 0, 6 * sizeof *load);
    for (n = 0; n < layout->count; n++) {
        deflections(maps[n], q0, d0);
        deflections(maps[n], q1, d1);
        characteristic_mean_force(&layout->mounts[n], d0, d1, mean, &slopes[3 * n]);
        for (i = 0; i < 6; i++) {
            double sum = 0.0;
            for (k = 0; k < 3; k++) {
                sum += maps[n][k][i] * mean[k];
            }
            load[i] += sum;
        }
    }
    if (jacobian != NULL) {
        congruence(layout, maps, slopes, jacobian);
    }
}

static double norm6(const double v[6])
{
    double sum = 0.0;
    int i;
    for (i = 0; i < 6; i++) {
        sum += v[i] * v[i];
    }
    return sqrt(sum);
}

ErrorKind forces_equilibrium(const Layout *layout, const double maps[][3][6], const double load[6],
                             const double linear_stiffness[6][6], double q[6], const char **message)
{
    double k[6][6], residual[6], trial[6], trial_residual[6], step[6];
    int iteration, i;
    memcpy(k, linear_stiffness, sizeof k);
    memcpy(q, load, 6 * sizeof *q);
    if (!dense_solve(&k[0][0], q, 6, 1)) {
        *message = "Singular matrix";
        return ERROR_VALUE;
    }
    forces_elastic_load(layout, maps, q, residual);
    for (i = 0; i < 6; i++) {
        residual[i] -= load[i];
    }
    for (iteration = 0; iteration < MOUNTS_FORCES_MAX_NEWTON; iteration++) {
        double size = 1.0, moved;
        for (i = 0; i < 6; i++) {
            if (!isfinite(residual[i])) {
                *message = "the static equilibrium is beyond the range of numbers (a load near 1e300)";
                return ERROR_ARITHMETIC;
            }
            step[i] = -residual[i];
        }
        forces_tangent_stiffness(layout, maps, q, k);
        if (!dense_solve(&k[0][0], step, 6, 1)) {
            *message = "Singular matrix";
            return ERROR_VALUE;
        }
        for (;;) {
            for (i = 0; i < 6; i++) {
                trial[i] = q[i] + size * step[i];
            }
            forces_elastic_load(layout, maps, trial, trial_residual);
            for (i = 0; i < 6; i++) {
                trial_residual[i] -= load[i];
            }
            if (norm6(trial_residual) < norm6(residual) || size < 1e-6) {
                break;
            }
            size *= 0.5;
        }
        memcpy(q, trial, 6 * sizeof *q);
        memcpy(residual, trial_residual, sizeof residual);
        moved = 0.0;
        for (i = 0; i < 6; i++) {
            moved = fmax(moved, fabs(size * step[i]));
        }
        if (moved <= MOUNTS_FORCES_NEWTON_STEP * fmax(dense_largest(q, 6), 1e-300)) {
            return ERROR_NONE;
        }
    }
    *message = "no static equilibrium found in " MOUNTS_NEWTON_TEXT " Newton steps";
    return ERROR_ARITHMETIC;
}

int forces_branch_map(const Layout *layout, const double maps[][3][6], const double operating[6], Branches *out)
{
    double d[3];
    int n, k, j;
    out->count = 0;
    for (n = 0; n < layout->count; n++) {
        const Mount *m = &layout->mounts[n];
        if (m->branch_count == 0) {
            continue;
        }
        deflections(maps[n], operating, d);
        for (k = 0; k < 3; k++) {
            double rate = mount_progressive(m) ? characteristic_tangent(m, k, d[k]) : m->stiffness[k];
            for (j = 0; j < m->branch_count; j++) {
                memcpy(out->rows[out->count], maps[n][k], sizeof out->rows[0]);
                out->gains[out->count] = m->branches[j] * rate;
                out->times[out->count] = rubber_relaxation_time(j);
                out->slots[out->count] = (3 * n + k) * MOUNTS_RUBBER_BRANCHES + j;
                out->count++;
            }
        }
    }
    return out->count;
}

void forces_branch_stiffness(const Branches *b, double frequency, double storage[6][6], double loss[6][6],
                             double slope[6][6])
{
    int n, i, j;
    memset(storage, 0, 36 * sizeof storage[0][0]);
    memset(loss, 0, 36 * sizeof loss[0][0]);
    memset(slope, 0, 36 * sizeof slope[0][0]);
    for (n = 0; n < b->count; n++) {
        double x = 2.0 * FMU_PI * frequency * b->times[n], parts[3];
        parts[0] = b->gains[n] * x * x / (1.0 + x * x);
        parts[1] = b->gains[n] * x / (1.0 + x * x);
        parts[2] = 2.0 * b->gains[n] * x * x / ((1.0 + x * x) * (1.0 + x * x));
        for (i = 0; i < 6; i++) {
            for (j = 0; j < 6; j++) {
                storage[i][j] += b->rows[n][i] * (parts[0] * b->rows[n][j]);
                loss[i][j] += b->rows[n][i] * (parts[1] * b->rows[n][j]);
                slope[i][j] += b->rows[n][i] * (parts[2] * b->rows[n][j]);
            }
        }
    }
}
