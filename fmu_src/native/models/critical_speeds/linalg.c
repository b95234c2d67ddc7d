/* Complex (and real) linear algebra of the damped rotor model (linalg.h). */
#include "linalg.h"

#include <float.h>
#include <math.h>
#include <string.h>

cplx reciprocal(cplx d)
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
void balance(cplx *a, int n, double *d)
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

void hessenberg(cplx *a, int n, cplx *v, cplx *w, double *tau)
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

int hessenberg_eigenvalues(cplx *h, int n, cplx *lambda)
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
            cplx p = cplx_scale(0.5, cplx_sub(a, d)), bc = cplx_mul(b, c), root = cplx_sqrt(cplx_add(cplx_mul(p, p),
                                                                                                     bc));
            cplx plus = cplx_add(p, root), minus = cplx_sub(p, root);
            cplx den = cplx_abs(plus) >= cplx_abs(minus) ? plus : minus;
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

void inverse_iteration(const cplx *h, int n, cplx lambda, cplx *lu, cplx *multiplier, unsigned char *swapped,
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

void hessenberg_part(const cplx *a, int n, cplx *h)
{
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < n; j++) {
            h[(size_t)i * (size_t)n + (size_t)j] = j + 1 >= i ? a[(size_t)i * (size_t)n + (size_t)j] : cplx_real(0.0);
        }
    }
}

void back_transform(const cplx *a, int n, const double *tau, const double *d, cplx *x)
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

int band_factor(Band band, cplx *ab, int *pivots)
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

void band_substitute(Band band, const cplx *ab, const int *pivots, cplx *b)
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

int band_solve(Band band, cplx *ab, int *pivots, cplx *b)
{
    if (band_factor(band, ab, pivots)) {
        return -1;
    }
    band_substitute(band, ab, pivots, b);
    return 0;
}

double vector_norm(const cplx *x, int n)
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

void orthogonalize(const cplx *basis, int count, int order, cplx *w, cplx *column, int stride)
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

void start_vector(const cplx *basis, int count, int order, unsigned long *seed, cplx *w)
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

int lu_factor(double *m, int n, int *pivots)
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

void mass_solve(const double *lu, const int *pivots, int n, cplx *x, int columns, int stride)
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
                sum = cplx_sub(sum, cplx_scale(lu[(size_t)i * (size_t)n + (size_t)k],
                                               x[(size_t)k * (size_t)stride + (size_t)c]));
            }
            x[(size_t)i * (size_t)stride + (size_t)c] = sum;
        }
        for (int i = n - 1; i >= 0; i--) {
            cplx sum = x[(size_t)i * (size_t)stride + (size_t)c];
            for (int k = i + 1; k < n; k++) {
                sum = cplx_sub(sum, cplx_scale(lu[(size_t)i * (size_t)n + (size_t)k],
                                               x[(size_t)k * (size_t)stride + (size_t)c]));
            }
            x[(size_t)i * (size_t)stride + (size_t)c] = cplx_div_real(sum, lu[(size_t)i * (size_t)n + (size_t)i]);
        }
        for (int i = 0; i < n; i++) {
            x[(size_t)i * (size_t)stride + (size_t)c] = cplx_neg(x[(size_t)i * (size_t)stride + (size_t)c]);
        }
    }
}
