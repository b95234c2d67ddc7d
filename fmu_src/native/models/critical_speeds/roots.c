/* The bracketing root search and the searches along lines (w, spin): a port of
 * driveline/rotor/roots.py (find_roots_batch) and of Driveline's searches in driveline/rotor/driveline.py
 * (_kappa, _grid, _line_roots, _roots_by_whirl, order_resonances, critical_speeds); seed Sec. 8, Fig. 3.
 *
 * The Python core searches many lines in one vectorised batch; here every line is searched on its
 * own, which finds the same roots: the grid scan, the dip sub-grids and the bracket refinement of
 * one line never depend on another line. */
#include "rotor.h"

#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N_NONE INT_MIN      /* n = None */

/* One search: the determinant along the line (w, spin) = (w x, s x + o) and the roots found so far. */
typedef struct {
    const Chain *chain;
    double w, s, o;
    double *x;
    int count, capacity;
    int rescans; /* dips re-scanned on the line (at most ROTOR_ROOTS_MAX_DIPS) */
    char *error;
    size_t size;
} Search;

static void free_all(void *a, void *b, void *c)
{
    free(a);
    free(b);
    free(c);
}

/* driveline._speed's message; ERROR_VALUE */
static ErrorKind speed_error(const char *name, double value, char *error, size_t size)
{
    char text[64];
    python_float_repr(value, text, sizeof text);
    if (error != NULL && size > 0) {
        snprintf(error, size, "%s must be a finite speed > 0 rad/s, got %s", name, text);
    }
    return ERROR_VALUE;
}

/* the determinant at x on the line, and its rounding level into *rounding (NULL: not asked) */
static double line_f(const Search *st, double x, double *rounding)
{
    double w = st->w * x, spin = st->s * x + st->o, f;
    chain_determinant_rounding(st->chain, 1, &w, &spin, &f, rounding);
    return f;
}

/* roots._Search.rounding at point j of a sampled sequence: its rounding level rx[j] raised to the difference
 * from the determinant with every segment cut into one more piece (the propagation's round-off), once per
 * point: level[j] < 0 until then */
static double raised_rounding(const Search *st, const double *x, const double *fx, const double *rx, double *level,
                              int j)
{
    if (level[j] < 0.0) {
        double w = st->w * x[j], spin = st->s * x[j] + st->o, again, difference;
        chain_determinant_cut(st->chain, 1, &w, &spin, 1, &again, NULL);
        difference = fabs(fx[j] - again);
        level[j] = rx[j] > difference ? rx[j] : difference; /* numpy.maximum */
    }
    return level[j];
}

/* ERROR_NONE, or ERROR_VALUE with ROTOR_BUDGET_SPENT once the chain's budget is spent (every search stops
 * at its next evaluation; the model names the stage) */
