/* Damped finite-element model of a driveline (damped.DampedRotor): damped modes from a dense complex
 * eigensolver up to DENSE_SIZE first-order unknowns and by shift-invert Arnoldi on a banded factorisation
 * above (the linear algebra in linalg.c), and the mode table the FMU's damping ratio interpolates; the
 * unbalance outputs in unbalance_outputs.c. */
#include "damped.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- damped.DampedRotor ---------------------------------------------------------------------- */
void rotor_free(Rotor *rotor)
{
    fe_model_free(&rotor->fe);
    free(rotor->K);
    free(rotor->C);
    free(rotor->G);
    for (int k = 0; k < 4; k++) {
        free(rotor->banded[k]);
    }
    free(rotor->order);
    free(rotor->translations);
    free(rotor->bearing_rows);
    free(rotor->coefficients);
    memset(rotor, 0, sizeof *rotor);
}

/* elements._components: the coefficients of u and conj(u) of [[xx, xy], [yx, yy]] */
static void components(double xx, double yy, double xy, double yx, cplx *a, cplx *b)
{
    *a = cplx_make(0.5 * (xx + yy), 0.5 * (yx - xy));
    *b = cplx_make(0.5 * (xx - yy), 0.5 * (yx + xy));
}

/* DampedRotor.__init__ (with fem.assemble_damped); ERROR_NONE, or the failure's kind with the message */
ErrorKind rotor_init(Rotor *rotor, const Driveline *d, const int *counts, char *error, size_t size)
{
    memset(rotor, 0, sizeof *rotor);
    ErrorKind failed = fe_model_build(d, counts, 0, &rotor->fe, error, size);
    if (failed != ERROR_NONE) {
        return failed;
    }
    const FeModel *fe = &rotor->fe;
    int n = fe->n_kept, nb = d->n_bearings;
    size_t cells = (size_t)n * (size_t)n;
    cplx *Kb = calloc(cells + 1, sizeof *Kb), *Cb = calloc(cells + 1, sizeof *Cb);
    cplx *Ka = calloc(cells + 1, sizeof *Ka), *Ca = calloc(cells + 1, sizeof *Ca);
    rotor->bearing_rows = malloc((size_t)(nb + 1) * sizeof *rotor->bearing_rows);
    rotor->coefficients = malloc(4 * (size_t)(nb + 1) * sizeof *rotor->coefficients);
    rotor->translations = malloc((size_t)(fe->n_elements + 1) * sizeof *rotor->translations);
    if (!Kb || !Cb || !Ka || !Ca || !rotor->bearing_rows || !rotor->coefficients || !rotor->translations) {
        goto out_of_memory;
    }
    for (size_t i = 0; i < cells; i++) {
        Ka[i] = cplx_real(fe->K[i]);
    }
    int doubled = 0;
    rotor->n_bearings = nb;
    for (int i = 0; i < nb; i++) {
        const RotorBearing *b = &d->bearings[i];
        cplx *c = rotor->coefficients + 4 * i;
        components(b->kxx, b->kyy, b->kxy, b->kyx, &c[0], &c[1]);
        components(b->cxx, b->cyy, b->cxy, b->cyx, &c[2], &c[3]);
        int row = fe->index[fe->node_u[b->node]];
        rotor->bearing_rows[i] = row;
        if (row < 0) { /* on a pinned or clamped end: the support holds it already */
            continue;
        }
        size_t at = (size_t)row * (size_t)n + (size_t)row;
        Ka[at] = cplx_add(Ka[at], c[0]);
        Kb[at] = cplx_add(Kb[at], c[1]);
        Ca[at] = cplx_add(Ca[at], c[2]);
        Cb[at] = cplx_add(Cb[at], c[3]);
    }
    int damped = 0, symmetric = 1;
    for (int i = 0; i < nb; i++) {
        int row = rotor->bearing_rows[i];
        symmetric &= d->bearings[i].kxy == d->bearings[i].kyx;
        if (row >= 0) {
            size_t at = (size_t)row * (size_t)n + (size_t)row;
            doubled |= !cplx_is_zero(Kb[at]) || !cplx_is_zero(Cb[at]);
            damped |= !cplx_is_zero(Ca[at]) || !cplx_is_zero(Cb[at]);
        }
    }
    rotor->conservative = !damped && symmetric;
    /* the translation rows of the beam nodes (np.unique of the elements' U dofs) */
    int count = 0;
    for (int e = 0; e <= fe->n_elements; e++) {
        int dof = e < fe->n_elements ? fe->elements[4 * e] : fe->elements[4 * (e - 1) + 2];
        int row = fe->index[dof];
        if (row >= 0) {
            rotor->translations[count++] = row;
        }
    }
    rotor->n_translations = count;
    int m = doubled ? 2 * n : n;
    rotor->n = n;
    rotor->doubled = doubled;
    rotor->size = m;
    size_t big = (size_t)m * (size_t)m + 1;
    rotor->K = calloc(big, sizeof *rotor->K);
    rotor->C = calloc(big, sizeof *rotor->C);
    rotor->G = calloc(big, sizeof *rotor->G);
    rotor->order = malloc(((size_t)m + 1) * sizeof *rotor->order);
    if (!rotor->K || !rotor->C || !rotor->G || !rotor->order) {
        goto out_of_memory;
    }
    /* K2 = [[K, K_b], [conj(K_b), conj(K)]], C2 likewise, Gv = diag(-i G, i G) */
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            size_t at = (size_t)i * (size_t)n + (size_t)j, top = (size_t)i * (size_t)m + (size_t)j;
            rotor->K[top] = Ka[at];
            rotor->C[top] = Ca[at];
            rotor->G[top] = cplx_make(0.0, -fe->G[at]);
            if (doubled) {
                size_t right = top + (size_t)n, below = top + (size_t)n * (size_t)m, across = below + (size_t)n;
                rotor->K[right] = Kb[at];
                rotor->C[right] = Cb[at];
                rotor->K[below] = cplx_conj(Kb[at]);
                rotor->C[below] = cplx_conj(Cb[at]);
                rotor->K[across] = cplx_conj(Ka[at]);
                rotor->C[across] = cplx_conj(Ca[at]);
                rotor->G[across] = cplx_make(0.0, fe->G[at]);
            }
        }
    }
    free(Ka);
    free(Kb);
    free(Ca);
    free(Cb);
    Ka = Kb = Ca = Cb = NULL;
    /* the dofs of p and q interleaved make the dynamic stiffness banded */
    for (int i = 0; i < m; i++) {
        rotor->order[i] = doubled ? (i % 2) * n + i / 2 : i;
    }
    int kl = 0, ku = 0;
    for (int i = 0; i < m; i++) {
        for (int j = 0; j < m; j++) {
            size_t at = (size_t)rotor->order[i] * (size_t)m + (size_t)rotor->order[j];
            int mass = rotor->order[i] / n == rotor->order[j] / n &&
                       fe->M[(size_t)(rotor->order[i] % n) * (size_t)n + (size_t)(rotor->order[j] % n)] != 0.0;
            if (!cplx_is_zero(rotor->K[at]) || !cplx_is_zero(rotor->C[at]) || !cplx_is_zero(rotor->G[at]) || mass) {
                kl = i - j > kl ? i - j : kl;
                ku = j - i > ku ? j - i : ku;
            }
        }
    }
    Band band = {m, kl, ku, 2 * kl + ku + 1};
    rotor->band = band;
    for (int k = 0; k < 4; k++) {
        rotor->banded[k] = calloc((size_t)band.rows * (size_t)m, sizeof *rotor->banded[k]);
        if (!rotor->banded[k]) {
            goto out_of_memory;
        }
    }
    for (int j = 0; j < m; j++) {
        int first = j - ku > 0 ? j - ku : 0, last = j + kl < m ? j + kl : m - 1;
        for (int i = first; i <= last; i++) {
            int r = rotor->order[i], c = rotor->order[j];
            size_t at = (size_t)r * (size_t)m + (size_t)c;
            AB(band, rotor->banded[0], i, j) = rotor->K[at];
            AB(band, rotor->banded[1], i, j) = rotor->C[at];
            AB(band, rotor->banded[2], i, j) = rotor->G[at];
            AB(band, rotor->banded[3], i, j) =
                cplx_real(r / n == c / n ? fe->M[(size_t)(r % n) * (size_t)n + (size_t)(c % n)] : 0.0);
        }
    }
    /* DampedRotor._scale = sqrt(max |diag K2| / max diag M2) */
    double k_max = 0.0, m_max = -INFINITY;
    for (int i = 0; i < m; i++) {
        double k = cplx_abs(rotor->K[(size_t)i * (size_t)m + (size_t)i]);
        k_max = k > k_max || isnan(k) ? k : k_max;
        m_max = fmax(m_max, fe->M[(size_t)(i % n) * (size_t)n + (size_t)(i % n)]);
    }
    rotor->scale = sqrt(k_max / m_max);
    return ERROR_NONE;
