/* Damped finite-element model of a driveline (damped.DampedRotor) and what the FMU reports of it
 * (unbalance_outputs.UnbalanceOutputs): damped modes from a dense complex eigensolver up to DENSE_SIZE
 * first-order unknowns and by shift-invert Arnoldi on a banded factorisation above, the synchronous
 * unbalance response from a banded complex LU solve. */
#include "rotor.h"

#include "cplx.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


#define OUT_OF_MEMORY "out of memory"
/* damped.py */
#define EXTRA_EIGENVALUES 6
#define DENSE_SIZE 160
#define SHIFT (-1.0)
/* unbalance_outputs.py */
#define FE_ELEMENTS 16
#define TABLE_ELEMENTS 8
#define DAMPING_POINTS 11
#define DAMPED_MODES 4

static void set_error(char *error, size_t size, const char *message)
{
    if (error && size) {
        snprintf(error, size, "%s", message);
    }
}

/* 1 / d without overflow or a library call (Smith's division; LAPACK's gbtf2 scales a column by the
 * pivot's reciprocal too) */
static cplx reciprocal(cplx d)
{
    double re = d.re, im = d.im;
    if (fabs(re) >= fabs(im)) {
        double ratio = im / re, denominator = re + im * ratio;
        return cplx_make(1.0 / denominator, -ratio / denominator);
    }
    double ratio = re / im, denominator = re * ratio + im;
    return cplx_make(ratio / denominator, -1.0 / denominator);
}

/* ---- the dense complex eigenproblem (numpy.linalg.eig) ------------------------------------- */
/* Balancing by powers of two: a[i][j] -> a[i][j] d[j] / d[i] with row and column norms brought
 * together, as LAPACK's gebal does before the QR iteration. */
static void balance(cplx *a, int n, double *d)
{
    for (int i = 0; i < n; i++) {
        d[i] = 1.0;
    }
    for (int sweep = 0, changed = 1; changed && sweep < 100; sweep++) {
        changed = 0;
        for (int i = 0; i < n; i++) {
            double c = 0.0, r = 0.0;
            for (int j = 0; j < n; j++) {
                if (j != i) {
                    cplx column = a[(size_t)j * (size_t)n + (size_t)i], row = a[(size_t)i * (size_t)n + (size_t)j];
                    c += column.re * column.re + column.im * column.im;
                    r += row.re * row.re + row.im * row.im;
                }
            }
            c = sqrt(c);
            r = sqrt(r);
            if (c == 0.0 || r == 0.0 || !isfinite(c) || !isfinite(r)) {
                continue;
            }
            /* f = 2^k nearest sqrt(r / c): the column times f, the row over f */
            int exponent;
            frexp(sqrt(r / c), &exponent);
            double f = ldexp(1.0, exponent - 1);
            if (sqrt(r / c) / f > 1.4142135623730951) {
                f *= 2.0;
            }
            if (f == 1.0 || c * f + r / f >= 0.95 * (c + r)) {
                continue;
            }
            changed = 1;
            d[i] *= f;
            for (int j = 0; j < n; j++) {
                a[(size_t)j * (size_t)n + (size_t)i] = cplx_scale(f, a[(size_t)j * (size_t)n + (size_t)i]);
                a[(size_t)i * (size_t)n + (size_t)j] = cplx_div_real(a[(size_t)i * (size_t)n + (size_t)j], f);
            }
        }
    }
}

/* Householder reduction to upper Hessenberg form, A = Q H Q^*; the reflector of column k is
 * I - tau_k v v^* with v = (1, a[k+2..][k]) over rows k+1.. (kept for the eigenvectors); v and w
 * are n long. */
static void hessenberg(cplx *a, int n, cplx *v, cplx *w, double *tau)
{
    for (int k = 0; k + 2 < n; k++) {
        int m = n - k - 1;
        double norm2 = 0.0;
        for (int i = 0; i < m; i++) {
            cplx x = a[(size_t)(k + 1 + i) * (size_t)n + (size_t)k];
            v[i] = x;
            norm2 += x.re * x.re + x.im * x.im;
        }
        double below = norm2 - (v[0].re * v[0].re + v[0].im * v[0].im);
        if (below == 0.0) {
            tau[k] = 0.0;
            continue;
        }
        double norm = sqrt(norm2), first = cplx_abs(v[0]);
        cplx phase = first == 0.0 ? cplx_real(1.0) : cplx_div_real(v[0], first);
        cplx alpha = cplx_scale(norm, cplx_neg(phase));
        v[0] = cplx_sub(v[0], alpha);
        double vv = 0.0;
        for (int i = 0; i < m; i++) {
            vv += v[i].re * v[i].re + v[i].im * v[i].im;
        }
        double t = 2.0 / vv;
        /* left: rows k+1.., columns k.., through w = t v^* A row by row */
        for (int j = k; j < n; j++) {
            w[j] = cplx_real(0.0);
        }
        for (int i = 0; i < m; i++) {
            const cplx *row = a + (size_t)(k + 1 + i) * (size_t)n;
            for (int j = k; j < n; j++) {
                w[j] = cplx_add(w[j], cplx_mul_conj(v[i], row[j]));
            }
        }
        for (int j = k; j < n; j++) {
            w[j] = cplx_scale(t, w[j]);
        }
        for (int i = 0; i < m; i++) {
            cplx *row = a + (size_t)(k + 1 + i) * (size_t)n;
            for (int j = k; j < n; j++) {
                row[j] = cplx_sub(row[j], cplx_mul(v[i], w[j]));
            }
        }
        /* right: all rows, columns k+1.. */
        for (int i = 0; i < n; i++) {
            cplx *row = a + (size_t)i * (size_t)n + (size_t)(k + 1);
            cplx sum = cplx_real(0.0);
            for (int j = 0; j < m; j++) {
                sum = cplx_add(sum, cplx_mul(row[j], v[j]));
            }
            sum = cplx_scale(t, sum);
            for (int j = 0; j < m; j++) {
                row[j] = cplx_sub(row[j], cplx_mul_conj(v[j], sum));
            }
        }
        /* the column below the subdiagonal is zero now: keep v there, scaled to v[0] = 1 (see
         * hessenberg_part) */
        a[(size_t)(k + 1) * (size_t)n + (size_t)k] = alpha;
        for (int i = 1; i < m; i++) {
            a[(size_t)(k + 1 + i) * (size_t)n + (size_t)k] = cplx_div(v[i], v[0]);
        }
        tau[k] = t * (v[0].re * v[0].re + v[0].im * v[0].im);
    }
}

