/* Finite-element model of a driveline (fem.py, the fe_matrices of elements.py) and the natural
 * frequencies of its plausibility check (model.natural_frequencies). */
#include "rotor.h"

#include "elements.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* fem.elements_by_length */
void fe_elements_by_length(const Driveline *driveline, int most, int *counts)
{
    double half = 0.5 * driveline_length(driveline);
    for (int k = 0; k < driveline->n_segments; k++) {
        double share = ceil(most * driveline->segments[k].length / half - ROTOR_FEM_SHARE_SLACK);
        int count = share >= most ? most : (int)share;
        counts[k] = count < 1 ? 1 : count;
    }
}

/* ---- fem.mesh ------------------------------------------------------------------------------- */
/* One element's contribution on ``n`` dofs (Mesh.blocks): row-major n x n each, NULL for zero. */
typedef struct {
    const int *dofs;
    int n;
    const double *K, *M, *G;
} Block;

static void add_block(const FeModel *model, const Block *block)
{
    int n_kept = model->n_kept;
    for (int i = 0; i < block->n; i++) {
        int row = model->index[block->dofs[i]];
        if (row < 0) {
            continue;
        }
        for (int j = 0; j < block->n; j++) {
            int col = model->index[block->dofs[j]];
            if (col < 0) {
                continue;
            }
            size_t at = (size_t)row * (size_t)n_kept + (size_t)col, local = (size_t)i * (size_t)block->n + (size_t)j;
            if (block->K) {
                model->K[at] += block->K[local];
            }
            if (block->M) {
                model->M[at] += block->M[local];
            }
            if (block->G) {
                model->G[at] += block->G[local];
            }
        }
    }
}

void fe_model_free(FeModel *model)
{
    if (!model) {
        return;
    }
    free(model->index);
    free(model->elements);
    free(model->z);
    free(model->node_u);
    free(model->K);
    free(model->M);
    free(model->G);
    memset(model, 0, sizeof *model);
}

/* fem._fixed_dofs */
static void fix_end(EndCondition end, int u, int psi, int *fixed)
{
    if (end == END_PINNED || end == END_CLAMPED) {
        fixed[u] = 1;
    }
    if (end == END_CLAMPED) {
        fixed[psi] = 1;
    }
}

/* One point element's block on [U, psi] (or [U, psi_in, psi_out]) */
static void add_point(const FeModel *model, int here, int n, const int *dofs, const double *K, const double *M,
                      const double *G)
{
    if (model->K && here) {
        Block block = {dofs, n, K, M, G};
        add_block(model, &block);
    }
}

/* fem.mesh: numbers the dofs (``fixed`` marks those of the end conditions, model->node_u, elements
 * and z are filled) and, once model->K exists, adds every block in the Python order. ``segment``
 * holds 3 (2 (count + 1))^2 and ``dofs`` 2 (count + 1) for the largest count. Returns n_dof. */