out_of_memory:
    free(Ka);
    free(Kb);
    free(Ca);
    free(Cb);
    rotor_free(rotor);
    ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
    return ERROR_VALUE;
}

/* One damped mode (damped.DampedMode) */
typedef struct {
    cplx eigenvalue;
    double forward_share;
    int place; /* among the eigenvalues: list.sort keeps the order of equal frequencies */
} Mode;

/* by damped frequency, stable */
static int by_frequency(const void *a, const void *b)
{
    const Mode *x = a, *y = b;
    double u = x->eigenvalue.im, v = y->eigenvalue.im;
    if (u != v) {
        return (u > v) - (u < v);
    }
    return (x->place > y->place) - (x->place < y->place);
}

/* ---- shift-invert Arnoldi (DampedRotor.modes above DENSE_SIZE) ------------------------------
 * The eigenvalues nu of (A - SHIFT B)^-1 B are 1 / (lam - SHIFT): the largest |nu| are the lam nearest
 * SHIFT. With y = [y1, y2] and v = [v1, v2] (x and x'/s blocks, each in the interleaved order),
 * (A - SHIFT B) y = B v reads -SHIFT y1 + s y2 = v1 and -K2 y1 / s - (C2 + spin Gv + SHIFT M2) y2 = M2 v2,
 * so that Q(SHIFT) y1 = -s M2 v2 - (C2 + spin Gv + SHIFT M2) v1 with the banded
 * Q(SHIFT) = K2 + SHIFT (C2 + spin Gv) + SHIFT^2 M2, and y2 = (v1 + SHIFT y1) / s. */
