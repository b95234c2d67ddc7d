/* Campbell data by branch (campbell.py) and the Campbell table of model.whirl_table.
 *
 * Every whirl branch is followed from one speed to the next, splined alone, and the branches of each
 * whirl sense are sorted only when the table is evaluated; where a branch's spline errs, the middle
 * of the interval is added to the speeds (campbell.whirl_branches). Anisotropic drivelines give the
 * sorted table of Driveline.campbell, one column per rank.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rotor.h"

struct WhirlTable {
    CubicSpline spline; /* forward columns first, then backward */
    int forward, n_modes;
};

/* Speeds with the forward (sense 0) and backward (sense 1) whirl frequencies found at each. */
typedef struct {
    int count;
    double *spin;
    RotorRoots *roots[2];
} Found;

/* One whirl sense's branches: ``columns`` per speed, row-major over the speeds, NaN where absent. */
typedef struct {
    int columns;
    double *value;
} Branches;

/* The message of a failed allocation; ERROR_VALUE, as the FMU reports it */
static ErrorKind out_of_memory(char *error, size_t size)
{
    snprintf(error, size, "out of memory");
    return ERROR_VALUE;
}

static void found_free(Found *found)
{
    for (int s = 0; s < 2; ++s) {
        if (found->roots[s]) {
            rotor_roots_free(found->roots[s], found->count);
        }
        free(found->roots[s]);
        found->roots[s] = NULL;
    }
    free(found->spin);
    found->spin = NULL;
    found->count = 0;
}

/* 0, or -1 without memory (the caller writes the message) */
static int found_alloc(Found *found, int count)
{
    found->count = count;
    found->spin = malloc((size_t)count * sizeof *found->spin);
    found->roots[0] = calloc((size_t)count, sizeof *found->roots[0]);
    found->roots[1] = calloc((size_t)count, sizeof *found->roots[1]);
    if (!found->spin || !found->roots[0] || !found->roots[1]) {
        free(found->spin);
        free(found->roots[0]);
        free(found->roots[1]);
        found->spin = NULL;
        found->roots[0] = found->roots[1] = NULL;
        found->count = 0;
        return -1;
    }
    return 0;
}

/* campbell._roots_over_speeds: the whirl frequencies up to ``x_hi`` at the ``count`` speeds
 * ``spin``, searched on bare-shaft grids; with ``neighbours`` NULL checked against the full grid at
 * the first speed and between consecutive speeds, otherwise against the counts of the known speeds
 * below and above each new one, ``neighbours`` (count x 2 x 2: speed, below/above, sense). A failed
 * check searches every speed on the full grid. ``out`` gets the speeds and their roots. ERROR_NONE,
 * or the failure's kind with the message. */
static ErrorKind roots_over_speeds(const Chain *chain, const double *spin, int count, double x_hi,
                                   const int *neighbours, Found *out, char *error, size_t size)
{
    int lines_n = 2 * count, total = lines_n + (neighbours ? 0 : 2);
    *out = (Found){0, NULL, {NULL, NULL}};
    RotorLine *lines = malloc((size_t)total * sizeof *lines);
    unsigned char *coarse = malloc((size_t)total);
    RotorRoots *roots = calloc((size_t)total, sizeof *roots);
    int failed = 0;
    ErrorKind status;
    if (!lines || !coarse || !roots || found_alloc(out, count)) {
        free(lines);
        free(coarse);
        free(roots);
        found_free(out);
        return out_of_memory(error, size);
    }
    memcpy(out->spin, spin, (size_t)count * sizeof *spin);
    for (int i = 0; i < total; ++i) {
        int speed = i < lines_n ? i / 2 : 0;
        lines[i].w = i % 2 ? -1.0 : 1.0;
        lines[i].s = 0.0;
        lines[i].o = spin[speed];
        coarse[i] = (unsigned char)(i < lines_n);
    }
    status = rotor_line_roots(chain, lines, total, 0, x_hi, ROTOR_DRIVELINE_SEARCH_LIMIT, coarse, roots, error, size);
    if (status != ERROR_NONE) {
        goto done;
    }
    for (int i = 0; i < count && !failed; ++i) {
        for (int s = 0; s < 2; ++s) {
            int here = roots[2 * i + s].count;
            if (!neighbours) {
                if ((i == 0 && here != roots[lines_n + s].count) ||
                    (i > 0 && abs(here - roots[2 * (i - 1) + s].count) > 1)) {
                    failed = 1;
                }
            } else if (abs(here - neighbours[4 * i + s]) > 1 || abs(here - neighbours[4 * i + 2 + s]) > 1) {
                failed = 1;
            }
        }
    }
    if (failed) {
        rotor_roots_free(roots, total);
        memset(roots, 0, (size_t)total * sizeof *roots);
        status = rotor_line_roots(chain, lines, lines_n, 0, x_hi, ROTOR_DRIVELINE_SEARCH_LIMIT, NULL, roots, error,
                                  size);
        if (status != ERROR_NONE) {
            goto done;
        }
        total = lines_n;
    }
    for (int i = 0; i < count; ++i) {
        for (int s = 0; s < 2; ++s) {
            out->roots[s][i] = roots[2 * i + s];
            roots[2 * i + s].count = 0;
            roots[2 * i + s].x = NULL;
        }
    }
done:
    rotor_roots_free(roots, total);
    free(roots);
    free(lines);
    free(coarse);
    if (status != ERROR_NONE) {
        found_free(out);
    }
    return status;
}

