/* Small dense linear algebra of the PowertrainMounts port (row-major matrices): products, solutions,
 * the symmetric eigenproblem (cyclic Jacobi; scipy.linalg.eigh's part) and the matrix exponential
 * (scipy.linalg.expm's part: Higham 2005, degree-13 Pade with scaling and squaring). */
#include "mounts.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* c = a b: (n x m) (m x p) */
void dense_multiply(const double *a, const double *b, double *c, int n, int m, int p)
{
    int i, j, k;
    for (i = 0; i < n; i++) {
        for (j = 0; j < p; j++) {
            double sum = 0.0;
            for (k = 0; k < m; k++) {
                sum += a[i * m + k] * b[k * p + j];
            }
            c[i * p + j] = sum;
        }
    }
}

/* max |v_i| of the ``n`` numbers of ``v`` */
double dense_largest(const double *v, int n)
{
    double found = 0.0;
    int i;
    for (i = 0; i < n; i++) {
        found = fmax(found, fabs(v[i]));
    }
    return found;
}

/* Factors a (n x n) in place as P a = L U by Gaussian elimination with partial pivoting (L's multipliers
 * below the diagonal, U on and above it, row k swapped with row pivots[k] at step k); 0 if a is singular. */
int dense_factor(double *a, int *pivots, int n)
{
    int i, j, k, pivot;
    for (k = 0; k < n; k++) {
        pivot = k;
        for (i = k + 1; i < n; i++) {
            if (fabs(a[i * n + k]) > fabs(a[pivot * n + k])) {
                pivot = i;
            }
        }
        if (a[pivot * n + k] == 0.0) {
            return 0;
        }
        pivots[k] = pivot;
        if (pivot != k) {
            for (j = 0; j < n; j++) {
                double t = a[k * n + j];
                a[k * n + j] = a[pivot * n + j], a[pivot * n + j] = t;
            }
        }
        for (i = k + 1; i < n; i++) {
            double f = a[i * n + k] / a[k * n + k];
            for (j = k + 1; j < n; j++) {
                a[i * n + j] -= f * a[k * n + j];
            }
            a[i * n + k] = f;
        }
    }
    return 1;
}

/* Solves a x = b for ``columns`` right-hand sides (b: n x columns, overwritten by x) with the factors of
 * dense_factor (each row of b takes the eliminations in the order of dense_factor's steps) */
void dense_substitute(const double *lu, const int *pivots, double *b, int n, int columns)
{
    int i, j, k;
    for (j = 0; j < columns; j++) { /* column by column, x[i] = b[i][j] */
        double *x = b + j;
        for (k = 0; k < n; k++) {
            if (pivots[k] != k) {
                double t = x[k * columns];
                x[k * columns] = x[pivots[k] * columns], x[pivots[k] * columns] = t;
            }
        }
        for (k = 0; k < n; k++) {
            const double xk = x[k * columns];
            for (i = k + 1; i < n; i++) {
                x[i * columns] -= lu[i * n + k] * xk;
            }
        }
        for (k = n - 1; k >= 0; k--) {
            double sum = x[k * columns];
            for (i = k + 1; i < n; i++) {
                sum -= lu[k * n + i] * x[i * columns];
            }
            x[k * columns] = sum / lu[k * n + k];
        }
    }
}

/* Solves a x = b for ``columns`` right-hand sides (b: n x columns, overwritten by x) by Gaussian
 * elimination with partial pivoting (a overwritten); 0 if a is singular. */
int dense_solve(double *a, double *b, int n, int columns)
{
    int pivots[MOUNTS_MAX_AUGMENTED];
    if (!dense_factor(a, pivots, n)) {
        return 0;
    }
    dense_substitute(a, pivots, b, n, columns);
    return 1;
}

/* Cyclic Jacobi rotations of the symmetric ``a`` (n x n, n <= 6): its eigenvalues on the diagonal, the
 * eigenvectors in the columns of ``vectors``. */
