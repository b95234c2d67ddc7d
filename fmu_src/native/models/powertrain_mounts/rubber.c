/* Rubber's frequency-independent damping as Maxwell branches (port of driveline/mounts/rubber.py): the
 * branches' weights of one mount fitted by non-negative least squares (R3) to a constant loss factor over the
 * band and a dynamic-to-static ratio at its geometric mean, and the fit's refusal in the Python core's words.
 * The non-negative least squares is Lawson and Hanson's active-set method (scipy.optimize.nnls's), each
 * unconstrained subproblem solved by Householder QR. */
#include "mounts.h"

#include <float.h>
#include <math.h>
#include <stdio.h>

#define ROWS (MOUNTS_RUBBER_FIT_POINTS + 1)
#define COLUMNS MOUNTS_RUBBER_BRANCHES

static const double RELAXATION[COLUMNS] = MOUNTS_RUBBER_RELAXATION_FREQUENCIES;
static const double BAND[2] = MOUNTS_RUBBER_BAND;

double rubber_relaxation_time(int j)
{
    return 1.0 / (2.0 * FMU_PI * RELAXATION[j]);
}

/* rubber._storage_loss at one frequency: each branch's x^2 / (1 + x^2) and x / (1 + x^2), x = w tau */
static void storage_loss(double frequency, double storage[COLUMNS], double loss[COLUMNS])
{
    int j;
    for (j = 0; j < COLUMNS; j++) {
        double x = 2.0 * FMU_PI * frequency * rubber_relaxation_time(j);
        storage[j] = x * x / (1.0 + x * x);
        loss[j] = x / (1.0 + x * x);
    }
}

/* rubber.relative_stiffness: K*(w) / k at ``frequency`` [Hz], its real and imaginary parts */
static void relative_stiffness(const double weights[COLUMNS], double frequency, double *real, double *imaginary)
{
    double storage[COLUMNS], loss[COLUMNS];
    int j;
    storage_loss(frequency, storage, loss);
    *real = 1.0, *imaginary = 0.0;
    for (j = 0; j < COLUMNS; j++) {
        *real += storage[j] * weights[j];
        *imaginary += loss[j] * weights[j];
    }
}

/* numpy.geomspace(BAND[0], BAND[1], FIT_POINTS): the band's frequencies, log-spaced (its ends exact) */
static double fit_frequency(int i)
{
    double low = log10(BAND[0]), high = log10(BAND[1]);
    if (i == 0) {
        return BAND[0];
    }
    if (i == MOUNTS_RUBBER_FIT_POINTS - 1) {
        return BAND[1];
    }
    return pow(10.0, i * ((high - low) / (MOUNTS_RUBBER_FIT_POINTS - 1)) + low);
}

/* The least-squares solution of a[:, passive] s = b (a: ROWS x COLUMNS, row-major) by Householder QR; 0 when
 * the passive columns are dependent. */
static int least_squares(double a[ROWS][COLUMNS], const double b[ROWS], const int passive[COLUMNS],
                         double s[COLUMNS])
{
    double q[ROWS][COLUMNS], r[ROWS];
    int chosen[COLUMNS], n = 0, i, j, k;
    for (j = 0; j < COLUMNS; j++) {
        s[j] = 0.0;
        if (passive[j]) {
            chosen[n++] = j;
        }
    }
    for (i = 0; i < ROWS; i++) {
        for (k = 0; k < n; k++) {
            q[i][k] = a[i][chosen[k]];
        }
        r[i] = b[i];
    }
    for (k = 0; k < n; k++) {
        double norm = 0.0, alpha, head;
        for (i = k; i < ROWS; i++) {
            norm += q[i][k] * q[i][k];
        }
        norm = sqrt(norm);
        if (!(norm > 0.0)) {
            return 0;
        }
        alpha = q[k][k] > 0.0 ? -norm : norm;
        head = q[k][k] - alpha; /* v = (head, q[k+1:, k]), H = I - 2 v v^T / v^T v, v^T v = -2 alpha head */
        q[k][k] = alpha;
        for (j = k + 1; j <= n; j++) {
            double dot = head * (j < n ? q[k][j] : r[k]), factor;
            for (i = k + 1; i < ROWS; i++) {
                dot += q[i][k] * (j < n ? q[i][j] : r[i]);
            }
            factor = dot / (alpha * head);
            if (j < n) {
                q[k][j] += factor * head;
                for (i = k + 1; i < ROWS; i++) {
                    q[i][j] += factor * q[i][k];
                }
            } else {
                r[k] += factor * head;
                for (i = k + 1; i < ROWS; i++) {
                    r[i] += factor * q[i][k];
                }
            }
        }
    }
    for (k = n - 1; k >= 0; k--) {
        double sum = r[k];
        for (j = k + 1; j < n; j++) {
            sum -= q[k][j] * s[chosen[j]];
        }
        s[chosen[k]] = sum / q[k][k];
    }
    return 1;
}

