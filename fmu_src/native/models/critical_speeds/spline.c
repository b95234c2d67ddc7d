/* Cubic splines with the not-a-knot end condition: scipy.interpolate.CubicSpline(x, y) with its
 * defaults, y of shape (n, m), all columns at once.
 *
 * The slopes at the knots solve the tridiagonal system of continuous second derivatives (Gaussian
 * elimination with partial pivoting, as LAPACK's gtsv that scipy's solve_banded calls); two knots give
 * the straight line, three the parabola through them. Each interval i then holds the cubic Hermite
 * polynomial in (x - x[i]); c[(4 i + k) m + j] is the coefficient of (x - x[i])^k of column j.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rotor.h"

/* The Hermite coefficients of every interval from the values and slopes at the knots
 * (scipy's CubicHermiteSpline.__init__). */
static void hermite_coefficients(CubicSpline *spline, const double *y, const double *slope_knot,
                                 const double *secant)
{
    int n = spline->n, m = spline->m;
    for (int i = 0; i + 1 < n; ++i) {
        double dx = spline->x[i + 1] - spline->x[i];
        double *c = spline->c + (size_t)4 * i * m;
        for (int j = 0; j < m; ++j) {
            double s0 = slope_knot[(size_t)i * m + j], s1 = slope_knot[(size_t)(i + 1) * m + j];
            double slope = secant[(size_t)i * m + j];
            double t = (s0 + s1 - 2.0 * slope) / dx;
            c[j] = y[(size_t)i * m + j];
            c[m + j] = s0;
            c[2 * m + j] = (slope - s0) / dx - t;
            c[3 * m + j] = t / dx;
        }
    }
}

/* The not-a-knot system for n >= 4 knots (CubicSpline.__init__), solved for the slopes ``s`` (n x m)
 * by elimination with partial pivoting. ``work`` holds 4 n doubles. */
static void not_a_knot_slopes(int n, int m, const double *x, const double *secant, double *s, double *work)
{
    double *sub = work, *diag = work + n, *sup = work + 2 * n, *sup2 = work + 3 * n;
    double dx0 = x[1] - x[0], dx1 = x[2] - x[1], d = x[2] - x[0];
    double dxa = x[n - 2] - x[n - 3], dxb = x[n - 1] - x[n - 2], e = x[n - 1] - x[n - 3];

    /* row 0: dx1 s0 + (x2 - x0) s1 */
    diag[0] = dx1;
    sup[0] = d;
    for (int j = 0; j < m; ++j) {
        s[j] = ((dx0 + 2.0 * d) * dx1 * secant[j] + dx0 * dx0 * secant[m + j]) / d;
    }
    for (int i = 1; i + 1 < n; ++i) {
        double left = x[i] - x[i - 1], right = x[i + 1] - x[i];
        sub[i] = right;
        diag[i] = 2.0 * (left + right);
        sup[i] = left;
        for (int j = 0; j < m; ++j) {
            s[(size_t)i * m + j] = 3.0 * (right * secant[(size_t)(i - 1) * m + j] + left * secant[(size_t)i * m + j]);
        }
    }
    /* row n - 1: (x[n-1] - x[n-3]) s[n-2] + dx[n-3] s[n-1] */
    sub[n - 1] = e;
    diag[n - 1] = dxa;
    for (int j = 0; j < m; ++j) {
        s[(size_t)(n - 1) * m + j] =
            (dxb * dxb * secant[(size_t)(n - 3) * m + j] + (2.0 * e + dxb) * dxa * secant[(size_t)(n - 2) * m + j]) /
            e;
    }

    /* forward elimination; a row exchange fills the second superdiagonal */
    for (int i = 0; i + 1 < n; ++i) {
        double *bi = s + (size_t)i * m, *bn = s + (size_t)(i + 1) * m;
        if (fabs(diag[i]) >= fabs(sub[i + 1])) {
            double factor = sub[i + 1] / diag[i];
            diag[i + 1] -= factor * sup[i];
            sup2[i] = 0.0;
            for (int j = 0; j < m; ++j) {
                bn[j] -= factor * bi[j];
            }
        } else {
            double factor = diag[i] / sub[i + 1];
            double next_diag = diag[i + 1], next_sup = i + 2 < n ? sup[i + 1] : 0.0;
            diag[i] = sub[i + 1];
            diag[i + 1] = sup[i] - factor * next_diag;
            sup2[i] = next_sup;
            if (i + 2 < n) {
                sup[i + 1] = -factor * next_sup;
            }
            sup[i] = next_diag;
            for (int j = 0; j < m; ++j) {
                double upper = bi[j];
                bi[j] = bn[j];
                bn[j] = upper - factor * bn[j];
            }
        }
    }
    /* back substitution */
    for (int i = n - 1; i >= 0; --i) {
        double *bi = s + (size_t)i * m;
        for (int j = 0; j < m; ++j) {
            double v = bi[j];
            if (i + 1 < n) {
                v -= sup[i] * s[(size_t)(i + 1) * m + j];
            }
            if (i + 2 < n) {
                v -= sup2[i] * s[(size_t)(i + 2) * m + j];
            }
            bi[j] = v / diag[i];
        }
    }
}