/* most Krylov vectors: memory 2 size (KRYLOV_CAP + 1) complex numbers */
#define KRYLOV_CAP 400
/* a Ritz value has converged when its residual estimate is below this times the largest |nu| */
#define RITZ_TOLERANCE (64.0 * DBL_EPSILON)

typedef struct {
    int cap, steps;        /* most Krylov vectors (0: the dense path); vectors of the last run */
    cplx *q, *coupling;    /* Q(SHIFT) factorised and C2 + spin Gv + SHIFT M2, band storage */
    int *pivots, *place;   /* Q's row swaps; place[order[i]] = i */
    cplx *basis;           /* cap + 1 orthonormal vectors of 2 size */
    cplx *hess;            /* (cap + 1) x cap Hessenberg matrix of the Arnoldi relation, by rows */
    cplx *small, *work, *lu, *ritz, *z, *multiplier; /* the leading steps x steps part and its work */
    unsigned char *swapped;
    int *rank;             /* the Ritz values by descending |nu| (the first ones wanted) */
} Krylov;

static void krylov_free(Krylov *krylov)
{
    void *all[] = {krylov->q, krylov->coupling, krylov->pivots, krylov->place, krylov->basis, krylov->hess,
                   krylov->small, krylov->work, krylov->lu, krylov->ritz, krylov->z, krylov->multiplier,
                   krylov->swapped, krylov->rank};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        free(all[i]);
    }
    memset(krylov, 0, sizeof *krylov);
}