/* scipy.optimize.nnls of the ROWS x COLUMNS system: Lawson and Hanson's active set */
static void nnls(double a[ROWS][COLUMNS], const double b[ROWS], double x[COLUMNS])
{
    int passive[COLUMNS] = {0}, iteration, i, j;
    double tolerance = 10.0 * DBL_EPSILON * ROWS, s[COLUMNS];
    for (j = 0; j < COLUMNS; j++) {
        x[j] = 0.0;
    }
    for (iteration = 0; iteration < 3 * COLUMNS; iteration++) {
        double w[COLUMNS], best = tolerance;
        int chosen = -1;
        for (j = 0; j < COLUMNS; j++) { /* the gradient A^T (b - A x) */
            w[j] = 0.0;
            for (i = 0; i < ROWS; i++) {
                double residual = b[i];
                int k;
                for (k = 0; k < COLUMNS; k++) {
                    residual -= a[i][k] * x[k];
                }
                w[j] += a[i][j] * residual;
            }
            if (!passive[j] && w[j] > best) {
                best = w[j], chosen = j;
            }
        }
        if (chosen < 0) {
            return;
        }
        passive[chosen] = 1;
        for (;;) {
            double alpha = 2.0;
            if (!least_squares(a, b, passive, s)) {
                passive[chosen] = 0;
                return;
            }
            for (j = 0; j < COLUMNS; j++) {
                if (passive[j] && s[j] <= 0.0) {
                    alpha = fmin(alpha, x[j] / (x[j] - s[j]));
                }
            }
            if (alpha > 1.0) {
                break;
            }
            for (j = 0; j < COLUMNS; j++) {
                x[j] += alpha * (s[j] - x[j]);
                if (passive[j] && x[j] <= tolerance) {
                    passive[j] = 0, x[j] = 0.0;
                }
            }
        }
        for (j = 0; j < COLUMNS; j++) {
            x[j] = s[j];
        }
    }
}

void rubber_fit(double loss_factor, double dynamic_ratio, RubberFit *fit)
{
    double a[ROWS][COLUMNS], b[ROWS], storage[COLUMNS], loss[COLUMNS], reference = sqrt(BAND[0] * BAND[1]);
    double real, imaginary;
    int i, j;
    for (i = 0; i < MOUNTS_RUBBER_FIT_POINTS; i++) {
        storage_loss(fit_frequency(i), storage, loss);
        for (j = 0; j < COLUMNS; j++) {
            a[i][j] = (loss[j] - loss_factor * storage[j]) / loss_factor;
        }
        b[i] = 1.0;
    }
    storage_loss(reference, storage, loss);
    for (j = 0; j < COLUMNS; j++) {
        a[ROWS - 1][j] = MOUNTS_RUBBER_RATIO_WEIGHT * storage[j];
    }
    b[ROWS - 1] = MOUNTS_RUBBER_RATIO_WEIGHT * (dynamic_ratio - 1.0);
    nnls(a, b, fit->weights);
    fit->loss_error = 0.0;
    for (i = 0; i < MOUNTS_RUBBER_FIT_POINTS; i++) {
        relative_stiffness(fit->weights, fit_frequency(i), &real, &imaginary);
        fit->loss_error = fmax(fit->loss_error, fabs(imaginary / real / loss_factor - 1.0));
    }
    relative_stiffness(fit->weights, reference, &real, &imaginary);
    fit->ratio_error = fabs(real / dynamic_ratio - 1.0);
}

int rubber_fit_error(const char *where, const RubberFit *fit, double loss_factor, double dynamic_ratio, char *error,
                     size_t size)
{
    char ratio[40], loss[40], loss_error[40], ratio_error[40], low[40], high[40], accepted_loss[40];
    char accepted_ratio[40];
    if (fit->loss_error <= MOUNTS_RUBBER_MAX_LOSS_ERROR && fit->ratio_error <= MOUNTS_RUBBER_MAX_RATIO_ERROR) {
        return 0;
    }
    python_float_repr(dynamic_ratio, ratio, sizeof ratio);
    python_float_repr(loss_factor, loss, sizeof loss);
    python_format_g(100.0 * fit->loss_error, 3, loss_error, sizeof loss_error);
    python_format_g(100.0 * fit->ratio_error, 3, ratio_error, sizeof ratio_error);
    python_format_g(BAND[0], 6, low, sizeof low);
    python_format_g(BAND[1], 6, high, sizeof high);
    python_format_g(100.0 * MOUNTS_RUBBER_MAX_LOSS_ERROR, 6, accepted_loss, sizeof accepted_loss);
    python_format_g(100.0 * MOUNTS_RUBBER_MAX_RATIO_ERROR, 6, accepted_ratio, sizeof accepted_ratio);
    snprintf(error, size, "%s.dynamic_ratio %s cannot go with loss_factor %s: Maxwell branches with that "
             "dynamic-to-static ratio miss the loss factor by %s %% over %s-%s Hz (accepted %s %%) and the ratio by "
             "%s %% (accepted %s %%): a constant loss factor needs a larger dynamic_ratio", where, ratio, loss,
             loss_error, low, high, accepted_loss, ratio_error, accepted_ratio);
    return 1;
}