/* campbell._slopes: dw/dOmega = -f_Omega / f_w of every root (central differences), 0 where undefined;
 * ``slopes[s]`` lists sense s's roots speed by speed. ERROR_NONE, or ERROR_VALUE out of memory. */
static ErrorKind slopes_of(const Chain *chain, const Found *found, double *slopes[2], char *error, size_t size)
{
    size_t n[2] = {0, 0};
    for (int s = 0; s < 2; ++s) {
        for (int i = 0; i < found->count; ++i) {
            n[s] += (size_t)found->roots[s][i].count;
        }
    }
    size_t all = n[0] + n[1];
    slopes[0] = malloc((n[0] + 1) * sizeof *slopes[0]);
    slopes[1] = malloc((n[1] + 1) * sizeof *slopes[1]);
    double *w = malloc((4 * all + 1) * sizeof *w);
    double *spin = malloc((4 * all + 1) * sizeof *spin);
    double *f = malloc((4 * all + 1) * sizeof *f);
    if (!slopes[0] || !slopes[1] || !w || !spin || !f) {
        free(slopes[0]);
        free(slopes[1]);
        slopes[0] = slopes[1] = NULL;
        free(w);
        free(spin);
        free(f);
        return out_of_memory(error, size);
    }
    size_t k = 0;
    for (int s = 0; s < 2; ++s) {
        double sign = s ? -1.0 : 1.0;
        for (int i = 0; i < found->count; ++i) {
            const RotorRoots *r = &found->roots[s][i];
            for (int j = 0; j < r->count; ++j, ++k) {
                double x = r->x[j], h = ROTOR_CAMPBELL_SLOPE_STEP * x, o = found->spin[i];
                w[4 * k] = sign * (x + h);
                spin[4 * k] = o;
                w[4 * k + 1] = sign * (x - h);
                spin[4 * k + 1] = o;
                w[4 * k + 2] = sign * x;
                spin[4 * k + 2] = o + h;
                w[4 * k + 3] = sign * x;
                spin[4 * k + 3] = o - h;
            }
        }
    }
    chain_determinant(chain, 4 * all, w, spin, f);
    for (k = 0; k < all; ++k) {
        double slope = -(f[4 * k + 2] - f[4 * k + 3]) / (f[4 * k] - f[4 * k + 1]);
        slope = isfinite(slope) ? slope : 0.0;
        if (k < n[0]) {
            slopes[0][k] = slope;
        } else {
            slopes[1][k - n[0]] = slope;
        }
    }
    free(w);
    free(spin);
    free(f);
    if (chain_budget_spent(chain)) {
        ROTOR_ERROR(error, size, ROTOR_BUDGET_SPENT);
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

/* numpy's float order: NaN after every number */
static int before(double a, double b)
{
    return a < b || (!isnan(a) && isnan(b));
}

/* campbell._follow: the columns of the branches through one sense's roots, each root moved on by its
 * slope to the next speed, the predicted positions in their order taking the roots found there in
 * theirs; only branches among the first ``n_modes`` at some speed. ERROR_NONE, or ERROR_VALUE out of
 * memory. */
static ErrorKind follow(const Found *found, int sense, const double *slopes, int n_modes, Branches *out, char *error,
                        size_t size)
{
    const RotorRoots *roots = found->roots[sense];
    int speeds = found->count;
    size_t total = 0, widest = 1;
    for (int i = 0; i < speeds; ++i) {
        total += (size_t)roots[i].count;
        widest = (size_t)roots[i].count > widest ? (size_t)roots[i].count : widest;
    }
    int *ids = malloc((total + 1) * sizeof *ids); /* the branch of every root, speed by speed */
    int *order = malloc(widest * sizeof *order);
    double *predicted = malloc(widest * sizeof *predicted);
    int *column = malloc((total + 1) * sizeof *column);
    out->columns = 0;
    out->value = NULL;
    if (!ids || !order || !predicted || !column) {
        free(ids);
        free(order);
        free(predicted);
        free(column);
        return out_of_memory(error, size);
    }
    int count = roots[0].count;
    for (int j = 0; j < count; ++j) {
        ids[j] = j;
    }
    size_t at = 0; /* where speed i's ids start */
    for (int i = 0; i + 1 < speeds; ++i) {
        int here = roots[i].count, next = roots[i + 1].count;
        double step = found->spin[i + 1] - found->spin[i];
        for (int j = 0; j < here; ++j) { /* a stable argsort by insertion */
            int k = j;
            predicted[j] = roots[i].x[j] + slopes[at + (size_t)j] * step;
            while (k > 0 && before(predicted[j], predicted[order[k - 1]])) {
                order[k] = order[k - 1];
                --k;
            }
            order[k] = j;
        }
        int kept = here < next ? here : next;
        size_t to = at + (size_t)here;
        for (int j = 0; j < kept; ++j) {
            ids[to + (size_t)j] = ids[at + (size_t)order[j]];
        }
        for (int j = kept; j < next; ++j) {
            ids[to + (size_t)j] = count + (j - kept);
        }
        count += next - kept;
        at = to;
    }
    for (int b = 0; b < count; ++b) {
        column[b] = -1;
    }
    at = 0;
    for (int i = 0; i < speeds; ++i) {
        for (int j = 0; j < roots[i].count && j < n_modes; ++j) {
            column[ids[at + (size_t)j]] = 0;
        }
        at += (size_t)roots[i].count;
    }
    int used = 0;
    for (int b = 0; b < count; ++b) { /* np.unique: ascending branch ids */
        if (column[b] == 0) {
            column[b] = used++;
        }
    }
    out->value = malloc(((size_t)speeds * (size_t)used + 1) * sizeof *out->value);
    if (!out->value) {
        free(ids);
        free(order);
        free(predicted);
        free(column);
        return out_of_memory(error, size);
    }
    out->columns = used;
    for (size_t v = 0; v < (size_t)speeds * (size_t)used; ++v) {
        out->value[v] = NAN;
    }
    at = 0;
    for (int i = 0; i < speeds; ++i) {
        for (int j = 0; j < roots[i].count; ++j) {
            int c = column[ids[at + (size_t)j]];
            if (c >= 0) {
                out->value[(size_t)i * used + c] = roots[i].x[j];
            }
        }
        at += (size_t)roots[i].count;
    }
    free(ids);
    free(order);
    free(predicted);
    free(column);
    return ERROR_NONE;
}

/* Both senses' branches side by side, row-major over the speeds (forward columns first); NaN in a
 * branch reads as ``missing`` unless ``missing`` is NaN, and each sense short of ``pad`` columns
 * gets constant ones at ``missing``. *columns is the total, *forward the forward columns. */
static double *side_by_side(const Branches branches[2], int speeds, int pad, double missing, int *columns,
                            int *forward)
{
    int width[2];
    for (int s = 0; s < 2; ++s) {
        width[s] = branches[s].columns > pad ? branches[s].columns : pad;
    }
    int m = width[0] + width[1];
    double *table = malloc(((size_t)speeds * (size_t)m + 1) * sizeof *table);
    if (!table) {
        return NULL;
    }
    for (int i = 0; i < speeds; ++i) {
        double *row = table + (size_t)i * m;
        for (int s = 0; s < 2; ++s) {
            for (int c = 0; c < width[s]; ++c) {
                double v = c < branches[s].columns ? branches[s].value[(size_t)i * branches[s].columns + c] : missing;
                row[(s ? width[0] : 0) + c] = isnan(v) ? missing : v;
            }
        }
    }
    *columns = m;
    *forward = width[0];
    return table;
}

/* campbell._spline_error: the relative error of the branches' splines at the middle of every knot
 * interval (largest of all branches) by one Newton step on the determinant there, zero within NOISE
 * times the same step at the interval's ends; ``error_of`` has count - 1 entries. A branch missing at
 * some speed (NaN) has no spline and contributes no error. ERROR_NONE, or ERROR_VALUE out of memory. */
static ErrorKind spline_error(const Chain *chain, const Found *found, const Branches branches[2], double *error_of,
                              char *error, size_t size)
{
    int knots = found->count, m, forward;
    for (int i = 0; i + 1 < knots; ++i) {
        error_of[i] = 0.0;
    }
    if (branches[0].columns + branches[1].columns == 0) {
        return ERROR_NONE;
    }
    double *table = side_by_side(branches, knots, 0, NAN, &m, &forward);
    CubicSpline spline;
    if (!table) {
        return out_of_memory(error, size);
    }
    int kept = 0, kept_forward = 0;
    for (int c = 0; c < m; ++c) { /* the complete columns, in their order, moved to the left */
        int complete = 1;
        for (int i = 0; i < knots && complete; ++i) {
            complete = !isnan(table[(size_t)i * m + c]);
        }
        if (complete) {
            for (int i = 0; i < knots; ++i) {
                table[(size_t)i * m + kept] = table[(size_t)i * m + c];
            }
            kept_forward += c < forward;
            ++kept;
        }
    }
    for (int i = 0; i < knots; ++i) { /* rows of ``kept`` columns */
        memmove(table + (size_t)i * kept, table + (size_t)i * m, (size_t)kept * sizeof *table);
    }
    m = kept;
    forward = kept_forward;
    if (m == 0) {
        free(table);
        return ERROR_NONE;
    }
    if (cubic_spline_build(&spline, knots, found->spin, m, table)) {
        free(table);
        return out_of_memory(error, size);
    }
    free(table);
    int points = 2 * knots - 1;
    ErrorKind status = ERROR_NONE;
    size_t cells = (size_t)points * (size_t)m;
    double *w = malloc(cells * sizeof *w);
    double *step = malloc(cells * sizeof *step);
    double *at_w = malloc(3 * cells * sizeof *at_w);
    double *at_spin = malloc(3 * cells * sizeof *at_spin);
    double *f = malloc(3 * cells * sizeof *f);
    if (!w || !step || !at_w || !at_spin || !f) {
        status = out_of_memory(error, size);
    } else {
        size_t n = 0;
        for (int p = 0; p < points; ++p) { /* the middles, then the knots */
            double at = p < knots - 1 ? 0.5 * (found->spin[p] + found->spin[p + 1]) : found->spin[p - (knots - 1)];
            double *row = w + (size_t)p * m;
            cubic_spline_evaluate(&spline, at, row);
            for (int c = 0; c < m; ++c, ++n) {
                double sign = c < forward ? 1.0 : -1.0, h = ROTOR_CAMPBELL_SLOPE_STEP * row[c];
                at_w[3 * n] = sign * row[c];
                at_w[3 * n + 1] = sign * (row[c] + h);
                at_w[3 * n + 2] = sign * (row[c] - h);
                at_spin[3 * n] = at_spin[3 * n + 1] = at_spin[3 * n + 2] = at;
            }
        }
        chain_determinant(chain, 3 * cells, at_w, at_spin, f);
        for (n = 0; n < cells; ++n) {
            double x = w[n], h = ROTOR_CAMPBELL_SLOPE_STEP * x;
            double estimate = fabs(f[3 * n] * 2.0 * h / (f[3 * n + 1] - f[3 * n + 2])) / x;
            step[n] = isfinite(estimate) ? estimate : 0.0;
        }
        for (int i = 0; i + 1 < knots; ++i) {
            const double *middle = step + (size_t)i * m, *lo = step + (size_t)(knots - 1 + i) * m, *hi = lo + m;
            for (int c = 0; c < m; ++c) {
                double noise = ROTOR_CAMPBELL_NOISE * (lo[c] > hi[c] ? lo[c] : hi[c]);
                double e = middle[c] > noise ? middle[c] : 0.0;
                error_of[i] = e > error_of[i] ? e : error_of[i];
            }
        }
    }
    free(w);
    free(step);
    free(at_w);
    free(at_spin);
    free(f);
    cubic_spline_free(&spline);
    if (status == ERROR_NONE && chain_budget_spent(chain)) {
        ROTOR_ERROR(error, size, ROTOR_BUDGET_SPENT);
        status = ERROR_VALUE;
    }
    return status;
}

/* campbell._insert (and np.insert of the speeds): ``added`` speed k after old speed ``rough[k]``;
 * the roots move into ``found`` and ``added`` is left empty. ERROR_NONE, or ERROR_VALUE out of memory. */
static ErrorKind insert_speeds(Found *found, Found *added, const int *rough, char *error, size_t size)
{
    Found merged;
    if (found_alloc(&merged, found->count + added->count)) {
        return out_of_memory(error, size);
    }
    int k = 0, to = 0;
    for (int i = 0; i < found->count; ++i) {
        merged.spin[to] = found->spin[i];
        merged.roots[0][to] = found->roots[0][i];
        merged.roots[1][to++] = found->roots[1][i];
        if (k < added->count && rough[k] == i) {
            merged.spin[to] = added->spin[k];
            merged.roots[0][to] = added->roots[0][k];
            merged.roots[1][to++] = added->roots[1][k++];
        }
    }
    for (int s = 0; s < 2; ++s) { /* ownership moved: free the arrays alone */
        free(found->roots[s]);
        free(added->roots[s]);
        added->roots[s] = NULL;
    }
    free(found->spin);
    free(added->spin);
    added->spin = NULL;
    added->count = 0;
    *found = merged;
    return ERROR_NONE;
}

static void branches_free(Branches branches[2])
{
    for (int s = 0; s < 2; ++s) {
        free(branches[s].value);
        branches[s].value = NULL;
        branches[s].columns = 0;
    }
}

/* Both senses' branches through ``found`` (campbell._slopes and _follow); ERROR_NONE, or the failure's
 * kind with the message */
static ErrorKind follow_both(const Chain *chain, const Found *found, int n_modes, Branches branches[2], char *error,
                             size_t size)
{
    double *slopes[2] = {NULL, NULL};
    ErrorKind status = slopes_of(chain, found, slopes, error, size);
    if (status != ERROR_NONE) {
        return status;
    }
    for (int s = 0; s < 2 && status == ERROR_NONE; ++s) {
        status = follow(found, s, slopes[s], n_modes, &branches[s], error, size);
    }
    free(slopes[0]);
    free(slopes[1]);
    if (status != ERROR_NONE) {
        branches_free(branches);
    }
    return status;
}

/* No branch of either sense missing at any of the ``knots`` speeds (none crosses the search bound). */
static int branches_complete(const Branches branches[2], int knots)
{
    for (int s = 0; s < 2; ++s) {
        for (size_t v = 0; v < (size_t)knots * (size_t)branches[s].columns; ++v) {
            if (isnan(branches[s].value[v])) {
                return 0;
            }
        }
    }
    return 1;
}

/* One round of refinement (the body of whirl_branches' inner loop after _follow): the middles of the
 * intervals whose splines err searched and inserted; *refined 0 when no interval errs. ERROR_NONE, or
 * the failure's kind with the message. */
static ErrorKind refine(const Chain *chain, Found *found, const Branches branches[2], double x_hi, int *refined,
                        char *error, size_t size)
{
    int knots = found->count, n_rough = 0;
    ErrorKind status;
    double *error_of = malloc((size_t)knots * sizeof *error_of);
    int *rough = malloc((size_t)knots * sizeof *rough);
    double *middles = malloc((size_t)knots * sizeof *middles);
    int *neighbours = malloc(4 * (size_t)knots * sizeof *neighbours);
    Found added = {0, NULL, {NULL, NULL}};
    *refined = 0;
    if (!error_of || !rough || !middles || !neighbours) {
        status = out_of_memory(error, size);
        goto done;
    }
    if ((status = spline_error(chain, found, branches, error_of, error, size)) != ERROR_NONE) {
        goto done;
    }
    for (int i = 0; i + 1 < knots; ++i) {
        if (error_of[i] > ROTOR_CAMPBELL_SPLINE_RTOL) {
            rough[n_rough] = i;
            middles[n_rough] = 0.5 * (found->spin[i] + found->spin[i + 1]);
            for (int side = 0; side < 2; ++side) {
                for (int s = 0; s < 2; ++s) {
                    neighbours[4 * n_rough + 2 * side + s] = found->roots[s][i + side].count;
                }
            }
            ++n_rough;
        }
    }
    if (n_rough) {
        if ((status = roots_over_speeds(chain, middles, n_rough, x_hi, neighbours, &added, error, size)) !=
                ERROR_NONE ||
            (status = insert_speeds(found, &added, rough, error, size)) != ERROR_NONE) {
            goto done;
        }
        *refined = 1;
    }
done:
    found_free(&added);
    free(error_of);
    free(rough);
    free(middles);
    free(neighbours);
    return status;
}

/* campbell.whirl_branches for an isotropic chain: the branches over the refined speeds in ``found``;
 * ERROR_NONE, or the failure's kind with the message. */
static ErrorKind isotropic_branches(const Chain *chain, const double *spins, int points, int n_modes, Found *found,
                                    Branches branches[2], char *error, size_t size)
{
    double reach = (n_modes + 2) * FMU_PI / chain_kappa(chain);
    double x_hi = fmin(reach * reach, ROTOR_DRIVELINE_SEARCH_LIMIT);
    ErrorKind failed;
    for (;;) {
        int final = 0;
        if ((failed = roots_over_speeds(chain, spins, points, x_hi, NULL, found, error, size)) != ERROR_NONE) {
            return failed;
        }
        for (int round = 0; round <= ROTOR_CAMPBELL_REFINEMENTS; ++round) {
            int refined;
            if ((failed = follow_both(chain, found, n_modes, branches, error, size)) != ERROR_NONE) {
                found_free(found);
                return failed;
            }
            int enough = 1;
            for (int s = 0; s < 2; ++s) {
                for (int i = 0; i < found->count; ++i) {
                    enough = enough && found->roots[s][i].count >= n_modes;
                }
            }
            final = x_hi >= ROTOR_DRIVELINE_SEARCH_LIMIT || (enough && branches_complete(branches, found->count));
            if (round == ROTOR_CAMPBELL_REFINEMENTS || found->count > ROTOR_CAMPBELL_MAX_KNOTS || !final) {
                break; /* a round to be widened restarts from ``spins``: refining it is wasted */
            }
            if ((failed = refine(chain, found, branches, x_hi, &refined, error, size)) != ERROR_NONE) {
                branches_free(branches);
                found_free(found);
                return failed;
            }
            if (!refined) {
                break;
            }
            branches_free(branches);
        }
        if (final) {
            return ERROR_NONE;
        }
        branches_free(branches);
        found_free(found);
        x_hi = fmin(4.0 * x_hi, ROTOR_DRIVELINE_SEARCH_LIMIT);
    }
}

/* Driveline.campbell: the first ``n_modes`` forward and backward whirl frequencies at every speed
 * (NaN where absent), one column per rank. ERROR_NONE, or the failure's kind with the message. */
static ErrorKind sorted_table(const Chain *chain, const double *spins, int points, int n_modes, Branches branches[2],
                              char *error, size_t size)
{
    RotorLine *cases = malloc((size_t)points * sizeof *cases);
    RotorRoots *roots[2];
    roots[0] = calloc((size_t)points, sizeof *roots[0]);
    roots[1] = calloc((size_t)points, sizeof *roots[1]);
    ErrorKind status;
    for (int s = 0; s < 2; ++s) {
        branches[s].columns = n_modes;
        branches[s].value = malloc((size_t)points * (size_t)n_modes * sizeof *branches[s].value);
    }
    if (!cases || !roots[0] || !roots[1] || !branches[0].value || !branches[1].value) {
        status = out_of_memory(error, size);
        goto done;
    }
    for (int i = 0; i < points; ++i) {
        cases[i].w = 1.0;
        cases[i].s = 0.0;
        cases[i].o = spins[i];
    }
    status = rotor_roots_by_whirl(chain, cases, points, n_modes, 0.0, ROTOR_DRIVELINE_SEARCH_LIMIT, roots[0], roots[1],
                                  error, size);
    if (status != ERROR_NONE) {
        goto done;
    }
    for (int s = 0; s < 2; ++s) {
        for (int i = 0; i < points; ++i) {
            for (int c = 0; c < n_modes; ++c) {
                branches[s].value[(size_t)i * n_modes + c] = c < roots[s][i].count ? roots[s][i].x[c] : NAN;
            }
        }
    }
done:
    for (int s = 0; s < 2; ++s) {
        if (roots[s]) {
            rotor_roots_free(roots[s], points);
        }
        free(roots[s]);
    }
    free(cases);
    if (status != ERROR_NONE) {
        branches_free(branches);
    }
    return status;
}

/* model.whirl_table without the plausibility check: WhirlTable(whirl_branches(driveline,
 * linspace(0, omega_max, points), n_modes), n_modes, SEARCH_LIMIT). */
ErrorKind whirl_table_new(const Chain *chain, double omega_max, int points, int n_modes, WhirlTable **out, char *error,
                          size_t size)
{
    *out = NULL;
    if (n_modes < 1) {
        snprintf(error, size, "n_modes must be a positive integer, got %d", n_modes);
        return ERROR_VALUE;
    }
    if (points < 2 || !isfinite(omega_max)) {
        snprintf(error, size, "spins must be at least two increasing finite speeds >= 0 rad/s");
        return ERROR_VALUE;
    }
    double *spins = malloc((size_t)points * sizeof *spins);
    WhirlTable *table = calloc(1, sizeof *table);
    if (!spins || !table) {
        free(spins);
        free(table);
        return out_of_memory(error, size);
    }
    double step = omega_max / (points - 1); /* np.linspace: start + i step, the end exact */
    for (int i = 0; i < points; ++i) {
        spins[i] = i + 1 < points ? i * step : omega_max;
    }
    for (int i = 1; i < points; ++i) {
        if (!(spins[i] > spins[i - 1])) {
            snprintf(error, size, "spins must be at least two increasing finite speeds >= 0 rad/s");
            free(spins);
            free(table);
            return ERROR_VALUE;
        }
    }
    Found found = {0, NULL, {NULL, NULL}};
    Branches branches[2] = {{0, NULL}, {0, NULL}};
    const double *knots = spins;
    int count = points;
    ErrorKind status;
    if (chain_isotropic(chain)) {
        status = isotropic_branches(chain, spins, points, n_modes, &found, branches, error, size);
        knots = found.spin;
        count = found.count;
    } else {
        status = sorted_table(chain, spins, points, n_modes, branches, error, size);
    }
    if (status == ERROR_NONE) { /* WhirlTable.__init__ */
        int m;
        double *values = side_by_side(branches, count, n_modes, ROTOR_DRIVELINE_SEARCH_LIMIT, &m, &table->forward);
        if (values == NULL || cubic_spline_build(&table->spline, count, knots, m, values) != 0) {
            status = out_of_memory(error, size);
        }
        free(values);
    }
    table->n_modes = n_modes;
    branches_free(branches);
    found_free(&found);
    free(spins);
    if (status != ERROR_NONE) {
        free(table);
        return status;
    }
    *out = table;
    return ERROR_NONE;
}

/* The first ``n`` of columns [first, end) at ``speed``, ascending (np.sort(...)[:n], NaN last); with
 * ``slopes`` (NULL: none) the derivative in the speed of the column each value comes from. */
static void smallest(const CubicSpline *spline, double speed, int first, int end, int n, double *out, double *slopes)
{
    int filled = 0;
    for (int c = first; c < end; ++c) {
        double v = cubic_spline_value(spline, speed, c);
        int k = filled < n ? filled++ : n;
        while (k > 0 && before(v, out[k - 1])) {
            if (k < n) {
                out[k] = out[k - 1];
                if (slopes) {
                    slopes[k] = slopes[k - 1];
                }
            }
            --k;
        }
        if (k < n) {
            out[k] = v;
            if (slopes) {
                slopes[k] = cubic_spline_slope(spline, speed, c);
            }
        }
    }
}

/* WhirlTable.__call__ */
void whirl_table_evaluate(const WhirlTable *table, double speed, double *out)
{
    smallest(&table->spline, speed, 0, table->forward, table->n_modes, out, NULL);
    smallest(&table->spline, speed, table->forward, table->spline.m, table->n_modes, out + table->n_modes, NULL);
}

void whirl_table_slopes(const WhirlTable *table, double speed, double *out, double *slopes)
{
    int n = table->n_modes;
    smallest(&table->spline, speed, 0, table->forward, n, out, slopes);
    smallest(&table->spline, speed, table->forward, table->spline.m, n, out + n, slopes + n);
}

int whirl_table_knots(const WhirlTable *table)
{
    return table->spline.n;
}

void whirl_table_free(WhirlTable *table)
{
    if (table) {
        cubic_spline_free(&table->spline);
        free(table);
    }
}
