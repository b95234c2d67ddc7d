/* Complex (and real) linear algebra of the damped rotor model (damped.c), in linalg.c: the dense
 * complex eigenproblem as numpy.linalg.eig computes it (LAPACK's balancing, Hessenberg reduction,
 * shifted QR, inverse iteration), the banded complex LU solve of LAPACK's gbsv, the vectors of the
 * Arnoldi iteration, the real LU solve of numpy.linalg.solve. Matrices are dense by rows.
 *   linalg.c     dense complex eigenproblem, banded complex LU, Arnoldi vectors, real LU
 */
#ifndef LINALG_H
#define LINALG_H

#include <stddef.h>

#include "cplx.h"

/* ---- the banded complex LU solve (LAPACK gbsv's storage: (i, j) at ab[j][kl + ku + i - j]) ---- */
typedef struct {
    int n, kl, ku, rows; /* rows = 2 kl + ku + 1 per column */
} Band;

#define AB(band, ab, i, j) (ab)[(size_t)(j) * (size_t)(band).rows + (size_t)((band).kl + (band).ku + (i) - (j))]

/* ---- the dense complex eigenproblem (numpy.linalg.eig) ------------------------------------- */
/* 1 / d without overflow or a library call (Smith's division; LAPACK's gbtf2 scales a column by the
 * pivot's reciprocal too) */
cplx reciprocal(cplx d);
/* Balancing by powers of two: a[i][j] -> a[i][j] d[j] / d[i] with row and column norms brought
 * together, as LAPACK's gebal does before the QR iteration. */
void balance(cplx *a, int n, double *d);
/* Householder reduction to upper Hessenberg form, A = Q H Q^*; the reflector of column k is
 * I - tau_k v v^* with v = (1, a[k+2..][k]) over rows k+1.. (kept for the eigenvectors); v and w
 * are n long. */
void hessenberg(cplx *a, int n, cplx *v, cplx *w, double *tau);
/* The eigenvalues of the upper Hessenberg ``h`` (destroyed): implicitly single-shifted complex QR
 * with Wilkinson shifts, exceptional shifts after 10 and 20 steps on one eigenvalue, deflation of
 * negligible subdiagonal entries; -1 after 30 max(10, n) steps in all. */
int hessenberg_eigenvalues(cplx *h, int n, cplx *lambda);
/* An eigenvector of the Hessenberg ``h`` for ``lambda`` by inverse iteration, into ``x`` (n):
 * the LU of h - lambda I with row interchanges between neighbours (``lu`` n x n, ``multiplier`` and
 * ``swapped`` n), a first solve U x = ones (any right-hand side will do) and a second full solve. */
void inverse_iteration(const cplx *h, int n, cplx lambda, cplx *lu, cplx *multiplier, unsigned char *swapped,
                       cplx *x);
/* The Hessenberg matrix of hessenberg()'s ``a`` without the reflectors below its subdiagonal */
void hessenberg_part(const cplx *a, int n, cplx *h);
/* x <- D Q x: an eigenvector of the Hessenberg matrix back to the balanced, then the original one */
void back_transform(const cplx *a, int n, const double *tau, const double *d, cplx *x);

/* LU factors of ab in place with partial pivoting (``pivots`` n, the row swapped with each row as
 * it is eliminated); -1 on an exactly zero pivot (singular) */
int band_factor(Band band, cplx *ab, int *pivots);
/* b <- ab^-1 b in place, ab factorised by band_factor */
void band_substitute(Band band, const cplx *ab, const int *pivots, cplx *b);
/* Solves ab x = b in place (ab factorised, ``pivots`` n); -1 on an exactly zero pivot (singular) */
int band_solve(Band band, cplx *ab, int *pivots, cplx *b);

/* ---- vectors (the Arnoldi iteration's) ------------------------------------------------------ */
/* the 2-norm, scaled against overflow */
double vector_norm(const cplx *x, int n);
/* w minus its projection on the first ``count`` basis vectors, twice (classical Gram-Schmidt with one
 * reorthogonalisation); the coefficients added to ``column`` (stride ``stride``) unless it is NULL */
void orthogonalize(const cplx *basis, int count, int order, cplx *w, cplx *column, int stride);
/* A unit start vector, orthogonal to the first ``count`` basis vectors, from a fixed pseudo-random sequence */
void start_vector(const cplx *basis, int count, int order, unsigned long *seed, cplx *w);

/* ---- the real LU solve ---------------------------------------------------------------------- */
/* LU factors with partial pivoting of the real ``m`` (numpy.linalg.solve); -1 if it is singular */
int lu_factor(double *m, int n, int *pivots);
/* x <- -M^-1 x for the n rows of x (``columns`` wide, ``stride`` apart), M by its LU factors */
void mass_solve(const double *lu, const int *pivots, int n, cplx *x, int columns, int stride);

#endif