/* The Arnoldi work arrays: 0, or -1 without memory (the caller writes the message) */
static int krylov_init(Krylov *krylov, const Rotor *rotor)
{
    memset(krylov, 0, sizeof *krylov);
    int m = rotor->size, order = 2 * m, cap = order < KRYLOV_CAP ? order : KRYLOV_CAP;
    size_t cells = (size_t)rotor->band.rows * (size_t)m, square = (size_t)cap * (size_t)cap;
    krylov->cap = cap;
    krylov->q = malloc(cells * sizeof(cplx));
    krylov->coupling = malloc(cells * sizeof(cplx));
    krylov->pivots = malloc((size_t)m * sizeof(int));
    krylov->place = malloc((size_t)m * sizeof(int));
    krylov->basis = malloc(((size_t)cap + 1) * (size_t)order * sizeof(cplx));
    krylov->hess = malloc(((size_t)cap + 1) * (size_t)cap * sizeof(cplx));
    krylov->small = malloc(square * sizeof(cplx));
    krylov->work = malloc(square * sizeof(cplx));
    krylov->lu = malloc(square * sizeof(cplx));
    krylov->ritz = malloc((size_t)cap * sizeof(cplx));
    krylov->z = malloc((size_t)cap * sizeof(cplx));
    krylov->multiplier = malloc((size_t)cap * sizeof(cplx));
    krylov->swapped = malloc((size_t)cap);
    krylov->rank = malloc((size_t)cap * sizeof(int));
    if (!krylov->q || !krylov->coupling || !krylov->pivots || !krylov->place || !krylov->basis || !krylov->hess ||
        !krylov->small || !krylov->work || !krylov->lu || !krylov->ritz || !krylov->z || !krylov->multiplier ||
        !krylov->swapped || !krylov->rank) {
        krylov_free(krylov);
        return -1;
    }
    for (int i = 0; i < m; i++) {
        krylov->place[rotor->order[i]] = i;
    }
    return 0;
}

/* y = (A - SHIFT B)^-1 B v (2 size each, blocks in the interleaved order) */
static void krylov_apply(const Rotor *rotor, const Krylov *krylov, const cplx *v, cplx *y)
{
    Band band = rotor->band;
    int m = rotor->size;
    double s = rotor->scale;
    const cplx *v1 = v, *v2 = v + m, *mass = rotor->banded[3];
    cplx *y1 = y, *y2 = y + m;
    for (int i = 0; i < m; i++) {
        y1[i] = cplx_real(0.0);
    }
    for (int j = 0; j < m; j++) { /* -s M2 v2 - (C2 + spin Gv + SHIFT M2) v1, column by column */
        int first = j - band.ku > 0 ? j - band.ku : 0, last = j + band.kl < m ? j + band.kl : m - 1;
        cplx a = cplx_scale(-s, v2[j]), b = v1[j];
        for (int i = first; i <= last; i++) {
            y1[i] = cplx_add(y1[i], cplx_sub(cplx_mul(AB(band, mass, i, j), a), cplx_mul(AB(band, krylov->coupling, i,
                                                                                            j), b)));
        }
    }
    band_substitute(band, krylov->q, krylov->pivots, y1);
    for (int i = 0; i < m; i++) {
        y2[i] = cplx_div_real(cplx_add(v1[i], cplx_scale(ROTOR_DAMPED_SHIFT, y1[i])), s);
    }
}

/* The Ritz values of the first ``steps`` vectors (into ritz, ranked by descending |nu|): 1 when the
 * ``wanted`` largest have converged, 0 when not yet, -1 when the small eigenproblem fails */
static int krylov_converged(Krylov *krylov, int steps, int order, int wanted)
{
    int cap = krylov->cap;
    for (int i = 0; i < steps; i++) {
        for (int j = 0; j < steps; j++) {
            krylov->small[(size_t)i * (size_t)steps + (size_t)j] = krylov->hess[(size_t)i * (size_t)cap + (size_t)j];
        }
    }
    memcpy(krylov->work, krylov->small, (size_t)steps * (size_t)steps * sizeof(cplx));
    if (hessenberg_eigenvalues(krylov->work, steps, krylov->ritz)) {
        return -1;
    }
    int *rank = krylov->rank;
    for (int i = 0; i < steps; i++) {
        rank[i] = i;
    }
    for (int k = 0; k < wanted; k++) { /* partial selection by descending |nu| */
        int best = k;
        for (int i = k + 1; i < steps; i++) {
            if (cplx_abs(krylov->ritz[rank[i]]) > cplx_abs(krylov->ritz[rank[best]])) {
                best = i;
            }
        }
        int t = rank[k];
        rank[k] = rank[best];
        rank[best] = t;
    }
    if (steps == order) { /* the whole space: the Ritz values are the eigenvalues */
        return 1;
    }
    double beta = cplx_abs(krylov->hess[(size_t)steps * (size_t)cap + (size_t)(steps - 1)]);
    double bound = RITZ_TOLERANCE * cplx_abs(krylov->ritz[rank[0]]);
    for (int k = 0; k < wanted; k++) { /* |h_{m+1,m} e_m^T z| with z a unit eigenvector of H */
        inverse_iteration(krylov->small, steps, krylov->ritz[rank[k]], krylov->lu, krylov->multiplier,
                          krylov->swapped, krylov->z);
        double norm = vector_norm(krylov->z, steps);
        if (!(beta * cplx_abs(krylov->z[steps - 1]) <= bound * norm)) {
            return 0;
        }
    }
    return 1;
}