/* The slopes of the parabola through three knots (CubicSpline.__init__, n = 3): its 3 x 3 system solved
 * by elimination with partial pivoting, as scipy's solve (LAPACK gesv). */
static void parabola_slopes(const double *x, int m, const double *secant, double *s)
{
    double dx0 = x[1] - x[0], dx1 = x[2] - x[1];
    double a[3][3] = {{1.0, 1.0, 0.0}, {dx1, 2.0 * (dx0 + dx1), dx0}, {0.0, 1.0, 1.0}};
    int order[3] = {0, 1, 2};
    for (int k = 0; k < 2; ++k) {
        int pivot = k;
        for (int i = k + 1; i < 3; ++i) {
            if (fabs(a[order[i]][k]) > fabs(a[order[pivot]][k])) {
                pivot = i;
            }
        }
        int swap = order[k];
        order[k] = order[pivot];
        order[pivot] = swap;
        double inverse = 1.0 / a[order[k]][k];
        for (int i = k + 1; i < 3; ++i) {
            double factor = a[order[i]][k] * inverse;
            a[order[i]][k] = factor;
            for (int j = k + 1; j < 3; ++j) {
                a[order[i]][j] -= factor * a[order[k]][j];
            }
        }
    }
    for (int col = 0; col < m; ++col) {
        double b[3] = {2.0 * secant[col], 3.0 * (dx0 * secant[m + col] + dx1 * secant[col]), 2.0 * secant[m + col]};
        double v[3];
        for (int i = 0; i < 3; ++i) {
            v[i] = b[order[i]];
            for (int j = 0; j < i; ++j) {
                v[i] -= a[order[i]][j] * v[j];
            }
        }
        for (int i = 2; i >= 0; --i) {
            for (int j = i + 1; j < 3; ++j) {
                v[i] -= a[order[i]][j] * v[j];
            }
            v[i] /= a[order[i]][i];
        }
        for (int i = 0; i < 3; ++i) {
            s[(size_t)i * m + col] = v[i];
        }
    }
}

/* CubicSpline.__init__ (bc_type 'not-a-knot'): -1 for fewer than two knots, knots not finite and
 * increasing, or out of memory. */
