/* What the FMU reports of the damped model (unbalance_outputs.UnbalanceOutputs): the synchronous unbalance
 * response from a banded complex LU solve of the damped model's dynamic stiffness (damped.h), its orbit and
 * bearing forces, the damping ratio from the mode table, and their derivatives in the speed. */
#include "damped.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct UnbalanceOutputs {
    Rotor rotor;        /* the response model (FE_ELEMENTS), its band matrices only */
    cplx *load;         /* DampedRotor.load per unit Omega^2, rotor.size */
    cplx *row;          /* DampedRotor.shape_rows at the response position, rotor.n */
    CubicSpline modes;  /* DAMPED_MODES damped frequencies, then their damping ratios */
    cplx *ab, *x, *dx;  /* evaluate's work: one object is evaluated by one caller at a time */
    int *pivots;
    int *place;         /* place[order[i]] = i: the row of each unknown [p, q] in the interleaved order */
};

/* DampedRotor.shape_rows for one position: ``row`` (rotor.n); ERROR_NONE, or ERROR_VALUE with the
 * message for a position off the shaft */
static ErrorKind shape_row(const Rotor *rotor, double z, double length, cplx *row, char *error, size_t size)
{
    const FeModel *fe = &rotor->fe;
    if (!isfinite(z) || z < 0.0 || z > length * (1 + 1e-12)) {
        char shown[40], at[40];
        python_float_repr(length, shown, sizeof shown);
        python_float_repr(z, at, sizeof at);
        if (error && size) {
            snprintf(error, size, "positions must lie on the shaft, 0 to %s m, got [%s]", shown, at);
        }
        return ERROR_VALUE;
    }
    int e = -1;
    while (e + 1 <= fe->n_elements && fe->z[e + 1] <= z) { /* searchsorted(side="right") - 1 */
        e++;
    }
    e = e < 0 ? 0 : e > fe->n_elements - 1 ? fe->n_elements - 1 : e;
    double h = fe->z[e + 1] - fe->z[e], xi = (z - fe->z[e]) / h;
    xi = xi < 0.0 ? 0.0 : xi > 1.0 ? 1.0 : xi;
    double x2 = xi * xi, x3 = pow(xi, 3.0);
    double shape[4] = {1 - 3 * x2 + 2 * x3, h * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, h * (x3 - x2)};
    for (int i = 0; i < rotor->n; i++) {
        row[i] = cplx_real(0.0);
    }
    for (int k = 0; k < 4; k++) {
        int target = fe->index[fe->elements[4 * e + k]];
        if (target >= 0) {
            row[target].re += shape[k];
        }
    }
    return ERROR_NONE;
}

void unbalance_outputs_free(UnbalanceOutputs *outputs)
{
    if (!outputs) {
        return;
    }
    rotor_free(&outputs->rotor);
    free(outputs->load);
    free(outputs->row);
    cubic_spline_free(&outputs->modes);
    free(outputs->ab);
    free(outputs->x);
    free(outputs->dx);
    free(outputs->pivots);
    free(outputs->place);
    free(outputs);
}