/* The ``wanted`` eigenvalues lam nearest SHIFT at ``spin`` into ``lambda`` (ranked by descending
 * |nu|); afterwards ritz[rank[k]] is the Ritz value of lambda[k] and small the Hessenberg matrix.
 * ERROR_NONE, or ERROR_VALUE with the message (numpy's LinAlgError; no convergence in KRYLOV_CAP). */
static ErrorKind krylov_modes(const Rotor *rotor, Krylov *krylov, double spin, int wanted, cplx *lambda, char *error,
                              size_t size)
{
    int m = rotor->size, order = 2 * m, cap = krylov->cap;
    if (!isfinite(spin)) {
        ROTOR_ERROR(error, size, "Array must not contain infs or NaNs");
        return ERROR_VALUE;
    }
    size_t cells = (size_t)rotor->band.rows * (size_t)m;
    for (size_t i = 0; i < cells; i++) {
        krylov->coupling[i] = cplx_add(cplx_add(rotor->banded[1][i], cplx_scale(spin, rotor->banded[2][i])),
                                       cplx_scale(ROTOR_DAMPED_SHIFT, rotor->banded[3][i]));
        krylov->q[i] = cplx_add(rotor->banded[0][i], cplx_scale(ROTOR_DAMPED_SHIFT, krylov->coupling[i]));
    }
    if (band_factor(rotor->band, krylov->q, krylov->pivots)) {
        ROTOR_ERROR(error, size, "the damped model is singular at the Arnoldi shift");
        return ERROR_VALUE;
    }
    memset(krylov->hess, 0, ((size_t)cap + 1) * (size_t)cap * sizeof(cplx));
    unsigned long seed = 20240601UL;
    start_vector(krylov->basis, 0, order, &seed, krylov->basis);
    int steps = 0, next = wanted + 8, status = 0;
    while (status == 0) {
        cplx *w = krylov->basis + (size_t)(steps + 1) * (size_t)order;
        krylov_apply(rotor, krylov, krylov->basis + (size_t)steps * (size_t)order, w);
        double before = vector_norm(w, order);
        if (!isfinite(before)) {
            ROTOR_ERROR(error, size, "the Arnoldi iteration met infs or NaNs");
            return ERROR_VALUE;
        }
        orthogonalize(krylov->basis, steps + 1, order, w, krylov->hess + steps, cap);
        double beta = vector_norm(w, order);
        steps++;
        if (beta > 1e-12 * before) {
            krylov->hess[(size_t)steps * (size_t)cap + (size_t)(steps - 1)] = cplx_real(beta);
            for (int i = 0; i < order; i++) {
                w[i] = cplx_div_real(w[i], beta);
            }
        } else if (steps < order) { /* an invariant subspace: go on with a new direction */
            start_vector(krylov->basis, steps, order, &seed, w);
        }
        if (steps == order || steps == cap || steps >= next) {
            status = krylov_converged(krylov, steps, order, wanted < steps ? wanted : steps);
            if (status < 0) {
                ROTOR_ERROR(error, size, "Eigenvalues did not converge");
                return ERROR_VALUE;
            }
            if (status == 0 && steps == cap) {
                if (error && size) {
                    snprintf(error, size, "the damped modes did not converge in %d Arnoldi vectors", cap);
                }
                return ERROR_VALUE;
            }
            next = steps + (steps / 8 > 4 ? steps / 8 : 4);
        }
    }
    krylov->steps = steps;
    for (int k = 0; k < wanted; k++) {
        cplx inverse = cplx_div(cplx_real(1.0), krylov->ritz[krylov->rank[k]]);
        lambda[k] = cplx_make(ROTOR_DAMPED_SHIFT + inverse.re, inverse.im);
    }
    return ERROR_NONE;
}