/* The eigenvalues of the upper Hessenberg ``h`` (destroyed): implicitly single-shifted complex QR
 * with Wilkinson shifts, exceptional shifts after 10 and 20 steps on one eigenvalue, deflation of
 * negligible subdiagonal entries; -1 after 30 max(10, n) steps in all. */
static int hessenberg_eigenvalues(cplx *h, int n, cplx *lambda)
{
#define H(i, j) h[(size_t)(i) * (size_t)n + (size_t)(j)]
    int hi = n - 1, steps = 0, cap = 30 * (n > 10 ? n : 10), its = 0;
    while (hi >= 0) {
        int lo = hi;
        while (lo > 0) {
            if (cplx_is_zero(H(lo, lo - 1))) {
                break;
            }
            /* negligible against its diagonal neighbours, and (Ahues and Tisseur) the deflation
             * perturbs the eigenvalues of the 2 x 2 around it no more than rounding does */
            double near = cplx_abs1(H(lo - 1, lo - 1)) + cplx_abs1(H(lo, lo)), sub = cplx_abs1(H(lo, lo - 1));
            if (sub <= DBL_EPSILON * near) {
                double super = cplx_abs1(H(lo - 1, lo)), ab = fmax(sub, super), ba = fmin(sub, super);
                double d1 = cplx_abs1(H(lo, lo)), d2 = cplx_abs1(cplx_sub(H(lo - 1, lo - 1), H(lo, lo)));
                double aa = fmax(d1, d2), bb = fmin(d1, d2), s = aa + ab;
                if (ba * (ab / s) <= fmax(DBL_MIN, DBL_EPSILON * (bb * (aa / s)))) {
                    H(lo, lo - 1) = cplx_real(0.0);
                    break;
                }
            }
            lo--;
        }
        if (lo == hi) {
            lambda[hi] = H(hi, hi);
            hi--;
            its = 0;
            continue;
        }
        if (++steps > cap) {
            return -1;
        }
        its++;
        cplx mu;
        if (its == 10 || its == 20) {
            mu = cplx_make(H(hi, hi).re + 0.75 * cplx_abs1(H(hi, hi - 1)), H(hi, hi).im);
        } else { /* the eigenvalue of the trailing 2 x 2 nearer its last diagonal entry */
            cplx a = H(hi - 1, hi - 1), b = H(hi - 1, hi), c = H(hi, hi - 1), d = H(hi, hi);
            cplx p = cplx_scale(0.5, cplx_sub(a, d)), bc = cplx_mul(b, c), root = cplx_sqrt(cplx_add(cplx_mul(p, p), bc));
            cplx plus = cplx_add(p, root), minus = cplx_sub(p, root), den = cplx_abs(plus) >= cplx_abs(minus) ? plus : minus;
            mu = cplx_is_zero(den) ? d : cplx_sub(d, cplx_div(bc, den));
        }
        cplx x = cplx_sub(H(lo, lo), mu), y = H(lo + 1, lo);
        for (int k = lo; k < hi; k++) {
            if (k > lo) {
                x = H(k, k - 1);
                y = H(k + 1, k - 1);
            }
            double ax = cplx_abs(x), norm = hypot(ax, cplx_abs(y));
            if (norm == 0.0) {
                continue;
            }
            double c = ax / norm;
            cplx s = cplx_div_real(cplx_mul(ax == 0.0 ? cplx_real(1.0) : cplx_div_real(x, ax), cplx_conj(y)), norm);
            if (ax == 0.0) {
                s = cplx_div_real(cplx_conj(y), norm);
            }
            int first = k > lo ? k - 1 : lo;
            for (int j = first; j <= hi; j++) {
                cplx top = H(k, j), bottom = H(k + 1, j);
                H(k, j) = cplx_add(cplx_scale(c, top), cplx_mul(s, bottom));
                H(k + 1, j) = cplx_sub(cplx_scale(c, bottom), cplx_mul_conj(s, top));
            }
            if (k > lo) {
                H(k + 1, k - 1) = cplx_real(0.0);
            }
            int last = k + 2 < hi ? k + 2 : hi;
            for (int i = lo; i <= last; i++) {
                cplx left = H(i, k), right = H(i, k + 1);
                H(i, k) = cplx_add(cplx_scale(c, left), cplx_mul_conj(s, right));
                H(i, k + 1) = cplx_sub(cplx_scale(c, right), cplx_mul(left, s));
            }
        }
    }
    return 0;
#undef H
}