static int walk_mesh(const Driveline *d, const int *counts, int with_bearings, FeModel *model, int *fixed,
                     double *segment, int *dofs)
{
    int u = 0, psi = 1, n_dof = 2, element = 0;
    model->z[0] = 0.0;
    for (int node = 0; node <= d->n_segments; node++) {
        model->node_u[node] = u;
        if (node == 0) {
            fix_end(d->left, u, psi, fixed);
        }
        /* Driveline.point_elements at the node: masses, bearings, hinges */
        for (int i = 0; i < d->n_masses; i++) {
            const RotorMass *mass = &d->masses[i];
            int pair[2] = {u, psi};
            double M[4] = {mass->mass, 0.0, 0.0, mass->diametral_inertia}, G[4] = {0.0, 0.0, 0.0, mass->polar_inertia};
            add_point(model, mass->node == node, 2, pair, NULL, M, G);
        }
        for (int i = 0; with_bearings && i < d->n_bearings; i++) {
            const RotorBearing *bearing = &d->bearings[i];
            int pair[2] = {u, psi};
            double K[4] = {0.5 * (bearing->kxx + bearing->kyy), 0.0, 0.0, 0.0};
            add_point(model, bearing->node == node, 2, pair, K, NULL, NULL);
        }
        for (int i = 0; i < d->n_hinges; i++) {
            if (d->hinges[i].node != node) {
                continue;
            }
            double k = d->hinges[i].bending_stiffness;
            int triple[3] = {u, psi, n_dof};
            double K[9] = {0.0, 0.0, 0.0, 0.0, k, -k, 0.0, -k, k};
            psi = n_dof++;
            add_point(model, 1, 3, triple, K, NULL, NULL);
        }
        if (node == d->n_segments) {
            fix_end(d->right, u, psi, fixed);
            break;
        }
        /* ShaftSegment.fe_matrices(count): the segment's own assembly, added as one block */
        const RotorSegment *s = &d->segments[node];
        int count = counts[node], n = 2 * (count + 1);
        double h = s->length / count;
        dofs[0] = u;
        dofs[1] = psi;
        for (int i = 2; i < n; i++) {
            dofs[i] = n_dof + i - 2;
        }
        n_dof += 2 * count;
        u = dofs[n - 2];
        psi = dofs[n - 1];
        if (model->K) {
            double *K = segment, *M = segment + (size_t)n * (size_t)n, *G = M + (size_t)n * (size_t)n;
            double k[16], m[16], g[16];
            memset(segment, 0, 3 * (size_t)n * (size_t)n * sizeof *segment);
            segment_fe_element(s, h, k, m, g);
            for (int e = 0; e < count; e++) {
                for (int i = 0; i < 4; i++) {
                    for (int j = 0; j < 4; j++) {
                        size_t at = (size_t)(2 * e + i) * (size_t)n + (size_t)(2 * e + j);
                        K[at] += k[4 * i + j];
                        M[at] += m[4 * i + j];
                        G[at] += g[4 * i + j];
                    }
                }
            }
            Block block = {dofs, n, K, M, G};
            add_block(model, &block);
        }
        for (int e = 0; e < count; e++, element++) {
            for (int i = 0; i < 4; i++) {
                model->elements[4 * element + i] = dofs[2 * e + i];
            }
            model->z[element + 1] = model->z[element] + h;
        }
    }
    return n_dof;
}

/* fem.mesh, Mesh.matrices and the kept rows (fem.assemble) */
ErrorKind fe_model_build(const Driveline *d, const int *counts, int with_bearings, FeModel *model, char *error,
                         size_t size)
{
    memset(model, 0, sizeof *model);
    int n_nodes = d->n_segments + 1, n_elements = 0, local = 0;
    for (int k = 0; k < d->n_segments; k++) {
        n_elements += counts[k];
        local = counts[k] > local ? counts[k] : local;
    }
    for (int i = 0; with_bearings && i < d->n_bearings; i++) {
        if (d->bearings[i].kxx != d->bearings[i].kyy) { /* Bearing.fe_matrices */
            ROTOR_ERROR(error, size, "the finite-element check covers isotropic bearings only");
            return ERROR_VALUE;
        }
    }
    int max_dof = 2 + 2 * n_elements + d->n_hinges, local_n = 2 * (local + 1);
    int *fixed = calloc((size_t)max_dof, sizeof *fixed);
    double *segment = malloc(3 * (size_t)local_n * (size_t)local_n * sizeof *segment);
    int *dofs = malloc((size_t)local_n * sizeof *dofs);
    model->index = malloc((size_t)max_dof * sizeof *model->index);
    model->elements = malloc(4 * (size_t)n_elements * sizeof *model->elements);
    model->z = malloc((size_t)(n_elements + 1) * sizeof *model->z);
    model->node_u = malloc((size_t)n_nodes * sizeof *model->node_u);
    if (!fixed || !segment || !dofs || !model->index || !model->elements || !model->z || !model->node_u) {
        goto out_of_memory;
    }
    int n_dof = walk_mesh(d, counts, with_bearings, model, fixed, segment, dofs);
    model->n_dof = n_dof;
    model->n_elements = n_elements;
    int n_kept = 0;
    for (int g = 0; g < n_dof; g++) {
        model->index[g] = fixed[g] ? -1 : n_kept++;
    }
    model->n_kept = n_kept;
    size_t cells = (size_t)n_kept * (size_t)n_kept + 1;
    model->K = calloc(cells, sizeof *model->K);
    model->M = calloc(cells, sizeof *model->M);
    model->G = calloc(cells, sizeof *model->G);
    if (!model->K || !model->M || !model->G) {
        goto out_of_memory;
    }
    memset(fixed, 0, (size_t)max_dof * sizeof *fixed);
    walk_mesh(d, counts, with_bearings, model, fixed, segment, dofs);
    free(fixed);
    free(segment);
    free(dofs);
    return ERROR_NONE;
out_of_memory:
    ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
    fe_model_free(model);
    free(fixed);
    free(segment);
    free(dofs);
    return ERROR_VALUE;
}