/* The forward and backward sums sum |p_U|^2, sum |q_U|^2 of the Ritz vector of lambda[k] */
static void krylov_shares(const Rotor *rotor, Krylov *krylov, int k, double *forward, double *backward)
{
    int steps = krylov->steps, order = 2 * rotor->size;
    inverse_iteration(krylov->small, steps, krylov->ritz[krylov->rank[k]], krylov->lu, krylov->multiplier,
                      krylov->swapped, krylov->z);
    *forward = *backward = 0.0;
    for (int t = 0; t < rotor->n_translations; t++) { /* x = y1 = V z at the rows of p_U and q_U */
        int rows[2] = {krylov->place[rotor->translations[t]], krylov->place[rotor->n + rotor->translations[t]]};
        for (int half = 0; half < 2; half++) {
            cplx x = cplx_real(0.0);
            for (int j = 0; j < steps; j++) {
                x = cplx_add(x, cplx_mul(krylov->basis[(size_t)j * (size_t)order + (size_t)rows[half]], krylov->z[j]));
            }
            *(half ? backward : forward) += x.re * x.re + x.im * x.im;
        }
    }
}

/* The dense work of DampedRotor.modes: the blocks of B^-1 A without the spin (_dense_blocks) and
 * the eigen solver's arrays, for a 2 size first-order system. */
typedef struct {
    int size, order;                   /* size of x; order = 2 size of y = [x, x'/s] */
    cplx *stiffness, *damping, *gyro;  /* -M2^-1 K2 / s, -M2^-1 C2, -M2^-1 Gv */
    cplx *a, *h, *saved, *v, *multiplier, *lambda, *x;
    double *tau, *d;
    unsigned char *swapped;
    Mode *modes;
    int *index;
    Krylov krylov;                     /* above DENSE_SIZE (krylov.cap > 0): none of the dense arrays */
} Dense;

static void dense_free(Dense *dense)
{
    void *all[] = {dense->stiffness, dense->damping, dense->gyro, dense->a, dense->h, dense->saved, dense->v,
                   dense->multiplier, dense->lambda, dense->x, dense->tau, dense->d, dense->swapped, dense->modes,
                   dense->index};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; i++) {
        free(all[i]);
    }
    krylov_free(&dense->krylov);
    memset(dense, 0, sizeof *dense);
}

/* DampedRotor._dense_blocks and the eigen solver's arrays; ERROR_NONE, or ERROR_VALUE with the message
 * (a singular mass matrix: numpy's LinAlgError; out of memory) */