/* An eigenvector of the Hessenberg ``h`` for ``lambda`` by inverse iteration, into ``x`` (n):
 * the LU of h - lambda I with row interchanges between neighbours (``lu`` n x n, ``multiplier`` and
 * ``swapped`` n), a first solve U x = ones (any right-hand side will do) and a second full solve. */
static void inverse_iteration(const cplx *h, int n, cplx lambda, cplx *lu, cplx *multiplier, unsigned char *swapped,
                              cplx *x)
{
    double norm = 0.0;
    for (size_t i = 0; i < (size_t)n * (size_t)n; i++) {
        norm = fmax(norm, cplx_abs1(h[i]));
    }
    double tiny = DBL_EPSILON * (norm > 0.0 ? norm : 1.0);
    memcpy(lu, h, (size_t)n * (size_t)n * sizeof *lu);
    for (int i = 0; i < n; i++) {
        lu[(size_t)i * (size_t)n + (size_t)i] = cplx_sub(lu[(size_t)i * (size_t)n + (size_t)i], lambda);
    }
    for (int k = 0; k + 1 < n; k++) {
        cplx *row = lu + (size_t)k * (size_t)n, *next = row + n;
        swapped[k] = cplx_abs1(next[k]) > cplx_abs1(row[k]);
        if (swapped[k]) {
            for (int j = k; j < n; j++) {
                cplx t = row[j];
                row[j] = next[j];
                next[j] = t;
            }
        }
        if (cplx_is_zero(row[k])) { /* exactly singular: perturb the pivot by the rounding level */
            row[k] = cplx_real(tiny);
        }
        multiplier[k] = cplx_div(next[k], row[k]);
        for (int j = k + 1; j < n; j++) {
            next[j] = cplx_sub(next[j], cplx_mul(multiplier[k], row[j]));
        }
        next[k] = cplx_real(0.0);
    }
    if (cplx_is_zero(lu[(size_t)n * (size_t)n - 1])) {
        lu[(size_t)n * (size_t)n - 1] = cplx_real(tiny);
    }
    for (int i = 0; i < n; i++) {
        x[i] = cplx_real(1.0);
    }
    for (int pass = 0; pass < 2; pass++) {
        if (pass) { /* L^-1 P */
            for (int k = 0; k + 1 < n; k++) {
                if (swapped[k]) {
                    cplx t = x[k];
                    x[k] = x[k + 1];
                    x[k + 1] = t;
                }
                x[k + 1] = cplx_sub(x[k + 1], cplx_mul(multiplier[k], x[k]));
            }
        }
        for (int i = n - 1; i >= 0; i--) {
            const cplx *row = lu + (size_t)i * (size_t)n;
            cplx sum = x[i];
            for (int j = i + 1; j < n; j++) {
                sum = cplx_sub(sum, cplx_mul(row[j], x[j]));
            }
            x[i] = cplx_div(sum, row[i]);
        }
        double largest = 0.0;
        for (int i = 0; i < n; i++) {
            largest = fmax(largest, cplx_abs1(x[i]));
        }
        for (int i = 0; i < n && largest > 0.0 && isfinite(largest); i++) {
            x[i] = cplx_div_real(x[i], largest);
        }
    }
}

/* The Hessenberg matrix of hessenberg()'s ``a`` without the reflectors below its subdiagonal */
static void hessenberg_part(const cplx *a, int n, cplx *h)
{
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            h[(size_t)i * (size_t)n + (size_t)j] = j + 1 >= i ? a[(size_t)i * (size_t)n + (size_t)j] : cplx_real(0.0);
        }
    }
}

/* x <- D Q x: an eigenvector of the Hessenberg matrix back to the balanced, then the original one */
static void back_transform(const cplx *a, int n, const double *tau, const double *d, cplx *x)
{
    for (int k = n - 3; k >= 0; k--) {
        if (tau[k] == 0.0) {
            continue;
        }
        cplx sum = x[k + 1];
        for (int i = k + 2; i < n; i++) {
            sum = cplx_add(sum, cplx_mul_conj(a[(size_t)i * (size_t)n + (size_t)k], x[i]));
        }
        sum = cplx_scale(tau[k], sum);
        x[k + 1] = cplx_sub(x[k + 1], sum);
        for (int i = k + 2; i < n; i++) {
            x[i] = cplx_sub(x[i], cplx_mul(a[(size_t)i * (size_t)n + (size_t)k], sum));
        }
    }
    for (int i = 0; i < n; i++) {
        x[i] = cplx_scale(d[i], x[i]);
    }
}

/* ---- the banded complex LU solve (LAPACK gbsv's storage: (i, j) at ab[j][kl + ku + i - j]) ---- */
typedef struct {
    int n, kl, ku, rows; /* rows = 2 kl + ku + 1 per column */
} Band;

#define AB(band, ab, i, j) (ab)[(size_t)(j) * (size_t)(band).rows + (size_t)((band).kl + (band).ku + (i) - (j))]