/* ---- scipy.linalg.eigh(K, M, eigvals_only=True) ---------------------------------------------- */
/* Cholesky factor M = L L^T in the lower triangle of ``m``; the order of the failing minor, or 0.
 * L keeps M's envelope: row i from its first non-zero, ``start`` (n places). */
static int cholesky(double *m, int n, int *start)
{
    for (int i = 0; i < n; i++) {
        const double *row = m + (size_t)i * (size_t)n;
        int first = 0;
        while (first < i && row[first] == 0.0) {
            first++;
        }
        start[i] = first;
    }
    for (int j = 0; j < n; j++) {
        double *row_j = m + (size_t)j * (size_t)n;
        double diagonal = row_j[j];
        for (int k = start[j]; k < j; k++) {
            diagonal -= row_j[k] * row_j[k];
        }
        if (!(diagonal > 0.0)) {
            return j + 1;
        }
        diagonal = sqrt(diagonal);
        row_j[j] = diagonal;
        for (int i = j + 1; i < n; i++) {
            double *row_i = m + (size_t)i * (size_t)n, sum = row_i[j];
            if (start[i] > j) {
                continue;
            }
            for (int k = start[i] > start[j] ? start[i] : start[j]; k < j; k++) {
                sum -= row_i[k] * row_j[k];
            }
            row_i[j] = sum / diagonal;
        }
    }
    return 0;
}

/* a = L^-1 a L^-T for the symmetric ``a`` (both triangles on return); row i of L starts at
 * ``first_nonzero[i]`` (cholesky's envelope) */
static void reduce_to_standard(double *a, const double *l, int n, const int *first_nonzero)
{
    /* L^-1 a: forward substitution, a row at a time */
    for (int i = 0; i < n; i++) {
        double *row = a + (size_t)i * (size_t)n;
        const double *li = l + (size_t)i * (size_t)n;
        for (int k = 0; k < i; k++) {
            const double *done = a + (size_t)k * (size_t)n;
            if (li[k] != 0.0) {
                for (int c = 0; c < n; c++) {
                    row[c] -= li[k] * done[c];
                }
            }
        }
        for (int c = 0; c < n; c++) {
            row[c] /= li[i];
        }
    }
    /* (L^-1 a) L^-T: the same substitution along each row, from each row of L's first non-zero */
    for (int r = 0; r < n; r++) {
        double *row = a + (size_t)r * (size_t)n;
        for (int j = 0; j < n; j++) {
            double sum = row[j];
            const double *lj = l + (size_t)j * (size_t)n;
            for (int k = first_nonzero[j]; k < j; k++) {
                sum -= row[k] * lj[k];
            }
            row[j] = sum / lj[j];
        }
    }
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < i; j++) {
            double mean = 0.5 * (a[(size_t)i * (size_t)n + (size_t)j] + a[(size_t)j * (size_t)n + (size_t)i]);
            a[(size_t)i * (size_t)n + (size_t)j] = mean;
            a[(size_t)j * (size_t)n + (size_t)i] = mean;
        }
    }
}

/* Householder reduction of the symmetric ``a`` to tridiagonal: diagonal d, off-diagonal e (n - 1) */
static void tridiagonalize(double *a, int n, double *d, double *e, double *v, double *p)
{
    for (int k = 0; k + 2 < n; k++) {
        int m = n - k - 1; /* the column below the diagonal: rows k + 1 .. n - 1 */
        double scale = 0.0;
        for (int i = 0; i < m; i++) {
            v[i] = a[(size_t)(k + 1 + i) * (size_t)n + (size_t)k];
            scale = fmax(scale, fabs(v[i]));
        }
        if (scale == 0.0) {
            e[k] = 0.0;
            continue;
        }
        double norm2 = 0.0;
        for (int i = 0; i < m; i++) {
            v[i] /= scale;
            norm2 += v[i] * v[i];
        }
        double alpha = v[0] >= 0.0 ? -sqrt(norm2) : sqrt(norm2);
        e[k] = alpha * scale;
        v[0] -= alpha;
        double vv = 0.0; /* |x - alpha e1|^2 */
        for (int i = 0; i < m; i++) {
            vv += v[i] * v[i];
        }
        double tau = 2.0 / vv, vp = 0.0;
        /* p = tau A v on the trailing block; w = p - (tau/2)(v.p) v; A -= v w^T + w v^T */
        for (int i = 0; i < m; i++) {
            const double *row = a + (size_t)(k + 1 + i) * (size_t)n + (size_t)(k + 1);
            double sum = 0.0;
            for (int j = 0; j < m; j++) {
                sum += row[j] * v[j];
            }
            p[i] = tau * sum;
            vp += v[i] * p[i];
        }
        for (int i = 0; i < m; i++) {
            p[i] -= 0.5 * tau * vp * v[i];
        }
        for (int i = 0; i < m; i++) {
            double *row = a + (size_t)(k + 1 + i) * (size_t)n + (size_t)(k + 1);
            for (int j = 0; j < m; j++) {
                row[j] -= v[i] * p[j] + p[i] * v[j];
            }
        }
    }
    for (int i = 0; i < n; i++) {
        d[i] = a[(size_t)i * (size_t)n + (size_t)i];
    }
    if (n >= 2) {
        e[n - 2] = a[(size_t)(n - 1) * (size_t)n + (size_t)(n - 2)];
    }
}