/* UnbalanceOutputs.build */
ErrorKind unbalance_outputs_new(const Driveline *d, const RotorUnbalance *unbalances, int n_unbalances,
                                double response_fraction, double omega_max, UnbalanceOutputs **out, char *error,
                                size_t size)
{
    int *counts = malloc((size_t)(d->n_segments + 1) * sizeof *counts);
    UnbalanceOutputs *outputs = calloc(1, sizeof *outputs);
    ErrorKind failed;
    *out = NULL;
    if (!counts || !outputs) {
        free(counts);
        free(outputs);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    double spins[ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS],
        table[ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS * 2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES];
    double step = omega_max / (ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS - 1); /* numpy.linspace */
    for (int i = 0; i < ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS; i++) {
        spins[i] = i * step + 0.0;
    }
    spins[ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS - 1] = omega_max;
    fe_elements_by_length(d, ROTOR_UNBALANCE_OUTPUTS_TABLE_ELEMENTS, counts);
    if ((failed = mode_table(d, counts, spins, table, error, size)) != ERROR_NONE) {
        free(counts);
        free(outputs);
        return failed;
    }
    fe_elements_by_length(d, ROTOR_UNBALANCE_OUTPUTS_FE_ELEMENTS, counts);
    Rotor *rotor = &outputs->rotor;
    if ((failed = rotor_init(rotor, d, counts, error, size)) != ERROR_NONE) {
        free(counts);
        free(outputs);
        return failed;
    }
    free(counts);
    free(rotor->K); /* the response needs the band matrices only */
    free(rotor->C);
    free(rotor->G);
    rotor->K = rotor->C = rotor->G = NULL;
    int m = rotor->size;
    outputs->load = calloc((size_t)m, sizeof *outputs->load);
    outputs->row = calloc((size_t)rotor->n + 1, sizeof *outputs->row);
    outputs->ab = malloc((size_t)rotor->band.rows * (size_t)m * sizeof *outputs->ab);
    outputs->x = malloc((size_t)m * sizeof *outputs->x);
    outputs->dx = malloc((size_t)m * sizeof *outputs->dx);
    outputs->pivots = malloc((size_t)m * sizeof *outputs->pivots);
    outputs->place = malloc((size_t)m * sizeof *outputs->place);
    cplx *rows = malloc(((size_t)rotor->n + 1) * sizeof *rows);
    if (!outputs->load || !outputs->row || !outputs->ab || !outputs->x || !outputs->dx || !outputs->pivots ||
        !outputs->place || !rows) {
        free(rows);
        unbalance_outputs_free(outputs);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (int i = 0; i < m; i++) {
        outputs->place[rotor->order[i]] = i;
    }
    /* DampedRotor.load: the unbalances' phasors times their shape rows */
    double length = driveline_length(d);
    for (int u = 0; u < n_unbalances; u++) {
        if ((failed = shape_row(rotor, unbalances[u].position, length, rows, error, size)) != ERROR_NONE) {
            free(rows);
            unbalance_outputs_free(outputs);
            return failed;
        }
        cplx phasor = cplx_scale(unbalances[u].amount, cplx_expi(unbalances[u].phase));
        for (int i = 0; i < rotor->n; i++) {
            outputs->load[i] = cplx_add(outputs->load[i], cplx_mul(phasor, rows[i]));
        }
    }
    free(rows);
    if ((failed = shape_row(rotor, response_fraction * length, length, outputs->row, error, size)) != ERROR_NONE) {
        unbalance_outputs_free(outputs);
        return failed;
    }
    /* CubicSpline(spins, table) and its checks */
    const char *refused = NULL;
    for (int i = 0; i < ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS * 2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES; i++) {
        refused = isfinite(table[i]) ? refused : "`y` must contain only finite values.";
    }
    for (int i = 0; i < ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS; i++) {
        refused = i > 0 && !(spins[i] > spins[i - 1]) && !refused ? "`x` must be strictly increasing sequence."
                                                                   : refused;
    }
    refused = isfinite(omega_max) ? refused : "`x` must contain only finite values.";
    if (refused || cubic_spline_build(&outputs->modes, ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS, spins,
                                      2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES, table)) {
        memset(&outputs->modes, 0, sizeof outputs->modes);
        unbalance_outputs_free(outputs);
        ROTOR_ERROR(error, size, refused ? refused : ROTOR_OUT_OF_MEMORY); /* scipy's ValueError */
        return ERROR_VALUE;
    }
    *out = outputs;
    return ERROR_NONE;
}

void unbalance_outputs_modes(const UnbalanceOutputs *outputs, double speed,
                             double out[2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES])
{
    cubic_spline_evaluate(&outputs->modes, speed, out);
}

/* The tabulated mode nearest ``speed``: numpy.argmin of |frequency - speed|, the first of equal ones, the first NaN */
static int nearest_mode(const double *table, double speed)
{
    int nearest = 0;
    for (int k = 0; k < ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES; k++) {
        double distance = fabs(table[k] - speed);
        if (isnan(distance)) {
            return k;
        }
        if (distance < fabs(table[nearest] - speed)) {
            nearest = k;
        }
    }
    return nearest;
}

/* DampedRotor.solve at ``speed``: K2 + i Omega (C2 + Omega Gv) - Omega^2 M2 factorised into ``ab``, the
 * response to Omega^2 [F, 0] into ``x`` (interleaved order); -1 if it is exactly singular */
static int dynamic_solve(const UnbalanceOutputs *outputs, double speed)
{
    const Rotor *rotor = &outputs->rotor;
    cplx spin_c = cplx_make(0.0, speed), spin_g = cplx_make(0.0, speed * speed);
    double squared = speed * speed;
    size_t cells = (size_t)rotor->band.rows * (size_t)rotor->size;
    for (size_t i = 0; i < cells; i++) {
        outputs->ab[i] = cplx_sub(cplx_add(cplx_add(rotor->banded[0][i], cplx_mul(spin_c, rotor->banded[1][i])),
                                            cplx_mul(spin_g, rotor->banded[2][i])),
                                   cplx_scale(squared, rotor->banded[3][i]));
    }
    for (int i = 0; i < rotor->size; i++) {
        outputs->x[i] = cplx_scale(squared, outputs->load[rotor->order[i]]);
    }
    return band_solve(rotor->band, outputs->ab, outputs->pivots, outputs->x);
}

/* The response's derivative in the speed into ``dx``, ``ab`` and ``x`` being dynamic_solve's: with
 * A = K2 + i Omega (C2 + Omega Gv) - Omega^2 M2 and b = Omega^2 [F, 0], x' = A^-1 (b' - A' x),
 * A' = i (C2 + 2 Omega Gv) - 2 Omega M2, b' = 2 Omega [F, 0]. */
static void response_slope(const UnbalanceOutputs *outputs, double speed)
{
    const Rotor *rotor = &outputs->rotor;
    Band band = rotor->band;
    cplx spin_c = cplx_make(0.0, 1.0), spin_g = cplx_make(0.0, 2.0 * speed);
    for (int i = 0; i < band.n; i++) {
        outputs->dx[i] = cplx_scale(2.0 * speed, outputs->load[rotor->order[i]]);
    }
    for (int j = 0; j < band.n; j++) {
        int first = j - band.ku > 0 ? j - band.ku : 0, last = j + band.kl < band.n ? j + band.kl : band.n - 1;
        for (int i = first; i <= last; i++) {
            cplx slope = cplx_sub(cplx_add(cplx_mul(spin_c, AB(band, rotor->banded[1], i, j)),
                                           cplx_mul(spin_g, AB(band, rotor->banded[2], i, j))),
                                  cplx_scale(2.0 * speed, AB(band, rotor->banded[3], i, j)));
            outputs->dx[i] = cplx_sub(outputs->dx[i], cplx_mul(slope, outputs->x[j]));
        }
    }
    band_substitute(band, outputs->ab, outputs->pivots, outputs->dx);
}

/* d|z| = Re(conj(z) dz) / |z|; 0 at z = 0 (|B| of an axisymmetric rotor, identically 0) */
static double modulus_slope(cplx z, cplx dz)
{
    double size = cplx_abs(z);
    return size > 0.0 ? (z.re * dz.re + z.im * dz.im) / size : 0.0;
}

/* (k + i Omega c) a: a bearing's force from the response ``a`` of one circle */
static cplx bearing_term(cplx k, cplx c, cplx spin_c, cplx a)
{
    return cplx_mul(cplx_add(k, cplx_mul(spin_c, c)), a);
}

/* its derivative in the speed: (k + i Omega c) a' + i c a */
static cplx bearing_slope(cplx k, cplx c, cplx spin_c, cplx a, cplx da)
{
    return cplx_add(bearing_term(k, c, spin_c, da), cplx_mul(cplx_make(0.0, 1.0), cplx_mul(c, a)));
}

/* The orbit's major semi-axis at the response row and the largest bearing force of the response in ``x``
 * at ``speed`` (components, bearing_forces) into out[0], out[1]; with ``slopes`` (NULL: none) their
 * derivatives in the speed from x' in ``dx``, the largest force's that of the bearing it is at. */
static void orbit_and_forces(const UnbalanceOutputs *outputs, double speed, double out[2], double slopes[2])
{
    const Rotor *rotor = &outputs->rotor;
    int n = rotor->n;
    cplx spin_c = cplx_make(0.0, speed), zero = cplx_real(0.0);
    cplx forward = zero, backward = zero, d_forward = zero, d_backward = zero;
    const cplx *x = outputs->x, *dx = outputs->dx;
    const int *place = outputs->place;
    for (int j = 0; j < n; j++) {
        forward = cplx_add(forward, cplx_mul(x[place[j]], outputs->row[j]));
        if (rotor->doubled) {
            backward = cplx_add(backward, cplx_mul(x[place[n + j]], outputs->row[j]));
        }
        if (slopes) {
            d_forward = cplx_add(d_forward, cplx_mul(dx[place[j]], outputs->row[j]));
            d_backward = rotor->doubled ? cplx_add(d_backward, cplx_mul(dx[place[n + j]], outputs->row[j])) : zero;
        }
    }
    out[0] = cplx_abs(forward) + cplx_abs(cplx_conj(backward));
    double largest = 0.0, d_largest = 0.0; /* np.max(forces, initial=0.0), nan propagated */
    for (int b = 0; b < rotor->n_bearings; b++) {
        int row = rotor->bearing_rows[b];
        double force = 0.0, d_force = 0.0;
        if (row >= 0) {
            const cplx *c = rotor->coefficients + 4 * b;
            cplx a = x[place[row]], q = rotor->doubled ? x[place[n + row]] : zero;
            cplx fa = cplx_add(bearing_term(c[0], c[2], spin_c, a), bearing_term(c[1], c[3], spin_c, q));
            cplx fq = cplx_add(bearing_term(cplx_conj(c[1]), cplx_conj(c[3]), spin_c, a),
                               bearing_term(cplx_conj(c[0]), cplx_conj(c[2]), spin_c, q));
            force = cplx_abs(fa) + cplx_abs(fq);
            if (slopes) {
                cplx da = dx[place[row]], dq = rotor->doubled ? dx[place[n + row]] : zero;
                cplx dfa = cplx_add(bearing_slope(c[0], c[2], spin_c, a, da), bearing_slope(c[1], c[3], spin_c, q, dq));
                cplx dfq = cplx_add(bearing_slope(cplx_conj(c[1]), cplx_conj(c[3]), spin_c, a, da),
                                    bearing_slope(cplx_conj(c[0]), cplx_conj(c[2]), spin_c, q, dq));
                d_force = modulus_slope(fa, dfa) + modulus_slope(fq, dfq);
            }
        }
        if (isnan(force) || force > largest) {
            d_largest = isnan(largest) ? d_largest : d_force;
            largest = isnan(largest) ? largest : force;
        }
    }
    out[1] = largest;
    if (slopes) {
        slopes[0] = modulus_slope(forward, d_forward) + modulus_slope(cplx_conj(backward), cplx_conj(d_backward));
        slopes[1] = d_largest;
    }
}

/* UnbalanceOutputs.evaluate (DampedRotor.solve, components and bearing_forces at one speed) */
void unbalance_outputs_evaluate(const UnbalanceOutputs *outputs, double speed, double out[3])
{
    double table[2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES];
    cubic_spline_evaluate(&outputs->modes, speed, table);
    out[2] = table[ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES + nearest_mode(table, speed)];
    if (speed == 0.0) {
        out[0] = out[1] = 0.0;
        return;
    }
    if (dynamic_solve(outputs, speed)) { /* an undamped resonance hit exactly */
        out[0] = out[1] = INFINITY;
        return;
    }
    orbit_and_forces(outputs, speed, out, NULL);
}

void unbalance_outputs_slopes(const UnbalanceOutputs *outputs, double speed, double slopes[3])
{
    double table[2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES], out[2];
    cubic_spline_evaluate(&outputs->modes, speed, table);
    slopes[2] = cubic_spline_slope(&outputs->modes, speed,
                                   ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES + nearest_mode(table, speed));
    if (speed == 0.0) { /* the response grows as Omega^2 */
        slopes[0] = slopes[1] = 0.0;
        return;
    }
    if (dynamic_solve(outputs, speed)) { /* the infinite response, which a step refuses */
        slopes[0] = slopes[1] = NAN;
        return;
    }
    response_slope(outputs, speed);
    orbit_and_forces(outputs, speed, out, slopes);
}