/* LU factors of ab in place with partial pivoting (``pivots`` n, the row swapped with each row as
 * it is eliminated); -1 on an exactly zero pivot (singular) */
static int band_factor(Band band, cplx *ab, int *pivots)
{
    int n = band.n, kl = band.kl, ju = 0; /* ju: the last column U reaches so far (LAPACK's gbtf2) */
    for (int j = 0; j < n; j++) {
        int last = j + kl < n ? j + kl : n - 1, pivot = j;
        double best = cplx_abs1(AB(band, ab, j, j));
        for (int i = j + 1; i <= last; i++) {
            double size = cplx_abs1(AB(band, ab, i, j));
            if (size > best) {
                best = size;
                pivot = i;
            }
        }
        pivots[j] = pivot;
        if (cplx_is_zero(AB(band, ab, pivot, j))) {
            return -1;
        }
        int reach = pivot + band.ku < n ? pivot + band.ku : n - 1, end;
        ju = reach > ju ? reach : ju;
        end = ju;
        if (pivot != j) {
            for (int c = j; c <= end; c++) {
                cplx t = AB(band, ab, j, c);
                AB(band, ab, j, c) = AB(band, ab, pivot, c);
                AB(band, ab, pivot, c) = t;
            }
        }
        cplx inverse = reciprocal(AB(band, ab, j, j));
        for (int i = j + 1; i <= last; i++) {
            cplx factor = cplx_mul(AB(band, ab, i, j), inverse);
            AB(band, ab, i, j) = factor;
            if (cplx_is_zero(factor)) {
                continue;
            }
            for (int c = j + 1; c <= end; c++) {
                AB(band, ab, i, c) = cplx_sub(AB(band, ab, i, c), cplx_mul(factor, AB(band, ab, j, c)));
            }
        }
    }
    return 0;
}

/* b <- ab^-1 b in place, ab factorised by band_factor */
static void band_substitute(Band band, const cplx *ab, const int *pivots, cplx *b)
{
    int n = band.n, kl = band.kl, width = kl + band.ku;
    for (int j = 0; j < n; j++) {
        int last = j + kl < n ? j + kl : n - 1;
        if (pivots[j] != j) {
            cplx t = b[j];
            b[j] = b[pivots[j]];
            b[pivots[j]] = t;
        }
        for (int i = j + 1; i <= last; i++) {
            cplx factor = AB(band, ab, i, j);
            if (!cplx_is_zero(factor)) {
                b[i] = cplx_sub(b[i], cplx_mul(factor, b[j]));
            }
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        int end = i + width < n ? i + width : n - 1;
        cplx sum = b[i];
        for (int c = i + 1; c <= end; c++) {
            cplx u = AB(band, ab, i, c);
            if (!cplx_is_zero(u)) { /* beyond the columns pivoting reached, U is zero */
                sum = cplx_sub(sum, cplx_mul(u, b[c]));
            }
        }
        b[i] = cplx_mul(sum, reciprocal(AB(band, ab, i, i)));
    }
}

/* Solves ab x = b in place (ab factorised, ``pivots`` n); -1 on an exactly zero pivot (singular) */
static int band_solve(Band band, cplx *ab, int *pivots, cplx *b)
{
    if (band_factor(band, ab, pivots)) {
        return -1;
    }
    band_substitute(band, ab, pivots, b);
    return 0;
}

/* ---- damped.DampedRotor ---------------------------------------------------------------------- */
typedef struct {
    FeModel fe;                /* fem.assemble_damped's mesh and real K, M, G (bearings left out) */
    int n, doubled, size;      /* p unknowns; [p, q] when doubled; size = n or 2 n */
    int conservative;          /* no damping, symmetric bearing stiffness: imaginary eigenvalues */
    cplx *K, *C, *G;           /* K2, C2, Gv (size x size); NULL once the rotor only solves */
    Band band;                 /* the interleaved order [p0, q0, p1, q1, ...] */
    cplx *banded[4];           /* k, c, g, m in band storage */
    int *order;                /* size: the unknown at each row of the interleaved order */
    int n_translations, *translations;
    int n_bearings, *bearing_rows; /* per bearing, -1 on a pinned or clamped end */
    cplx *coefficients;        /* per bearing: k_a, k_b, c_a, c_b */
    double scale;              /* DampedRotor._scale */
} Rotor;

static void rotor_free(Rotor *rotor)
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

/* DampedRotor.__init__ (with fem.assemble_damped) */
static int rotor_init(Rotor *rotor, const Driveline *d, const int *counts, char *error, size_t size)
{
    memset(rotor, 0, sizeof *rotor);
    if (fe_model_build(d, counts, 0, &rotor->fe, error, size)) {
        return -1;
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
    return 0;
out_of_memory:
    free(Ka);
    free(Kb);
    free(Ca);
    free(Cb);
    rotor_free(rotor);
    set_error(error, size, OUT_OF_MEMORY);
    return -1;
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
            y1[i] = cplx_add(y1[i], cplx_sub(cplx_mul(AB(band, mass, i, j), a), cplx_mul(AB(band, krylov->coupling, i, j), b)));
        }
    }
    band_substitute(band, krylov->q, krylov->pivots, y1);
    for (int i = 0; i < m; i++) {
        y2[i] = cplx_div_real(cplx_add(v1[i], cplx_scale(SHIFT, y1[i])), s);
    }
}