static ErrorKind dense_init(Dense *dense, const Rotor *rotor, char *error, size_t size)
{
    memset(dense, 0, sizeof *dense);
    int m = rotor->size, n = rotor->n, order = 2 * m;
    size_t block = (size_t)m * (size_t)m, full = (size_t)order * (size_t)order;
    dense->size = m;
    dense->order = order;
    if (order > ROTOR_DAMPED_DENSE_SIZE) { /* shift-invert Arnoldi: the banded matrices and O(order KRYLOV_CAP) work */
        int cap = order < KRYLOV_CAP ? order : KRYLOV_CAP;
        dense->lambda = malloc((size_t)cap * sizeof(cplx));
        dense->modes = malloc((size_t)cap * sizeof(Mode));
        dense->index = malloc((size_t)cap * sizeof(int));
        if (!dense->lambda || !dense->modes || !dense->index || krylov_init(&dense->krylov, rotor)) {
            dense_free(dense);
            ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
            return ERROR_VALUE;
        }
        return ERROR_NONE;
    }
    dense->stiffness = malloc(block * sizeof(cplx));
    dense->damping = malloc(block * sizeof(cplx));
    dense->gyro = malloc(block * sizeof(cplx));
    dense->a = malloc(full * sizeof(cplx));
    dense->h = malloc(full * sizeof(cplx));
    dense->saved = rotor->doubled ? malloc(full * sizeof(cplx)) : NULL;
    dense->v = malloc((size_t)order * sizeof(cplx));
    dense->multiplier = malloc((size_t)order * sizeof(cplx));
    dense->lambda = malloc((size_t)order * sizeof(cplx));
    dense->x = malloc((size_t)order * sizeof(cplx));
    dense->tau = malloc((size_t)order * sizeof(double));
    dense->d = malloc((size_t)order * sizeof(double));
    dense->swapped = malloc((size_t)order);
    dense->modes = malloc((size_t)order * sizeof(Mode));
    dense->index = malloc((size_t)order * sizeof(int));
    double *l = malloc((size_t)n * (size_t)n * sizeof *l + 1);
    int *pivots = malloc((size_t)n * sizeof *pivots + 1);
    if (!dense->stiffness || !dense->damping || !dense->gyro || !dense->a || !dense->h ||
        (rotor->doubled && !dense->saved) || !dense->v || !dense->multiplier || !dense->lambda || !dense->x ||
        !dense->tau || !dense->d || !dense->swapped || !dense->modes || !dense->index || !l || !pivots) {
        free(l);
        free(pivots);
        dense_free(dense);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    memcpy(l, rotor->fe.M, (size_t)n * (size_t)n * sizeof *l);
    if (lu_factor(l, n, pivots)) {
        free(l);
        free(pivots);
        dense_free(dense);
        ROTOR_ERROR(error, size, "Singular matrix");
        return ERROR_VALUE;
    }
    for (size_t i = 0; i < block; i++) {
        dense->stiffness[i] = cplx_div_real(rotor->K[i], rotor->scale);
        dense->damping[i] = rotor->C[i];
        dense->gyro[i] = rotor->G[i];
    }
    for (int half = 0; half < m / n; half++) { /* M2 = diag(M, M) */
        size_t first = (size_t)half * (size_t)n * (size_t)m;
        mass_solve(l, pivots, n, dense->stiffness + first, m, m);
        mass_solve(l, pivots, n, dense->damping + first, m, m);
        mass_solve(l, pivots, n, dense->gyro + first, m, m);
    }
    free(l);
    free(pivots);
    return ERROR_NONE;
}

/* All eigenvalues of the first-order system at ``spin`` (numpy.linalg.eig) into dense->lambda;
 * ERROR_NONE, or ERROR_VALUE with numpy's LinAlgError's message */
static ErrorKind dense_eigenvalues(const Rotor *rotor, Dense *dense, double spin, char *error, size_t size)
{
    int m = dense->size, order = dense->order;
    cplx *a = dense->a;
    /* [[0, s I], [-M2^-1 K2 / s, -M2^-1 (C2 + spin Gv)]] */
    for (int i = 0; i < order; i++) {
        for (int j = 0; j < order; j++) {
            size_t at = (size_t)i * (size_t)order + (size_t)j;
            if (i < m) {
                a[at] = cplx_real(j == m + i ? rotor->scale : 0.0);
            } else {
                size_t b = (size_t)(i - m) * (size_t)m + (size_t)(j < m ? j : j - m);
                a[at] = j < m ? dense->stiffness[b] : cplx_add(dense->damping[b], cplx_scale(spin, dense->gyro[b]));
            }
        }
    }
    for (size_t i = 0; i < (size_t)order * (size_t)order; i++) {
        if (!isfinite(a[i].re) || !isfinite(a[i].im)) { /* numpy.linalg's check */
            ROTOR_ERROR(error, size, "Array must not contain infs or NaNs");
            return ERROR_VALUE;
        }
    }
    balance(a, order, dense->d);
    hessenberg(a, order, dense->v, dense->x, dense->tau);
    hessenberg_part(a, order, dense->h);
    if (rotor->doubled) {
        memcpy(dense->saved, dense->h, (size_t)order * (size_t)order * sizeof(cplx));
    }
    if (hessenberg_eigenvalues(dense->h, order, dense->lambda)) {
        ROTOR_ERROR(error, size, "Eigenvalues did not converge");
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

/* DampedRotor.modes(spin, n): the first ``n`` damped modes into ``out`` (n), their number in *found;
 * ERROR_NONE, or the failure's kind with the message */
static ErrorKind rotor_modes(const Rotor *rotor, Dense *dense, double spin, int n, Mode *out, int *found, char *error,
                             size_t size)
{
    int order = dense->order, count, *index = dense->index;
    ErrorKind failed;
    if (dense->krylov.cap) { /* above DENSE_SIZE: the 2 n + EXTRA_EIGENVALUES nearest SHIFT by Arnoldi */
        count = 2 * n + ROTOR_DAMPED_EXTRA_EIGENVALUES;
        count = count < dense->krylov.cap ? count : dense->krylov.cap;
        if ((failed = krylov_modes(rotor, &dense->krylov, spin, count, dense->lambda, error, size)) != ERROR_NONE) {
            return failed;
        }
        for (int i = 0; i < count; i++) {
            index[i] = i;
        }
    } else if ((failed = dense_eigenvalues(rotor, dense, spin, error, size)) != ERROR_NONE) {
        return failed;
    } else {
        count = order;
        for (int i = 0; i < order; i++) {
            index[i] = i;
        }
    }
    if (rotor->conservative) { /* the eigensolver's real parts are round-off (DampedRotor.modes) */
        for (int k = 0; k < count; k++) {
            dense->lambda[index[k]] = cplx_make(0.0, (dense->lambda[index[k]]).im);
        }
    }
    double largest = 0.0;
    for (int k = 0; k < count; k++) {
        double size_k = cplx_abs(dense->lambda[index[k]]);
        largest = size_k > largest || isnan(size_k) ? size_k : largest;
    }
    /* whirling: not overdamped or static */
    int kept = 0;
    for (int k = 0; k < count; k++) {
        cplx value = dense->lambda[index[k]];
        if (!isfinite(value.re) || !isfinite(value.im) || !(fabs(value.im) > ROTOR_DAMPED_WHIRL_SHARE * largest)) {
            continue;
        }
        Mode *mode = &dense->modes[kept];
        mode->place = k;
        if (!rotor->doubled) { /* u = p exp(lam t): Im lam < 0 whirls backward */
            mode->eigenvalue = cplx_make(value.re, fabs(value.im));
            mode->forward_share = value.im > 0.0 ? 1.0 : 0.0;
            kept++;
        } else if (value.im > 0.0) { /* each mode also appears conjugated, at -w_d */
            mode->eigenvalue = value;
            mode->forward_share = 0.0; /* from its eigenvector below */
            kept++;
        }
    }
    qsort(dense->modes, (size_t)kept, sizeof(Mode), by_frequency);
    int take = kept < n ? kept : n;
    for (int k = 0; k < take; k++) {
        out[k] = dense->modes[k];
        if (rotor->doubled) { /* the forward share sum |p_U|^2 / sum (|p_U|^2 + |q_U|^2) of its eigenvector */
            double forward = 0.0, backward = 0.0;
            if (dense->krylov.cap) { /* its Ritz vector */
                krylov_shares(rotor, &dense->krylov, out[k].place, &forward, &backward);
            } else {
                inverse_iteration(dense->saved, order, out[k].eigenvalue, dense->h, dense->multiplier, dense->swapped,
                                  dense->x);
                back_transform(dense->a, order, dense->tau, dense->d, dense->x);
                for (int t = 0; t < rotor->n_translations; t++) {
                    cplx p = dense->x[rotor->translations[t]], q = dense->x[rotor->n + rotor->translations[t]];
                    forward += p.re * p.re + p.im * p.im;
                    backward += q.re * q.re + q.im * q.im;
                }
            }
            out[k].forward_share = forward / (forward + backward);
        }
    }
    *found = take;
    return ERROR_NONE;
}

/* ---- the mode table of unbalance_outputs.UnbalanceOutputs.build ------------------------------ */
/* The mode table of UnbalanceOutputs.build: DAMPING_POINTS rows of 2 DAMPED_MODES; ERROR_NONE, or the
 * failure's kind with the message */
ErrorKind mode_table(const Driveline *d, const int *counts, const double *spins, double *table, char *error,
                     size_t size)
{
    Rotor coarse;
    Dense dense;
    ErrorKind status = rotor_init(&coarse, d, counts, error, size);
    if (status != ERROR_NONE) {
        return status;
    }
    if ((status = dense_init(&dense, &coarse, error, size)) != ERROR_NONE) {
        rotor_free(&coarse);
        return status;
    }
    Mode modes[4 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES];
    for (int i = 0; i < ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS && !status; i++) {
        int found = 0, excited = 0;
        status = rotor_modes(&coarse, &dense, spins[i], 4 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES, modes, &found,
                             error, size);
        double *out = table + (size_t)i * 2 * ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES;
        for (int k = 0; k < found && excited < ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES && !status; k++) {
            if (modes[k].forward_share >= ROTOR_DRIVELINE_EXCITED_SHARE) {
                cplx value = modes[k].eigenvalue;
                out[excited] = value.im;
                out[ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES + excited] = -value.re / cplx_abs(value);
                excited++;
            }
        }
        /* a short model: beyond the search limit, undamped */
        for (; excited < ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES; excited++) {
            out[excited] = ROTOR_DRIVELINE_SEARCH_LIMIT;
            out[ROTOR_UNBALANCE_OUTPUTS_DAMPED_MODES + excited] = 0.0;
        }
    }
    dense_free(&dense);
    rotor_free(&coarse);
    return status;
}