/* Eigenvalues of the symmetric tridiagonal (d, e) by implicitly shifted QR steps (Wilkinson shift)
 * with deflation; 0, or -1 when a block does not converge within the iteration cap. */
static int tridiagonal_eigenvalues(double *d, double *e, int n)
{
    int iterations = 0, cap = 30 * (n > 10 ? n : 10);
    int hi = n - 1;
    while (hi > 0) {
        /* deflate at the bottom */
        if (fabs(e[hi - 1]) <= DBL_EPSILON * (fabs(d[hi - 1]) + fabs(d[hi]))) {
            e[hi - 1] = 0.0;
            hi--;
            continue;
        }
        int lo = hi - 1;
        while (lo > 0 && fabs(e[lo - 1]) > DBL_EPSILON * (fabs(d[lo - 1]) + fabs(d[lo]))) {
            lo--;
        }
        if (lo > 0) {
            e[lo - 1] = 0.0;
        }
        if (++iterations > cap) {
            return -1;
        }
        /* Wilkinson shift from the trailing 2 x 2 */
        double delta = 0.5 * (d[hi - 1] - d[hi]), b = e[hi - 1];
        double root = hypot(delta, b);
        double mu = d[hi] - b * b / (delta + (delta >= 0.0 ? root : -root));
        if (delta == 0.0 && b == 0.0) {
            mu = d[hi];
        }
        double x = d[lo] - mu, z = e[lo];
        for (int k = lo; k < hi; k++) {
            double r = hypot(x, z), c = r == 0.0 ? 1.0 : x / r, s = r == 0.0 ? 0.0 : z / r;
            if (k > lo) {
                e[k - 1] = r;
            }
            double a = d[k], bk = e[k], dd = d[k + 1];
            double cs = c * s, cc = c * c, ss = s * s;
            d[k] = cc * a + 2.0 * cs * bk + ss * dd;
            d[k + 1] = ss * a - 2.0 * cs * bk + cc * dd;
            e[k] = cs * (dd - a) + (cc - ss) * bk;
            if (k + 1 < hi) {
                z = s * e[k + 1];
                e[k + 1] *= c;
                x = e[k];
            }
        }
    }
    return 0;
}