static double vector_norm(const cplx *x, int n)
{
    double scale = 0.0;
    for (int i = 0; i < n; i++) {
        scale = fmax(scale, cplx_abs1(x[i]));
    }
    if (!(scale > 0.0) || !isfinite(scale)) {
        return scale;
    }
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        double re = x[i].re / scale, im = x[i].im / scale;
        sum += re * re + im * im;
    }
    return scale * sqrt(sum);
}

/* w minus its projection on the first ``count`` basis vectors, twice (classical Gram-Schmidt with one
 * reorthogonalisation); the coefficients added to ``column`` (stride ``stride``) unless it is NULL */
static void orthogonalize(const cplx *basis, int count, int order, cplx *w, cplx *column, int stride)
{
    for (int pass = 0; pass < 2; pass++) {
        for (int j = 0; j < count; j++) {
            const cplx *v = basis + (size_t)j * (size_t)order;
            cplx c = cplx_real(0.0);
            for (int i = 0; i < order; i++) {
                c = cplx_add(c, cplx_mul_conj(v[i], w[i]));
            }
            for (int i = 0; i < order; i++) {
                w[i] = cplx_sub(w[i], cplx_mul(c, v[i]));
            }
            if (column) {
                column[(size_t)j * (size_t)stride] = cplx_add(column[(size_t)j * (size_t)stride], c);
            }
        }
    }
}

/* A unit start vector, orthogonal to the first ``count`` basis vectors, from a fixed pseudo-random sequence */
static void start_vector(const cplx *basis, int count, int order, unsigned long *seed, cplx *w)
{
    for (int attempt = 0; attempt < 3; attempt++) {
        for (int i = 0; i < order; i++) {
            double part[2];
            for (int k = 0; k < 2; k++) { /* a 32-bit linear congruential sequence */
                *seed = (*seed * 1664525UL + 1013904223UL) & 0xffffffffUL;
                part[k] = (double)*seed / 4294967296.0 - 0.5;
            }
            w[i] = cplx_make(part[0], part[1]);
        }
        orthogonalize(basis, count, order, w, NULL, 0);
        double norm = vector_norm(w, order);
        if (norm > 0.0) {
            for (int i = 0; i < order; i++) {
                w[i] = cplx_div_real(w[i], norm);
            }
            return;
        }
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
 * |nu|); afterwards ritz[rank[k]] is the Ritz value of lambda[k] and small the Hessenberg matrix */
static int krylov_modes(const Rotor *rotor, Krylov *krylov, double spin, int wanted, cplx *lambda, char *error,
                        size_t size)
{
    int m = rotor->size, order = 2 * m, cap = krylov->cap;
    if (!isfinite(spin)) {
        set_error(error, size, "Array must not contain infs or NaNs");
        return -1;
    }
    size_t cells = (size_t)rotor->band.rows * (size_t)m;
    for (size_t i = 0; i < cells; i++) {
        krylov->coupling[i] = cplx_add(cplx_add(rotor->banded[1][i], cplx_scale(spin, rotor->banded[2][i])),
                                       cplx_scale(SHIFT, rotor->banded[3][i]));
        krylov->q[i] = cplx_add(rotor->banded[0][i], cplx_scale(SHIFT, krylov->coupling[i]));
    }
    if (band_factor(rotor->band, krylov->q, krylov->pivots)) {
        set_error(error, size, "the damped model is singular at the Arnoldi shift");
        return -1;
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
            set_error(error, size, "the Arnoldi iteration met infs or NaNs");
            return -1;
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
                set_error(error, size, "Eigenvalues did not converge");
                return -1;
            }
            if (status == 0 && steps == cap) {
                if (error && size) {
                    snprintf(error, size, "the damped modes did not converge in %d Arnoldi vectors", cap);
                }
                return -1;
            }
            next = steps + (steps / 8 > 4 ? steps / 8 : 4);
        }
    }
    krylov->steps = steps;
    for (int k = 0; k < wanted; k++) {
        cplx inverse = cplx_div(cplx_real(1.0), krylov->ritz[krylov->rank[k]]);
        lambda[k] = cplx_make(SHIFT + inverse.re, inverse.im);
    }
    return 0;
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

/* LU factors with partial pivoting of the real ``m`` (numpy.linalg.solve); -1 if it is singular */
static int lu_factor(double *m, int n, int *pivots)
{
    for (int j = 0; j < n; j++) {
        int pivot = j;
        for (int i = j + 1; i < n; i++) {
            if (fabs(m[(size_t)i * (size_t)n + (size_t)j]) > fabs(m[(size_t)pivot * (size_t)n + (size_t)j])) {
                pivot = i;
            }
        }
        pivots[j] = pivot;
        if (m[(size_t)pivot * (size_t)n + (size_t)j] == 0.0) {
            return -1;
        }
        if (pivot != j) {
            for (int c = 0; c < n; c++) {
                double t = m[(size_t)j * (size_t)n + (size_t)c];
                m[(size_t)j * (size_t)n + (size_t)c] = m[(size_t)pivot * (size_t)n + (size_t)c];
                m[(size_t)pivot * (size_t)n + (size_t)c] = t;
            }
        }
        const double *row_j = m + (size_t)j * (size_t)n;
        for (int i = j + 1; i < n; i++) {
            double *row_i = m + (size_t)i * (size_t)n;
            double factor = row_i[j] / row_j[j];
            row_i[j] = factor;
            if (factor != 0.0) {
                for (int c = j + 1; c < n; c++) {
                    row_i[c] -= factor * row_j[c];
                }
            }
        }
    }
    return 0;
}