static ErrorKind budget_left(const Chain *chain, char *error, size_t size)
{
    if (chain_budget_spent(chain)) {
        ROTOR_ERROR(error, size, ROTOR_BUDGET_SPENT);
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

/* x appended to the roots found; ERROR_NONE, or ERROR_VALUE out of memory */
static ErrorKind found(Search *st, double x)
{
    if (st->count == st->capacity) {
        int capacity = st->capacity ? 2 * st->capacity : 16;
        double *grown = realloc(st->x, (size_t)capacity * sizeof *grown);
        if (grown == NULL) {
            ROTOR_ERROR(st->error, st->size, ROTOR_OUT_OF_MEMORY);
            return ERROR_VALUE;
        }
        st->x = grown;
        st->capacity = capacity;
    }
    st->x[st->count++] = x;
    return ERROR_NONE;
}

static double sign_of(double v)
{ /* numpy.sign (nan for nan) */
    return v > 0.0 ? 1.0 : v < 0.0 ? -1.0 : v;
}

/* roots._refine for one bracket: Chandrupatla's method (inverse quadratic interpolation where safe,
 * else bisection); a converged point with |f| above both ends is a pole and is rejected. ERROR_NONE,
 * or the failure's kind with the message in st->error. */
static ErrorKind refine(Search *st, double a, double b, double fa, double fb)
{
    double f_ends = fabs(fa) > fabs(fb) ? fabs(fa) : fabs(fb);
    double c, fc, t = 0.5;
    int iteration;
    for (iteration = 0; iteration < ROTOR_ROOTS_MAX_ITERATIONS; iteration++) {
        double xt = a + t * (b - a), ft = line_f(st, xt, NULL), xm, fm, tlim, xi, phi;
        ErrorKind spent = budget_left(st->chain, st->error, st->size);
        if (spent != ERROR_NONE) {
            return spent;
        }
        if (sign_of(ft) == sign_of(fa)) { /* the new point replaces a; else b becomes a */
            c = a;
            fc = fa;
        } else {
            c = b;
            fc = fb;
            b = a;
            fb = fa;
        }
        a = xt;
        fa = ft;
        if (fabs(fa) < fabs(fb)) {
            xm = a;
            fm = fa;
        } else {
            xm = b;
            fm = fb;
        }
        tlim = (ROTOR_ROOTS_XTOL + ROTOR_ROOTS_RTOL * fabs(xm)) / fabs(b - a);
        if (fm == 0.0 || tlim > 0.5) {
            if (fabs(fm) > f_ends) { /* |f| grew towards the 'root': a pole */
                return ERROR_NONE;
            }
            return found(st, xm);
        }
        xi = (a - b) / (c - b);
        phi = (fa - fb) / (fc - fb);
        t = 0.5;
        if (phi * phi < xi && (1.0 - phi) * (1.0 - phi) < 1.0 - xi) {
            t = fa / (fb - fa) * fc / (fb - fc) + (c - a) / (b - a) * fa / (fc - fa) * fb / (fc - fb);
            if (!isfinite(t)) {
                t = 0.5;
            }
        }
        t = t > tlim ? t : tlim;
        t = t < 1.0 - tlim ? t : 1.0 - tlim;
    }
    ROTOR_ERROR(st->error, st->size, "root refinement did not converge");
    return ERROR_ARITHMETIC;
}

static ErrorKind scan(Search *st, const double *x, const double *fx, const double *rx, int n, int depth);

/* scan with the rounding levels of the sequence's points (level, n entries, < 0: not raised yet) */
static ErrorKind scan_levels(Search *st, const double *x, const double *fx, const double *rx, double *level, int n,
                             int depth)
{
    int i, j;
    ErrorKind failed;
    for (i = 0; i < n; i++) {
        if (fx[i] == 0.0 && (failed = found(st, x[i])) != ERROR_NONE) {
            return failed;
        }
    }
    for (i = 0; i + 1 < n; i++) {
        if (sign_of(fx[i]) * sign_of(fx[i + 1]) < 0.0 &&
            (failed = refine(st, x[i], x[i + 1], fx[i], fx[i + 1])) != ERROR_NONE) {
            return failed;
        }
    }
    for (i = 1; i + 1 < n; i++) {
        double s = sign_of(fx[i]), lo = x[i - 1], hi = x[i + 1], mid = x[i];
        double a0 = fabs(fx[i - 1]), a1 = fabs(fx[i]), a2 = fabs(fx[i + 1]), larger = a0 > a2 ? a0 : a2;
        double sx[ROTOR_ROOTS_SUBGRID + 1], sf[ROTOR_ROOTS_SUBGRID + 1], sr[ROTOR_ROOTS_SUBGRID + 1], r0, r1, r2;
        int unresolved;
        if (!(sign_of(fx[i - 1]) == s && s == sign_of(fx[i + 1]) && s != 0.0)) {
            continue;
        }
        if (!(a1 < a0 && a1 <= a2 && a1 <= ROTOR_ROOTS_DIP_RATIO * larger)) {
            continue;
        }
        /* the propagation's round-off at the dip's points, which the rounding levels of f do not see */
        r0 = raised_rounding(st, x, fx, rx, level, i - 1);
        r1 = raised_rounding(st, x, fx, rx, level, i);
        r2 = raised_rounding(st, x, fx, rx, level, i + 1);
        if ((failed = budget_left(st->chain, st->error, st->size)) != ERROR_NONE) {
            return failed;
        }
        unresolved = a1 <= ROTOR_ROOTS_ROUNDING * r1;
        if (!unresolved && !(larger - a1 > ROTOR_ROOTS_ROUNDING * (r0 + r1 + r2))) {
            continue; /* ripple */
        }
        if (hi - lo <= 2.0 * (ROTOR_ROOTS_XTOL + ROTOR_ROOTS_RTOL * fabs(mid)) || depth >= ROTOR_ROOTS_MAX_DEPTH ||
            unresolved) {
            if ((failed = found(st, mid)) != ERROR_NONE || (failed = found(st, mid)) != ERROR_NONE) {
                return failed;
            }
            continue;
        }
        if (++st->rescans > ROTOR_ROOTS_MAX_DIPS) {
            if (st->error != NULL && st->size > 0) {
                snprintf(st->error, st->size,
                         "the root search met more than %d dips on one line: rounding hides the roots there",
                         ROTOR_ROOTS_MAX_DIPS);
            }
            return ERROR_ARITHMETIC;
        }
        sx[0] = lo;
        sf[0] = fx[i - 1];
        sr[0] = r0;
        for (j = 1; j < ROTOR_ROOTS_SUBGRID; j++) {
            sx[j] = lo + (hi - lo) * (j * (1.0 / ROTOR_ROOTS_SUBGRID)); /* numpy.linspace(0, 1, SUBGRID + 1) */
            sf[j] = line_f(st, sx[j], &sr[j]);
            if ((failed = budget_left(st->chain, st->error, st->size)) != ERROR_NONE) {
                return failed;
            }
        }
        sx[ROTOR_ROOTS_SUBGRID] = hi;
        sf[ROTOR_ROOTS_SUBGRID] = fx[i + 1];
        sr[ROTOR_ROOTS_SUBGRID] = r2;
        if ((failed = scan(st, sx, sf, sr, ROTOR_ROOTS_SUBGRID + 1, depth + 1)) != ERROR_NONE) {
            return failed;
        }
    }
    return ERROR_NONE;
}

/* roots._scan for one sampled sequence (f fx, rounding levels rx): its zeros and sign changes, then its
 * dips re-scanned on sub-grids of SUBGRID steps (a dip that persists down to the root tolerance or to the
 * rounding of f is a double root, one that the rounding of its points explains is dropped; the rounding of
 * a dip's points raised to the propagation's round-off, raised_rounding; more than MAX_DIPS re-scans on the
 * line are refused). ERROR_NONE, or the failure's kind with the message in st->error. */
static ErrorKind scan(Search *st, const double *x, const double *fx, const double *rx, int n, int depth)
{
    double *level = malloc((size_t)n * sizeof *level);
    int i;
    ErrorKind status;
    if (level == NULL) {
        ROTOR_ERROR(st->error, st->size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (i = 0; i < n; i++) {
        level[i] = -1.0;
    }
    status = scan_levels(st, x, fx, rx, level, n, depth);
    free(level);
    return status;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* roots.find_roots_batch for one function: the roots on [grid[0], grid[n - 1]], ascending; ERROR_NONE,
 * or the failure's kind with the message in st->error */
static ErrorKind find_roots(Search *st, const double *grid, int n)
{
    double *fx = malloc(2 * (size_t)n * sizeof *fx), *rx;
    int i;
    ErrorKind status;
    if (fx == NULL) {
        ROTOR_ERROR(st->error, st->size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    rx = fx + n;
    status = ERROR_NONE;
    for (i = 0; i < n && status == ERROR_NONE; i++) {
        fx[i] = line_f(st, grid[i], &rx[i]);
        status = budget_left(st->chain, st->error, st->size);
    }
    status = status != ERROR_NONE ? status : scan(st, grid, fx, rx, n, 0);
    free(fx);
    if (status == ERROR_NONE && st->count > 1) {
        qsort(st->x, (size_t)st->count, sizeof *st->x, compare_doubles);
    }
    return status;
}

/* Driveline._grid: uniform in the bare-shaft phase kappa sqrt(|ratio| x) with POINTS_PER_ROOT points per
 * expected root, plus a logarithmic lead-in (numpy.geomspace(x[0] LEAD_RATIO, x[0], LEAD_POINTS)[:-1]),
 * into *grid (owned) and *count; ERROR_NONE, or ERROR_VALUE out of memory (*grid NULL). */
static ErrorKind grid_new(const Chain *chain, double x_max, double ratio, int coarse, double **grid, int *count,
                          char *error, size_t size)
{
    int extra = coarse ? 0 : chain_freedoms(chain), per_pi, n, i;
    double kappa = chain_kappa(chain) * sqrt(fabs(ratio)), theta_max, steps, step, log_start, log_stop, *x;
    per_pi = ROTOR_DRIVELINE_POINTS_PER_ROOT * (1 + extra) * (chain_isotropic(chain) ? 1 : 2);
    theta_max = kappa * sqrt(x_max);
    steps = ceil(theta_max / FMU_PI * per_pi);
    *grid = NULL;
    if (!(steps < (double)(INT_MAX / 2))) {
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    n = steps > 8.0 ? (int)steps : 8;
    x = malloc((size_t)(ROTOR_DRIVELINE_LEAD_POINTS - 1 + n + 1) * sizeof *x);
    if (x == NULL) {
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    step = theta_max / n;
    for (i = 0; i < n; i++) { /* offset by an irrational fraction of a step */
        double t = (i + ROTOR_DRIVELINE_GRID_OFFSET) * step / kappa;
        x[ROTOR_DRIVELINE_LEAD_POINTS - 1 + i] = t * t;
    }
    x[ROTOR_DRIVELINE_LEAD_POINTS - 1 + n] = (theta_max / kappa) * (theta_max / kappa);
    x[0] = x[ROTOR_DRIVELINE_LEAD_POINTS - 1] * ROTOR_DRIVELINE_LEAD_RATIO;
    log_start = log10(x[0]);
    log_stop = log10(x[ROTOR_DRIVELINE_LEAD_POINTS - 1]);
    for (i = 1; i < ROTOR_DRIVELINE_LEAD_POINTS - 1; i++) {
        x[i] = pow(10.0, i * ((log_stop - log_start) / (ROTOR_DRIVELINE_LEAD_POINTS - 1)) + log_start);
    }
    *count = ROTOR_DRIVELINE_LEAD_POINTS + n;
    *grid = x;
    return ERROR_NONE;
}

/* The roots on one line over its grid (x_max, ratio |w|, coarse) into *roots; ERROR_NONE, or the
 * failure's kind with the message */
static ErrorKind search_line(const Chain *chain, const RotorLine *line, double x_max, int coarse, RotorRoots *roots,
                             char *error, size_t size)
{
    Search st;
    int n;
    double *grid;
    ErrorKind status = grid_new(chain, x_max, line->w, coarse, &grid, &n, error, size);
    if (status != ERROR_NONE) {
        return status;
    }
    st.chain = chain;
    st.w = line->w;
    st.s = line->s;
    st.o = line->o;
    st.x = NULL;
    st.count = st.capacity = st.rescans = 0;
    st.error = error;
    st.size = size;
    status = find_roots(&st, grid, n);
    free(grid);
    if (status != ERROR_NONE) {
        free(st.x);
        return status;
    }
    free(roots->x);
    roots->x = st.x;
    roots->count = st.count;
    return ERROR_NONE;
}

void rotor_roots_free(RotorRoots *roots, int m)
{
    int i;
    for (i = 0; roots != NULL && i < m; i++) {
        free(roots[i].x);
        roots[i].x = NULL;
        roots[i].count = 0;
    }
}

/* Driveline._line_roots with n = N_NONE for None; returns as rotor_line_roots */
static ErrorKind line_roots(const Chain *chain, const RotorLine *lines, int m, int n, double x_max, double limit,
                            const unsigned char *coarse, RotorRoots *roots, char *error, size_t size)
{
    int j;
    ErrorKind failed;
    for (j = 0; j < m; j++) {
        roots[j].count = 0;
        roots[j].x = NULL;
    }
    if (x_max != 0.0) {
        if (!(x_max > 0.0) || isinf(x_max)) {
            return speed_error("x_max", x_max, error, size);
        }
        for (j = 0; j < m; j++) {
            if ((failed = search_line(chain, &lines[j], x_max, coarse != NULL && coarse[j], &roots[j], error, size)) !=
                ERROR_NONE) {
                rotor_roots_free(roots, m);
                return failed;
            }
        }
        return ERROR_NONE;
    }
    if (n == N_NONE || n < 1) {
        if (error != NULL && size > 0) {
            if (n == N_NONE) {
                snprintf(error, size, "n must be a positive integer (or give an upper limit), got None");
            } else {
                snprintf(error, size, "n must be a positive integer (or give an upper limit), got %d", n);
            }
        }
        return ERROR_VALUE;
    }
    if (!(limit > 0.0) || isinf(limit)) {
        return speed_error("limit", limit, error, size);
    }
    for (j = 0; j < m; j++) {
        double ratio = fabs(lines[j].w), x_hi = (n + 2) * FMU_PI / (chain_kappa(chain) * sqrt(ratio));
        x_hi = x_hi * x_hi;
        x_hi = x_hi < limit ? x_hi : limit;
        for (;;) { /* a line short of n roots is searched again over a 4x wider range, until limit */
            if ((failed = search_line(chain, &lines[j], x_hi, 0, &roots[j], error, size)) != ERROR_NONE) {
                rotor_roots_free(roots, m);
                return failed;
            }
            if (roots[j].count >= n || !(x_hi < limit)) {
                break;
            }
            x_hi = 4.0 * x_hi < limit ? 4.0 * x_hi : limit;
        }
        if (roots[j].count > n) {
            roots[j].count = n;
        }
    }
    return ERROR_NONE;
}

ErrorKind rotor_line_roots(const Chain *chain, const RotorLine *lines, int m, int n, double x_max, double limit,
                           const unsigned char *coarse, RotorRoots *roots, char *error, size_t size)
{
    return line_roots(chain, lines, m, n, x_max, limit, coarse, roots, error, size);
}

/* a copy of the first ``n`` roots (all for N_NONE) of ``from`` that ``keep`` selects (NULL: all);
 * ERROR_NONE, or ERROR_VALUE out of memory */
static ErrorKind take(const RotorRoots *from, const unsigned char *keep, int n, RotorRoots *to, char *error,
                      size_t size)
{
    int i;
    to->count = 0;
    to->x = malloc((size_t)(from->count > 0 ? from->count : 1) * sizeof *to->x);
    if (to->x == NULL) {
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (i = 0; i < from->count && (n == N_NONE || to->count < n); i++) {
        if (keep == NULL || keep[i]) {
            to->x[to->count++] = from->x[i];
        }
    }
    return ERROR_NONE;
}

/* Driveline._roots_by_whirl: isotropic, forward at +w and backward at -w; anisotropic, the 2 n lowest
 * roots at w > 0 classified by their mode's forward fraction (>= 0.5 forward); standstill cases
 * (s = o = 0) are searched once and both senses get their roots. n = N_NONE: all up to x_max.
 * Returns as rotor_roots_by_whirl. */
static ErrorKind roots_by_whirl(const Chain *chain, const RotorLine *cases, int m, int n, double x_max, double limit,
                                RotorRoots *forward, RotorRoots *backward, char *error, size_t size)
{
    int iso = chain_isotropic(chain), c, count = 0, nn;
    ErrorKind status;
    RotorLine *lines = malloc((size_t)(2 * m > 0 ? 2 * m : 1) * sizeof *lines);
    int *first = malloc((size_t)(m > 0 ? m : 1) * sizeof *first);
    RotorRoots *found_roots = malloc((size_t)(2 * m > 0 ? 2 * m : 1) * sizeof *found_roots);
    unsigned char *kinds = NULL;
    for (c = 0; c < m; c++) {
        forward[c].count = backward[c].count = 0;
        forward[c].x = backward[c].x = NULL;
    }
    if (lines == NULL || first == NULL || found_roots == NULL) {
        free_all(lines, first, found_roots);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (c = 0; c < m; c++) {
        int standstill = cases[c].s == 0.0 && cases[c].o == 0.0;
        first[c] = count;
        lines[count++] = cases[c];
        if (iso && !standstill) {
            lines[count] = cases[c];
            lines[count++].w = -cases[c].w;
        }
    }
    nn = n == N_NONE || iso ? n : 2 * n;
    if ((status = line_roots(chain, lines, count, nn, x_max, limit, NULL, found_roots, error, size)) != ERROR_NONE) {
        free_all(lines, first, found_roots);
        return status;
    }
    for (c = 0; c < m && status == ERROR_NONE; c++) {
        const RotorRoots *roots = &found_roots[first[c]];
        int standstill = cases[c].s == 0.0 && cases[c].o == 0.0, i;
        if (standstill) {
            status = take(roots, NULL, n, &forward[c], error, size);
            status = status != ERROR_NONE ? status : take(roots, NULL, n, &backward[c], error, size);
        } else if (iso) {
            status = take(roots, NULL, n, &forward[c], error, size);
            status = status != ERROR_NONE ? status : take(roots + 1, NULL, n, &backward[c], error, size);
        } else {
            kinds = malloc((size_t)(2 * roots->count + 2));
            if (kinds == NULL) {
                ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
                status = ERROR_VALUE;
                break;
            }
            for (i = 0; i < roots->count && status == ERROR_NONE; i++) {
                double x = roots->x[i];
                kinds[i] = chain_forward_fraction(chain, cases[c].w * x, cases[c].s * x + cases[c].o) >= 0.5;
                kinds[roots->count + i] = !kinds[i];
                status = budget_left(chain, error, size);
            }
            if (status != ERROR_NONE) {
                free(kinds);
                kinds = NULL;
                break;
            }
            status = take(roots, kinds, n, &forward[c], error, size);
            status = status != ERROR_NONE ? status : take(roots, kinds + roots->count, n, &backward[c], error, size);
            free(kinds);
            kinds = NULL;
        }
    }
    rotor_roots_free(found_roots, count);
    free_all(lines, first, found_roots);
    if (status != ERROR_NONE) {
        rotor_roots_free(forward, m);
        rotor_roots_free(backward, m);
        return status;
    }
    return ERROR_NONE;
}

ErrorKind rotor_roots_by_whirl(const Chain *chain, const RotorLine *cases, int m, int n, double x_max, double limit,
                               RotorRoots *forward, RotorRoots *backward, char *error, size_t size)
{
    return roots_by_whirl(chain, cases, m, n == 0 ? N_NONE : n, x_max, limit, forward, backward, error, size);
}

/* sorted(..., key=lambda r: (r.spin, r.order)) keeps the given order among equal keys */
typedef struct {
    OrderResonance resonance;
    int index;
} Ranked;

static int compare_ranked(const void *a, const void *b)
{
    const Ranked *x = a, *y = b;
    if (x->resonance.spin != y->resonance.spin) {
        return x->resonance.spin < y->resonance.spin ? -1 : 1;
    }
    if (x->resonance.order != y->resonance.order) {
        return x->resonance.order < y->resonance.order ? -1 : 1;
    }
    return (x->index > y->index) - (x->index < y->index);
}

/* Driveline.order_resonances with n = N_NONE for None and spin_max = 0 for None; returns as
 * rotor_order_resonances */
static ErrorKind order_resonances(const Chain *chain, const int *orders, int n_orders, int whirls, int n,
                                  double spin_max, double limit, OrderResonance **out, int *count, char *error,
                                  size_t size)
{
    RotorLine *cases;
    RotorRoots *forward, *backward;
    Ranked *ranked;
    int k, i, total = 0, at = 0;
    ErrorKind failed;
    *out = NULL;
    *count = 0;
    if (spin_max != 0.0 && (!(spin_max > 0.0) || isinf(spin_max))) {
        return speed_error("spin_max", spin_max, error, size);
    }
    for (k = 0; k < n_orders; k++) {
        if (orders[k] < 1) {
            if (error != NULL && size > 0) {
                snprintf(error, size, "order must be a positive integer, got %d", orders[k]);
            }
            return ERROR_VALUE;
        }
    }
    if (n_orders < 1) {
        return ERROR_NONE;
    }
    cases = malloc((size_t)n_orders * sizeof *cases);
    forward = malloc((size_t)n_orders * sizeof *forward);
    backward = malloc((size_t)n_orders * sizeof *backward);
    if (cases == NULL || forward == NULL || backward == NULL) {
        free_all(cases, forward, backward);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    for (k = 0; k < n_orders; k++) {
        cases[k].w = orders[k];
        cases[k].s = 1.0;
        cases[k].o = 0.0;
    }
    if ((failed = roots_by_whirl(chain, cases, n_orders, n, spin_max, limit, forward, backward, error, size)) !=
        ERROR_NONE) {
        free_all(cases, forward, backward);
        return failed;
    }
    for (k = 0; k < n_orders; k++) {
        total += (whirls & WHIRL_FORWARD ? forward[k].count : 0) + (whirls & WHIRL_BACKWARD ? backward[k].count : 0);
    }
    ranked = malloc((size_t)(total > 0 ? total : 1) * sizeof *ranked);
    *out = malloc((size_t)(total > 0 ? total : 1) * sizeof **out);
    if (ranked == NULL || *out == NULL) {
        free(ranked);
        free(*out);
        *out = NULL;
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        total = -1;
    }
    for (k = 0; k < n_orders && total >= 0; k++) {
        const RotorRoots *senses[2] = {&forward[k], &backward[k]};
        int s;
        for (s = 0; s < 2; s++) {
            if (!(whirls & (s == 0 ? WHIRL_FORWARD : WHIRL_BACKWARD))) {
                continue;
            }
            for (i = 0; i < senses[s]->count; i++) {
                ranked[at].resonance.order = orders[k];
                ranked[at].resonance.whirl = s == 0 ? 1 : -1;
                ranked[at].resonance.spin = senses[s]->x[i];
                ranked[at].index = at;
                at++;
            }
        }
    }
    rotor_roots_free(forward, n_orders);
    rotor_roots_free(backward, n_orders);
    free_all(cases, forward, backward);
    if (total < 0) { /* out of memory */
        return ERROR_VALUE;
    }
    qsort(ranked, (size_t)total, sizeof *ranked, compare_ranked);
    for (i = 0; i < total; i++) {
        (*out)[i] = ranked[i].resonance;
    }
    free(ranked);
    *count = total;
    return ERROR_NONE;
}

ErrorKind rotor_order_resonances(const Chain *chain, const int *orders, int n_orders, int whirls, int n,
                                 double spin_max, double limit, OrderResonance **found_out, int *count, char *error,
                                 size_t size)
{
    return order_resonances(chain, orders, n_orders, whirls, n == 0 ? N_NONE : n, spin_max, limit, found_out, count,
                            error, size);
}

typedef struct {
    double spin, share;
} Share;

static int compare_shares(const void *a, const void *b)
{
    const Share *x = a, *y = b;
    if (x->spin != y->spin) {
        return x->spin < y->spin ? -1 : 1;
    }
    return (x->share > y->share) - (x->share < y->share);
}

/* Driveline.critical_speeds(n) = unbalance_critical_speeds(n): isotropic, the forward synchronous roots;
 * anisotropic, those of the 2 (n + 1) lowest synchronous roots whose forward share is at least
 * EXCITED_SHARE. */
ErrorKind rotor_critical_speeds(const Chain *chain, int n, double *spins, int *count, char *error, size_t size)
{
    static const int first_order[1] = {1};
    OrderResonance *found_list = NULL;
    int found_count = 0, i;
    ErrorKind failed;
    *count = 0;
    if (chain_isotropic(chain)) {
        if ((failed = order_resonances(chain, first_order, 1, WHIRL_FORWARD, n, 0.0, ROTOR_DRIVELINE_SEARCH_LIMIT,
                                       &found_list, &found_count, error, size)) != ERROR_NONE) {
            return failed;
        }
        for (i = 0; i < found_count && i < n; i++) {
            spins[(*count)++] = found_list[i].spin;
        }
    } else {
        Share *shares;
        if ((failed = order_resonances(chain, first_order, 1, WHIRL_FORWARD | WHIRL_BACKWARD, n + 1, 0.0,
                                       ROTOR_DRIVELINE_SEARCH_LIMIT, &found_list, &found_count, error, size)) !=
            ERROR_NONE) {
            return failed;
        }
        shares = malloc((size_t)(found_count > 0 ? found_count : 1) * sizeof *shares);
        if (shares == NULL) {
            free(found_list);
            ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
            return ERROR_VALUE;
        }
        for (i = 0; i < found_count; i++) {
            shares[i].spin = found_list[i].spin;
            shares[i].share = chain_forward_fraction(chain, found_list[i].spin, found_list[i].spin);
            if ((failed = budget_left(chain, error, size)) != ERROR_NONE) {
                free(shares);
                free(found_list);
                return failed;
            }
        }
        qsort(shares, (size_t)found_count, sizeof *shares, compare_shares);
        for (i = 0; i < found_count && *count < n; i++) {
            if (shares[i].share >= ROTOR_DRIVELINE_EXCITED_SHARE) {
                spins[(*count)++] = shares[i].spin;
            }
        }
        free(shares);
    }
    free(found_list);
    return ERROR_NONE;
}