static int ascending(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* eigh(K, M, eigvals_only=True) ascending into ``values``; K and M are overwritten. ERROR_NONE, or
 * ERROR_VALUE with the message (scipy's LinAlgError, the iteration not converging, out of memory). */
static ErrorKind generalized_eigenvalues(double *K, double *M, int n, double *values, char *error, size_t size)
{
    int *first_nonzero = malloc((size_t)(n + 1) * sizeof *first_nonzero);
    if (!first_nonzero) {
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    int minor = cholesky(M, n, first_nonzero);
    if (minor) {
        free(first_nonzero);
        if (error && size) {
            snprintf(error, size,
                     "The leading minor of order %d of B is not positive definite. The factorization of B could "
                     "not be completed and no eigenvalues or eigenvectors were computed.", minor);
        }
        return ERROR_VALUE;
    }
    double *work = malloc(3 * (size_t)(n + 1) * sizeof *work);
    if (!work) {
        free(first_nonzero);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    reduce_to_standard(K, M, n, first_nonzero);
    free(first_nonzero);
    double *e = work, *v = work + n + 1, *p = v + n + 1;
    tridiagonalize(K, n, values, e, v, p);
    /* scaled by a power of two (exact) to order one: the shifts' squares neither overflow nor underflow */
    double largest = 0.0;
    for (int i = 0; i < n; i++) {
        largest = fmax(largest, fmax(fabs(values[i]), i + 1 < n ? fabs(e[i]) : 0.0));
    }
    int exponent = 0;
    if (largest > 0.0 && isfinite(largest)) {
        frexp(largest, &exponent);
    }
    for (int i = 0; i < n; i++) {
        values[i] = ldexp(values[i], -exponent);
        if (i + 1 < n) {
            e[i] = ldexp(e[i], -exponent);
        }
    }
    int status = tridiagonal_eigenvalues(values, e, n);
    for (int i = 0; i < n; i++) {
        values[i] = ldexp(values[i], exponent);
    }
    free(work);
    if (status) {
        ROTOR_ERROR(error, size, "the eigenvalue iteration did not converge");
        return ERROR_VALUE;
    }
    qsort(values, (size_t)n, sizeof *values, ascending);
    return ERROR_NONE;
}

/* The natural frequencies of one plane: bearings isotropic with ``stiffness``; ERROR_NONE, or the
 * failure's kind with the message */
static ErrorKind plane_frequencies(const Driveline *d, const int *counts, RotorBearing *plane, double *out, int *count,
                                   char *error, size_t size)
{
    Driveline copy = *d;
    copy.bearings = plane;
    FeModel model;
    ErrorKind failed = fe_model_build(&copy, counts, 1, &model, error, size);
    if (failed != ERROR_NONE) {
        return failed;
    }
    int n = model.n_kept;
    for (size_t i = 0; i < (size_t)n * (size_t)n; i++) {
        if (!isfinite(model.K[i]) || !isfinite(model.M[i])) { /* scipy.linalg.eigh's check_finite */
            ROTOR_ERROR(error, size, "array must not contain infs or NaNs");
            fe_model_free(&model);
            return ERROR_VALUE;
        }
    }
    if ((failed = generalized_eigenvalues(model.K, model.M, n, out, error, size)) != ERROR_NONE) {
        fe_model_free(&model);
        return failed;
    }
    for (int i = 0; i < n; i++) {
        out[i] = sqrt(fabs(out[i]));
    }
    *count = n;
    fe_model_free(&model);
    return ERROR_NONE;
}

/* model.natural_frequencies: the kxx plane, then (anisotropic bearings) the kyy plane */
ErrorKind fe_natural_frequencies(const Driveline *d, int elements, double **frequencies, int *count, char *error,
                                 size_t size)
{
    *frequencies = NULL;
    *count = 0;
    if (elements < 1) { /* ShaftSegment.fe_matrices: length / n_elements */
        ROTOR_ERROR(error, size, "float division by zero");
        return ERROR_ZERO_DIVISION;
    }
    int n_bearings = d->n_bearings, planes = 1, total = 2 + d->n_hinges;
    for (int i = 0; i < n_bearings; i++) {
        planes = d->bearings[i].kxx != d->bearings[i].kyy ? 2 : planes;
    }
    for (int k = 0; k < d->n_segments; k++) {
        total += 2 * elements;
    }
    int *counts = malloc((size_t)(d->n_segments + 1) * sizeof *counts);
    RotorBearing *plane = malloc((size_t)(n_bearings + 1) * sizeof *plane);
    double *out = malloc((size_t)planes * (size_t)total * sizeof *out);
    if (!counts || !plane || !out) {
        free(counts);
        free(plane);
        free(out);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (int k = 0; k < d->n_segments; k++) {
        counts[k] = elements;
    }
    int found = 0;
    for (int p = 0; p < planes; p++) {
        for (int i = 0; i < n_bearings; i++) { /* Bearing(b.node, k) */
            double k = p == 0 ? d->bearings[i].kxx : d->bearings[i].kyy;
            RotorBearing isotropic = {d->bearings[i].node, k, k, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
            plane[i] = isotropic;
        }
        int n = 0;
        ErrorKind failed = plane_frequencies(d, counts, plane, out + found, &n, error, size);
        if (failed != ERROR_NONE) {
            free(counts);
            free(plane);
            free(out);
            return failed;
        }
        found += n;
    }
    free(counts);
    free(plane);
    *frequencies = out;
    *count = found;
    return ERROR_NONE;
}