/* x <- -M^-1 x for the n rows of x (``columns`` wide, ``stride`` apart), M by its LU factors */
static void mass_solve(const double *lu, const int *pivots, int n, cplx *x, int columns, int stride)
{
    for (int c = 0; c < columns; c++) {
        for (int i = 0; i < n; i++) {
            if (pivots[i] != i) {
                cplx t = x[(size_t)i * (size_t)stride + (size_t)c];
                x[(size_t)i * (size_t)stride + (size_t)c] = x[(size_t)pivots[i] * (size_t)stride + (size_t)c];
                x[(size_t)pivots[i] * (size_t)stride + (size_t)c] = t;
            }
        }
        for (int i = 0; i < n; i++) {
            cplx sum = x[(size_t)i * (size_t)stride + (size_t)c];
            for (int k = 0; k < i; k++) {
                sum = cplx_sub(sum, cplx_scale(lu[(size_t)i * (size_t)n + (size_t)k], x[(size_t)k * (size_t)stride + (size_t)c]));
            }
            x[(size_t)i * (size_t)stride + (size_t)c] = sum;
        }
        for (int i = n - 1; i >= 0; i--) {
            cplx sum = x[(size_t)i * (size_t)stride + (size_t)c];
            for (int k = i + 1; k < n; k++) {
                sum = cplx_sub(sum, cplx_scale(lu[(size_t)i * (size_t)n + (size_t)k], x[(size_t)k * (size_t)stride + (size_t)c]));
            }
            x[(size_t)i * (size_t)stride + (size_t)c] = cplx_div_real(sum, lu[(size_t)i * (size_t)n + (size_t)i]);
        }
        for (int i = 0; i < n; i++) {
            x[(size_t)i * (size_t)stride + (size_t)c] = cplx_neg(x[(size_t)i * (size_t)stride + (size_t)c]);
        }
    }
}

/* DampedRotor._dense_blocks and the eigen solver's arrays */
static int dense_init(Dense *dense, const Rotor *rotor, char *error, size_t size)
{
    memset(dense, 0, sizeof *dense);
    int m = rotor->size, n = rotor->n, order = 2 * m;
    size_t block = (size_t)m * (size_t)m, full = (size_t)order * (size_t)order;
    dense->size = m;
    dense->order = order;
    if (order > DENSE_SIZE) { /* shift-invert Arnoldi: the banded matrices and O(order KRYLOV_CAP) work */
        int cap = order < KRYLOV_CAP ? order : KRYLOV_CAP;
        dense->lambda = malloc((size_t)cap * sizeof(cplx));
        dense->modes = malloc((size_t)cap * sizeof(Mode));
        dense->index = malloc((size_t)cap * sizeof(int));
        if (!dense->lambda || !dense->modes || !dense->index || krylov_init(&dense->krylov, rotor)) {
            dense_free(dense);
            set_error(error, size, OUT_OF_MEMORY);
            return -1;
        }
        return 0;
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
        set_error(error, size, OUT_OF_MEMORY);
        return -1;
    }
    memcpy(l, rotor->fe.M, (size_t)n * (size_t)n * sizeof *l);
    if (lu_factor(l, n, pivots)) {
        free(l);
        free(pivots);
        dense_free(dense);
        set_error(error, size, "Singular matrix");
        return -1;
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
    return 0;
}

/* All eigenvalues of the first-order system at ``spin`` (numpy.linalg.eig) into dense->lambda */
static int dense_eigenvalues(const Rotor *rotor, Dense *dense, double spin, char *error, size_t size)
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
            set_error(error, size, "Array must not contain infs or NaNs");
            return -1;
        }
    }
    balance(a, order, dense->d);
    hessenberg(a, order, dense->v, dense->x, dense->tau);
    hessenberg_part(a, order, dense->h);
    if (rotor->doubled) {
        memcpy(dense->saved, dense->h, (size_t)order * (size_t)order * sizeof(cplx));
    }
    if (hessenberg_eigenvalues(dense->h, order, dense->lambda)) {
        set_error(error, size, "Eigenvalues did not converge");
        return -1;
    }
    return 0;
}