void dense_symmetric_eigen(double *a, double *vectors, int n)
{
    int sweep, p, q, k;
    for (p = 0; p < n * n; p++) {
        vectors[p] = (p % (n + 1)) == 0;
    }
    for (sweep = 0; sweep < 64; sweep++) {
        double off = 0.0, scale = 0.0;
        for (p = 0; p < n; p++) {
            for (q = 0; q < n; q++) {
                if (p == q) {
                    scale += a[p * n + q] * a[p * n + q];
                } else {
                    off += a[p * n + q] * a[p * n + q];
                }
            }
        }
        if (off <= 1e-32 * scale || off == 0.0) {
            return;
        }
        for (p = 0; p < n - 1; p++) {
            for (q = p + 1; q < n; q++) {
                double apq = a[p * n + q], theta, t, c, s;
                if (apq == 0.0) {
                    continue;
                }
                theta = (a[q * n + q] - a[p * n + p]) / (2.0 * apq);
                t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                c = 1.0 / sqrt(t * t + 1.0);
                s = t * c;
                for (k = 0; k < n; k++) { /* a <- a J */
                    double akp = a[k * n + p], akq = a[k * n + q];
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for (k = 0; k < n; k++) { /* a <- J^T a */
                    double apk = a[p * n + k], aqk = a[q * n + k];
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
                for (k = 0; k < n; k++) {
                    double vkp = vectors[k * n + p], vkq = vectors[k * n + q];
                    vectors[k * n + p] = c * vkp - s * vkq;
                    vectors[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
}

/* exp(z) by the degree-13 Pade approximant with ``count`` squarings (Higham 2005); 0 without memory */
int dense_exponential(double *z, int n, int count, double *out)
{
    static const double b[14] = {64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
                                 1187353796428800.0,  129060195264000.0,   10559470521600.0,
                                 670442572800.0,      33522128640.0,       1323241920.0,
                                 40840800.0,          960960.0,            16380.0,
                                 182.0,               1.0};
    const int nn = n * n;
    double *w = malloc(6 * nn * sizeof *w), *a2, *a4, *a6, *u, *v, scale = ldexp(1.0, -count);
    int i;
    if (w == NULL) {
        return 0;
    }
    a2 = w, a4 = w + nn, a6 = w + 2 * nn, u = w + 3 * nn, v = w + 4 * nn;
    for (i = 0; i < nn; i++) {
        z[i] *= scale;
    }
    dense_multiply(z, z, a2, n, n, n);
    dense_multiply(a2, a2, a4, n, n, n);
    dense_multiply(a2, a4, a6, n, n, n);
    for (i = 0; i < nn; i++) {
        u[i] = b[13] * a6[i] + b[11] * a4[i] + b[9] * a2[i];
        v[i] = b[12] * a6[i] + b[10] * a4[i] + b[8] * a2[i];
    }
    dense_multiply(a6, u, w + 5 * nn, n, n, n);
    memcpy(u, w + 5 * nn, nn * sizeof *u);
    dense_multiply(a6, v, w + 5 * nn, n, n, n);
    memcpy(v, w + 5 * nn, nn * sizeof *v);
    for (i = 0; i < nn; i++) {
        int diagonal = i % (n + 1) == 0;
        u[i] += b[7] * a6[i] + b[5] * a4[i] + b[3] * a2[i] + (diagonal ? b[1] : 0.0);
        v[i] += b[6] * a6[i] + b[4] * a4[i] + b[2] * a2[i] + (diagonal ? b[0] : 0.0);
    }
    dense_multiply(z, u, w + 5 * nn, n, n, n); /* U */
    for (i = 0; i < nn; i++) {
        out[i] = v[i] + w[5 * nn + i];  /* V + U */
        a2[i] = v[i] - w[5 * nn + i];   /* V - U */
    }
    if (!dense_solve(a2, out, n, n)) {
        free(w);
        return 0;
    }
    for (i = 0; i < count; i++) {
        dense_multiply(out, out, a4, n, n, n);
        memcpy(out, a4, nn * sizeof *out);
    }
    free(w);
    return 1;
}