int cubic_spline_build(CubicSpline *spline, int n, const double *x, int m, const double *y)
{
    spline->n = 0;
    spline->m = 0;
    spline->x = NULL;
    spline->c = NULL;
    if (n < 2 || m < 0) {
        return -1;
    }
    for (int i = 0; i < n; ++i) {
        if (!isfinite(x[i]) || (i > 0 && !(x[i] > x[i - 1]))) {
            return -1;
        }
    }
    size_t values = (size_t)n * (size_t)(m > 0 ? m : 1);
    double *knots = malloc((size_t)n * sizeof *knots);
    double *c = malloc(4 * values * sizeof *c);
    double *secant = malloc(values * sizeof *secant);
    double *s = malloc(values * sizeof *s);
    double *work = malloc(4 * (size_t)n * sizeof *work);
    if (!knots || !c || !secant || !s || !work) {
        free(knots);
        free(c);
        free(secant);
        free(s);
        free(work);
        return -1;
    }
    memcpy(knots, x, (size_t)n * sizeof *knots);
    spline->n = n;
    spline->m = m;
    spline->x = knots;
    spline->c = c;

    for (int i = 0; i + 1 < n; ++i) {
        double dx = x[i + 1] - x[i];
        for (int j = 0; j < m; ++j) {
            secant[(size_t)i * m + j] = (y[(size_t)(i + 1) * m + j] - y[(size_t)i * m + j]) / dx;
        }
    }
    if (n == 2) { /* the straight line: both end slopes the secant's */
        for (int j = 0; j < m; ++j) {
            s[j] = secant[j];
            s[m + j] = secant[j];
        }
    } else if (n == 3) { /* the parabola through the three points */
        parabola_slopes(x, m, secant, s);
    } else {
        not_a_knot_slopes(n, m, x, secant, s, work);
    }
    hermite_coefficients(spline, y, s, secant);
    free(secant);
    free(s);
    free(work);
    return 0;
}

/* PPoly's interval search with extrapolation: the interval holding ``x`` (a knot starts the interval
 * on its right, the last knot ends the last one), the end intervals beyond the knots. */
static int interval_of(const CubicSpline *spline, double x)
{
    int lo = 0, hi = spline->n - 2;
    if (x >= spline->x[hi]) {
        return hi;
    }
    while (lo < hi) { /* the last interval lo with x[lo] <= x, or 0 */
        int mid = lo + (hi - lo + 1) / 2;
        if (spline->x[mid] <= x) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    return lo;
}

/* The polynomial of interval ``i`` of column ``j`` at ``t`` = x - x[i], ascending powers summed
 * (PPoly's evaluation). */
static double polynomial(const CubicSpline *spline, int i, int j, double t)
{
    const double *c = spline->c + (size_t)4 * i * spline->m + j;
    double value = 0.0, power = 1.0;
    for (int k = 0; k < 4; ++k) {
        value += c[(size_t)k * spline->m] * power;
        power *= t;
    }
    return value;
}

/* PPoly.__call__ (extrapolating); NaN gives NaN. */
void cubic_spline_evaluate(const CubicSpline *spline, double x, double *out)
{
    if (isnan(x)) {
        for (int j = 0; j < spline->m; ++j) {
            out[j] = x;
        }
        return;
    }
    int i = interval_of(spline, x);
    for (int j = 0; j < spline->m; ++j) {
        out[j] = polynomial(spline, i, j, x - spline->x[i]);
    }
}

double cubic_spline_value(const CubicSpline *spline, double x, int column)
{
    if (isnan(x)) {
        return x;
    }
    int i = interval_of(spline, x);
    return polynomial(spline, i, column, x - spline->x[i]);
}

double cubic_spline_slope(const CubicSpline *spline, double x, int column)
{
    if (isnan(x)) {
        return x;
    }
    int i = interval_of(spline, x);
    const double *c = spline->c + (size_t)4 * i * spline->m + column;
    double t = x - spline->x[i];
    return c[spline->m] + t * (2.0 * c[2 * (size_t)spline->m] + t * 3.0 * c[3 * (size_t)spline->m]);
}

void cubic_spline_free(CubicSpline *spline)
{
    free(spline->x);
    free(spline->c);
    spline->x = NULL;
    spline->c = NULL;
    spline->n = 0;
    spline->m = 0;
}