/* DampedRotor.modes(spin, n): the first ``n`` damped modes into ``out`` (n), their number in *found */
static int rotor_modes(const Rotor *rotor, Dense *dense, double spin, int n, Mode *out, int *found, char *error,
                       size_t size)
{
    int order = dense->order, count, *index = dense->index;
    if (dense->krylov.cap) { /* above DENSE_SIZE: the 2 n + EXTRA_EIGENVALUES nearest SHIFT by Arnoldi */
        count = 2 * n + EXTRA_EIGENVALUES < dense->krylov.cap ? 2 * n + EXTRA_EIGENVALUES : dense->krylov.cap;
        if (krylov_modes(rotor, &dense->krylov, spin, count, dense->lambda, error, size)) {
            return -1;
        }
        for (int i = 0; i < count; i++) {
            index[i] = i;
        }
    } else if (dense_eigenvalues(rotor, dense, spin, error, size)) {
        return -1;
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
        if (!isfinite(value.re) || !isfinite(value.im) || !(fabs(value.im) > 1e-9 * largest)) {
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
    return 0;
}

/* ---- unbalance_outputs.UnbalanceOutputs ------------------------------------------------------ */
struct UnbalanceOutputs {
    Rotor rotor;        /* the response model (FE_ELEMENTS), its band matrices only */
    cplx *load;         /* DampedRotor.load per unit Omega^2, rotor.size */
    cplx *row;          /* DampedRotor.shape_rows at the response position, rotor.n */
    CubicSpline modes;  /* DAMPED_MODES damped frequencies, then their damping ratios */
    cplx *ab, *x;       /* evaluate's work: one object is evaluated by one caller at a time */
    int *pivots;
};

/* DampedRotor.shape_rows for one position: ``row`` (rotor.n) */
static int shape_row(const Rotor *rotor, double z, double length, cplx *row, char *error, size_t size)
{
    const FeModel *fe = &rotor->fe;
    if (!isfinite(z) || z < 0.0 || z > length * (1 + 1e-12)) {
        char shown[40], at[40];
        python_float_repr(length, shown, sizeof shown);
        python_float_repr(z, at, sizeof at);
        if (error && size) {
            snprintf(error, size, "positions must lie on the shaft, 0 to %s m, got [%s]", shown, at);
        }
        return -1;
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
    return 0;
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
    free(outputs->pivots);
    free(outputs);
}

/* The mode table of UnbalanceOutputs.build: DAMPING_POINTS rows of 2 DAMPED_MODES */
static int mode_table(const Driveline *d, const int *counts, const double *spins, double *table, char *error,
                      size_t size)
{
    Rotor coarse;
    Dense dense;
    if (rotor_init(&coarse, d, counts, error, size)) {
        return -1;
    }
    if (dense_init(&dense, &coarse, error, size)) {
        rotor_free(&coarse);
        return -1;
    }
    int status = 0;
    Mode modes[4 * DAMPED_MODES];
    for (int i = 0; i < DAMPING_POINTS && !status; i++) {
        int found = 0, excited = 0;
        status = rotor_modes(&coarse, &dense, spins[i], 4 * DAMPED_MODES, modes, &found, error, size);
        double *out = table + (size_t)i * 2 * DAMPED_MODES;
        for (int k = 0; k < found && excited < DAMPED_MODES && !status; k++) {
            if (modes[k].forward_share >= ROTOR_EXCITED_SHARE) {
                cplx value = modes[k].eigenvalue;
                out[excited] = value.im;
                out[DAMPED_MODES + excited] = -value.re / cplx_abs(value);
                excited++;
            }
        }
        for (; excited < DAMPED_MODES; excited++) { /* a short model: beyond the search limit, undamped */
            out[excited] = ROTOR_SEARCH_LIMIT;
            out[DAMPED_MODES + excited] = 0.0;
        }
    }
    dense_free(&dense);
    rotor_free(&coarse);
    return status;
}

/* UnbalanceOutputs.build */
UnbalanceOutputs *unbalance_outputs_new(const Driveline *d, const RotorUnbalance *unbalances, int n_unbalances,
                                        double response_fraction, double omega_max, char *error, size_t size)
{
    int *counts = malloc((size_t)(d->n_segments + 1) * sizeof *counts);
    UnbalanceOutputs *outputs = calloc(1, sizeof *outputs);
    if (!counts || !outputs) {
        free(counts);
        free(outputs);
        set_error(error, size, OUT_OF_MEMORY);
        return NULL;
    }
    double spins[DAMPING_POINTS], table[DAMPING_POINTS * 2 * DAMPED_MODES];
    double step = omega_max / (DAMPING_POINTS - 1); /* numpy.linspace */
    for (int i = 0; i < DAMPING_POINTS; i++) {
        spins[i] = i * step + 0.0;
    }
    spins[DAMPING_POINTS - 1] = omega_max;
    fe_elements_by_length(d, TABLE_ELEMENTS, counts);
    if (mode_table(d, counts, spins, table, error, size)) {
        free(counts);
        free(outputs);
        return NULL;
    }
    fe_elements_by_length(d, FE_ELEMENTS, counts);
    Rotor *rotor = &outputs->rotor;
    if (rotor_init(rotor, d, counts, error, size)) {
        free(counts);
        free(outputs);
        return NULL;
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
    outputs->pivots = malloc((size_t)m * sizeof *outputs->pivots);
    cplx *rows = malloc(((size_t)rotor->n + 1) * sizeof *rows);
    if (!outputs->load || !outputs->row || !outputs->ab || !outputs->x || !outputs->pivots || !rows) {
        free(rows);
        unbalance_outputs_free(outputs);
        set_error(error, size, OUT_OF_MEMORY);
        return NULL;
    }
    /* DampedRotor.load: the unbalances' phasors times their shape rows */
    double length = driveline_length(d);
    for (int u = 0; u < n_unbalances; u++) {
        if (shape_row(rotor, unbalances[u].position, length, rows, error, size)) {
            free(rows);
            unbalance_outputs_free(outputs);
            return NULL;
        }
        cplx phasor = cplx_scale(unbalances[u].amount, cplx_expi(unbalances[u].phase));
        for (int i = 0; i < rotor->n; i++) {
            outputs->load[i] = cplx_add(outputs->load[i], cplx_mul(phasor, rows[i]));
        }
    }
    free(rows);
    if (shape_row(rotor, response_fraction * length, length, outputs->row, error, size)) {
        unbalance_outputs_free(outputs);
        return NULL;
    }
    /* CubicSpline(spins, table) and its checks */
    const char *refused = NULL;
    for (int i = 0; i < DAMPING_POINTS * 2 * DAMPED_MODES; i++) {
        refused = isfinite(table[i]) ? refused : "`y` must contain only finite values.";
    }
    for (int i = 0; i < DAMPING_POINTS; i++) {
        refused = i > 0 && !(spins[i] > spins[i - 1]) && !refused ? "`x` must be strictly increasing sequence." : refused;
    }
    refused = isfinite(omega_max) ? refused : "`x` must contain only finite values.";
    if (refused || cubic_spline_build(&outputs->modes, DAMPING_POINTS, spins, 2 * DAMPED_MODES, table)) {
        memset(&outputs->modes, 0, sizeof outputs->modes);
        unbalance_outputs_free(outputs);
        set_error(error, size, refused ? refused : OUT_OF_MEMORY);
        return NULL;
    }
    return outputs;
}

void unbalance_outputs_modes(const UnbalanceOutputs *outputs, double speed, double out[2 * DAMPED_MODES])
{
    cubic_spline_evaluate(&outputs->modes, speed, out);
}

/* UnbalanceOutputs.evaluate (DampedRotor.solve, components and bearing_forces at one speed) */
void unbalance_outputs_evaluate(const UnbalanceOutputs *outputs, double speed, double out[3])
{
    double table[2 * DAMPED_MODES];
    cubic_spline_evaluate(&outputs->modes, speed, table);
    int nearest = 0; /* numpy.argmin: the first of equal ones, the first nan */
    for (int k = 0; k < DAMPED_MODES; k++) {
        double distance = fabs(table[k] - speed);
        if (isnan(distance)) {
            nearest = k;
            break;
        }
        if (distance < fabs(table[nearest] - speed)) {
            nearest = k;
        }
    }
    out[2] = table[DAMPED_MODES + nearest];
    if (speed == 0.0) {
        out[0] = out[1] = 0.0;
        return;
    }
    const Rotor *rotor = &outputs->rotor;
    Band band = rotor->band;
    int m = rotor->size, n = rotor->n;
    /* K2 + i Omega (C2 + Omega Gv) - Omega^2 M2 */
    cplx spin_c = cplx_make(0.0, speed), spin_g = cplx_make(0.0, speed * speed);
    double squared = speed * speed;
    size_t cells = (size_t)band.rows * (size_t)m;
    for (size_t i = 0; i < cells; i++) {
        outputs->ab[i] = cplx_sub(cplx_add(cplx_add(rotor->banded[0][i], cplx_mul(spin_c, rotor->banded[1][i])),
                                            cplx_mul(spin_g, rotor->banded[2][i])),
                                   cplx_scale(squared, rotor->banded[3][i]));
    }
    for (int i = 0; i < m; i++) {
        outputs->x[i] = cplx_scale(squared, outputs->load[rotor->order[i]]);
    }
    if (band_solve(band, outputs->ab, outputs->pivots, outputs->x)) { /* an undamped resonance hit exactly */
        out[0] = out[1] = INFINITY;
        return;
    }
    /* the solution back in the order [p, q]: x[i] is unknown order[i] */
    cplx forward = cplx_real(0.0), backward = cplx_real(0.0);
    const cplx *x = outputs->x;
    int *place = outputs->pivots; /* free again after the solve */
    for (int i = 0; i < m; i++) {
        place[rotor->order[i]] = i;
    }
    for (int j = 0; j < n; j++) {
        forward = cplx_add(forward, cplx_mul(x[place[j]], outputs->row[j]));
        if (rotor->doubled) {
            backward = cplx_add(backward, cplx_mul(x[place[n + j]], outputs->row[j]));
        }
    }
    out[0] = cplx_abs(forward) + cplx_abs(cplx_conj(backward));
    double largest = 0.0; /* np.max(forces, initial=0.0), nan propagated */
    for (int b = 0; b < rotor->n_bearings; b++) {
        int row = rotor->bearing_rows[b];
        double force = 0.0;
        if (row >= 0) {
            const cplx *c = rotor->coefficients + 4 * b;
            cplx a = x[place[row]], q = rotor->doubled ? x[place[n + row]] : cplx_real(0.0);
            cplx fa = cplx_add(cplx_mul(cplx_add(c[0], cplx_mul(spin_c, c[2])), a),
                               cplx_mul(cplx_add(c[1], cplx_mul(spin_c, c[3])), q));
            cplx fq = cplx_add(cplx_mul(cplx_add(cplx_conj(c[1]), cplx_mul(spin_c, cplx_conj(c[3]))), a),
                               cplx_mul(cplx_add(cplx_conj(c[0]), cplx_mul(spin_c, cplx_conj(c[2]))), q));
            force = cplx_abs(fa) + cplx_abs(fq);
        }
        if (isnan(force) || force > largest) {
            largest = isnan(largest) ? largest : force;
        }
    }
    out[1] = largest;
}
