/* The driveline of a layout: the checks of driveline/rotor/loader.py on the TOML read (toml.c), the
 * element checks of elements.py (elements.c) and Driveline.__post_init__ (driveline.py), with their
 * messages; the one-piece tube. A function of the loader that returns ErrorKind gives ERROR_NONE, or
 * the failure's kind with its message in loader->error: ERROR_VALUE (loader.py raises ValueError, and
 * the FMU reports out of memory as one), but for the length's math.fsum (its own kind). */
#include "elements.h"
#include "lib/toml.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>


/* ---- the loader (loader.py) --------------------------------------------------------------- */

typedef struct {
    const char *name;
    size_t length;
    double E, rho;
} Material;

/* loader._station: node (is_node) or position */
typedef struct {
    int is_node, node;
    double value;
} Station;

static const char *const TOP_KEYS[] = {"bearings", "hinges", "left_end", "masses", "materials", "name",
                                       "right_end", "segments", "unbalances", NULL};
static const char *const MATERIAL_KEYS[] = {"density", "youngs_modulus", NULL};
static const char *const SEGMENT_KEYS[] = {
    "density", "gyroscopic", "inner_diameter", "inner_radius", "label", "length", "material",
    "outer_diameter", "outer_radius", "poisson_ratio", "rotary_inertia", "shear", "wall_thickness",
    "youngs_modulus", NULL};
static const char *const MASS_KEYS[] = {"diametral_inertia", "label", "mass", "node", "polar_inertia", "position",
                                        NULL};
static const char *const BEARING_KEYS[] = {"cxx", "cxy",   "cyx",  "cyy",      "damping",   "kxx", "kxy",
                                           "kyx", "kyy",   "label", "node", "position", "stiffness", NULL};
static const char *const UNBALANCE_KEYS[] = {"amount", "label", "node", "phase", "position", NULL};
static const char *const HINGE_KEYS[] = {"bending_stiffness", "label", "node", "position", NULL};
static const char *const END_NAMES[] = {"free", "pinned", "clamped"};

/* loader._number of an optional key (``fallback`` when absent, as t.layout_get(key, 0.0)) */
static ErrorKind number_or(const Loader *loader, const char *where, const Value *table, const char *key,
                           double fallback, int signed_, double *out)
{
    const Value *value = layout_get(table, key);
    if (value == NULL) {
        *out = fallback;
        return ERROR_NONE;
    }
    return layout_number(loader, where, key, value, 0, signed_, out);
}

static int list_count(const Value *list)
{
    return list == NULL ? 0 : (int)list->count;
}

/* Driveline.length: math.fsum of the segment lengths; ERROR_NONE, or Python's exception */
static ErrorKind segments_length(const Driveline *d, double *sum, const char **message)
{
    return python_fsum_strided(&d->segments[0].length, d->n_segments, sizeof(RotorSegment) / sizeof(double), sum,
                               message);
}

/* Driveline.__post_init__'s checks on the nodes and the unbalances. */
static ErrorKind check_driveline(const Loader *loader, const Driveline *d)
{
    int i;
    double length;
    const char *failure;
    ErrorKind kind = driveline_check_nodes(d, loader->error, loader->size);
    if (kind != ERROR_NONE) {
        return kind;
    }
    kind = segments_length(d, &length, &failure);
    if (kind != ERROR_NONE) { /* math.fsum's OverflowError or ValueError */
        layout_error(loader->error, loader->size, "%s", failure);
        return kind;
    }
    for (i = 0; i < d->n_unbalances; i++) {
        if (d->unbalances[i].position > length) {
            char position[32], end[32];
            python_float_repr(d->unbalances[i].position, position, sizeof position);
            python_float_repr(length, end, sizeof end);
            return layout_error(loader->error, loader->size,
                                "unbalances[%d].position = %s m lies beyond the right end (%s m)",
                        i, position, end);
        }
    }
    return ERROR_NONE;
}

/* loader._materials */
static ErrorKind materials(const Loader *loader, const Value *data, Material **out, int *count)
{
    const Value *table = layout_get(data, "materials");
    const Item *item;
    int n = 0;
    ErrorKind failed;
    *out = NULL;
    *count = 0;
    if (table == NULL) {
        return ERROR_NONE;
    }
    if (table->kind != V_TABLE) {
        return layout_error(loader->error, loader->size,
                            "materials must be a table of named materials ([materials.NAME])");
    }
    *out = arena_alloc(loader->arena, (table->count + 1) * sizeof **out);
    if (*out == NULL) {
        return layout_error(loader->error, loader->size, "out of memory");
    }
    for (item = table->first; item != NULL; item = item->next, n++) {
        const Value *t = item->value, *E, *rho;
        char *where = arena_alloc(loader->arena, item->key_length + 16);
        Material *m = &(*out)[n];
        if (where == NULL) {
            return layout_error(loader->error, loader->size, "out of memory");
        }
        memcpy(where, "materials.", 10);
        memcpy(where + 10, item->key, item->key_length);
        where[10 + item->key_length] = '\0';
        if (t->kind != V_TABLE) {
            return layout_error(loader->error, loader->size, "%s must be a table", where);
        }
        if ((failed = layout_unknown(loader, where, t, MATERIAL_KEYS)) != ERROR_NONE) {
            return failed;
        }
        E = layout_get(t, "youngs_modulus");
        rho = layout_get(t, "density");
        if (rho == NULL || E == NULL) {
            return layout_error(loader->error, loader->size, "%s: missing key %r", where,
                        rho == NULL ? "density" : "youngs_modulus");
        }
        m->name = item->key;
        m->length = item->key_length;
        if ((failed = layout_number(loader, where, "youngs_modulus", E, 1, 0, &m->E)) != ERROR_NONE ||
            (failed = layout_number(loader, where, "density", rho, 1, 0, &m->rho)) != ERROR_NONE) {
            return failed;
        }
        *count = n + 1;
    }
    return ERROR_NONE;
}

/* loader._flag */
static ErrorKind flag(const Loader *loader, const char *where, const Value *t, const char *key, int *out)
{
    const Value *value = layout_get(t, key);
    if (value == NULL) {
        return ERROR_NONE;
    }
    if (value->kind != V_BOOL) {
        return layout_error(loader->error, loader->size, "%s.%s must be true or false, got %v", where, key, value);
    }
    *out = (int)value->integer;
    return ERROR_NONE;
}

/* The known material names, sorted, joined by ", " (or "none defined"). */
static const char *material_names(const Loader *loader, const Material *mats, int count)
{
    size_t total = 16;
    int i, j, *order;
    char *text;
    for (i = 0; i < count; i++) {
        total += mats[i].length + 2;
    }
    text = arena_alloc(loader->arena, total);
    order = arena_alloc(loader->arena, ((size_t)count + 1) * sizeof *order);
    if (text == NULL || order == NULL) {
        return NULL;
    }
    for (i = 0; i < count; i++) { /* insertion sort */
        for (j = i; j > 0 && layout_key_before(mats[i].name, mats[i].length, mats[order[j - 1]].name,
                                        mats[order[j - 1]].length);
             j--) {
            order[j] = order[j - 1];
        }
        order[j] = i;
    }
    text[0] = '\0';
    for (i = 0, total = 0; i < count; i++) {
        if (i > 0) {
            memcpy(text + total, ", ", 2);
            total += 2;
        }
        memcpy(text + total, mats[order[i]].name, mats[order[i]].length);
        total += mats[order[i]].length;
    }
    text[total] = '\0';
    return count > 0 ? text : "none defined";
}

/* loader._segment and ShaftSegment.__post_init__ */
static ErrorKind segment(const Loader *loader, int i, const Value *t, const Material *mats, int n_mats, RotorSegment *s)
{
    static const char *const inner_keys[] = {"inner_diameter", "inner_radius", "wall_thickness"};
    char where[40];
    const char *outer_key = NULL, *inner_key = NULL;
    const Value *value, *nu;
    double d_out, d_in = 0.0, v;
    int have_E = 0, have_rho = 0, k;
    ErrorKind failed;
    snprintf(where, sizeof where, "segments[%d]", i);
    if ((failed = layout_unknown(loader, where, t, SEGMENT_KEYS)) != ERROR_NONE) {
        return failed;
    }
    if (layout_get(t, "length") == NULL) {
        return layout_error(loader->error, loader->size, "%s: missing key 'length'", where);
    }
    if ((failed = layout_number(loader, where, "length", layout_get(t, "length"), 1, 0, &s->length)) != ERROR_NONE) {
        return failed;
    }
    if ((layout_get(t, "outer_diameter") == NULL) == (layout_get(t, "outer_radius") == NULL)) {
        return layout_error(loader->error, loader->size, "%s: give exactly one of 'outer_diameter' or 'outer_radius'",
                            where);
    }
    outer_key = layout_get(t, "outer_diameter") != NULL ? "outer_diameter" : "outer_radius";
    if ((failed = layout_number(loader, where, outer_key, layout_get(t, outer_key), 1, 0, &d_out)) != ERROR_NONE) {
        return failed;
    }
    d_out *= outer_key[6] == 'r' ? 2.0 : 1.0;
    for (k = 0; k < 3; k++) {
        if (layout_get(t, inner_keys[k]) != NULL) {
            if (inner_key != NULL) {
                return layout_error(loader->error, loader->size,
                            "%s: give at most one of 'inner_diameter', 'inner_radius', 'wall_thickness'", where);
            }
            inner_key = inner_keys[k];
        }
    }
    if (inner_key != NULL) {
        value = layout_get(t, inner_key);
        if ((failed = layout_number(loader, where, inner_key, value, 0, 0, &v)) != ERROR_NONE) {
            return failed;
        }
        if (inner_key[0] == 'w') {
            if (v <= 0.0) {
                return layout_error(loader->error, loader->size, "%s.wall_thickness must be > 0, got %v", where, value);
            }
            if (2.0 * v > d_out) {
                return layout_error(loader->error, loader->size,
                            "%s.wall_thickness = %v exceeds half the outer diameter (%g)", where, value, d_out / 2);
            }
            d_in = d_out - 2.0 * v;
            d_in = 0.0 > d_in ? 0.0 : d_in;
        } else {
            d_in = v * (inner_key[6] == 'r' ? 2.0 : 1.0);
            if (d_in >= d_out) {
                return layout_error(loader->error, loader->size,
                            "%s.%s = %v must be smaller than the outer size (%s = %v)", where, inner_key, value,
                            outer_key, layout_get(t, outer_key));
            }
        }
    }
    s->outer_diameter = d_out;
    s->inner_diameter = d_in;
    if ((value = layout_get(t, "material")) != NULL) {
        int m = n_mats;
        if (value->kind == V_STRING) {
            for (m = 0; m < n_mats; m++) {
                if (mats[m].length == value->length && memcmp(mats[m].name, value->text, value->length) == 0) {
                    break;
                }
            }
        }
        if (m == n_mats) {
            const char *known = material_names(loader, mats, n_mats);
            if (known == NULL) {
                return layout_error(loader->error, loader->size, "out of memory");
            }
            return layout_error(loader->error, loader->size, "%s.material %v is not a defined material (%s)", where,
                                value,
                        known);
        }
        s->youngs_modulus = mats[m].E;
        s->density = mats[m].rho;
        have_E = have_rho = 1;
    }
    if ((value = layout_get(t, "youngs_modulus")) != NULL) {
        if ((failed = layout_number(loader, where, "youngs_modulus", value, 1, 0, &s->youngs_modulus)) != ERROR_NONE) {
            return failed;
        }
        have_E = 1;
    }
    if ((value = layout_get(t, "density")) != NULL) {
        if ((failed = layout_number(loader, where, "density", value, 1, 0, &s->density)) != ERROR_NONE) {
            return failed;
        }
        have_rho = 1;
    }
    if (!have_E || !have_rho) {
        return layout_error(loader->error, loader->size, "%s: missing key %r (or a 'material')", where,
                    !have_E ? "youngs_modulus" : "density");
    }
    s->rotary_inertia = s->gyroscopic = s->shear = 1;
    if ((failed = flag(loader, where, t, "rotary_inertia", &s->rotary_inertia)) != ERROR_NONE ||
        (failed = flag(loader, where, t, "gyroscopic", &s->gyroscopic)) != ERROR_NONE ||
        (failed = flag(loader, where, t, "shear", &s->shear)) != ERROR_NONE) {
        return failed;
    }
    s->poisson_ratio = 0.3;
    if ((nu = layout_get(t, "poisson_ratio")) != NULL) {
        double x = nu->kind == V_INTEGER ? (double)nu->integer : nu->kind == V_FLOAT ? nu->number : NAN;
        /* an integer is in (-1, 0.5) just when it is 0, its double too */
        if (!(-1.0 < x && x < 0.5)) {
            return layout_error(loader->error, loader->size, "%s.poisson_ratio must be a number in (-1, 0.5), got %v",
                                where,
                        nu);
        }
        s->poisson_ratio = x;
    }
    return segment_check(s, loader->error, loader->size);
}

/* loader._station */
static ErrorKind station(const Loader *loader, const char *where, const Value *t, int n_nodes, Station *out)
{
    const Value *node = layout_get(t, "node"), *position = layout_get(t, "position");
    if ((node != NULL) == (position != NULL)) {
        return layout_error(loader->error, loader->size, "%s: give exactly one of 'node' or 'position'", where);
    }
    out->is_node = node != NULL;
    if (node != NULL) {
        if (node->kind != V_INTEGER || node->integer < 0) {
            return layout_error(loader->error, loader->size, "%s.node must be an integer >= 0, got %v", where, node);
        }
        if (node->integer >= n_nodes) {
            char shown[32];
            snprintf(shown, sizeof shown, "%lld", node->integer);
            return layout_error(loader->error, loader->size, "%s.node = %s is out of range: nodes are 0..%d", where,
                                shown,
                        n_nodes - 1);
        }
        out->node = (int)node->integer;
        out->value = out->node;
        return ERROR_NONE;
    }
    return layout_number(loader, where, "position", position, 0, 0, &out->value);
}

/* loader._unbalance */
static ErrorKind unbalance(const Loader *loader, int i, const Value *t, const double *ends, int n_ends,
                           RotorUnbalance *u)
{
    char where[40];
    Station at;
    double position, right = ends[n_ends - 1];
    ErrorKind failed;
    snprintf(where, sizeof where, "unbalances[%d]", i);
    if ((failed = layout_unknown(loader, where, t, UNBALANCE_KEYS)) != ERROR_NONE ||
        (failed = station(loader, where, t, n_ends, &at)) != ERROR_NONE) {
        return failed;
    }
    position = at.is_node ? ends[at.node] : at.value;
    if (position > right + ROTOR_LOADER_NODE_SNAP) {
        return layout_error(loader->error, loader->size, "%s.position = %g m lies beyond the right end (%g m)", where,
                    at.value, right);
    }
    if (layout_get(t, "amount") == NULL) {
        return layout_error(loader->error, loader->size, "%s: missing key 'amount'", where);
    }
    u->position = right < position ? right : position;
    if ((failed = layout_number(loader, where, "amount", layout_get(t, "amount"), 0, 0, &u->amount)) != ERROR_NONE ||
        (failed = number_or(loader, where, t, "phase", 0.0, 1, &u->phase)) != ERROR_NONE) {
        return failed;
    }
    return unbalance_check(u, loader->error, loader->size);
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* loader._cut: the segments split at every position that is no node (into ``d``), and every
 * station's node (``nodes[kind][i]``). */
static ErrorKind cut(const Loader *loader, const RotorSegment *old, int n_old, Station *const stations[3],
                     const int counts[3], Driveline *d, int *const nodes[3])
{
    static const char *const kinds[] = {"masses", "bearings", "hinges"};
    double *ends, *cuts, *new_ends;
    int *segment_of, *node_of_old, n_cuts = 0, kind, i, j, k, n_new = 0;
    size_t room = (size_t)n_old + 1 + (size_t)(counts[0] + counts[1] + counts[2]);
    ends = arena_alloc(loader->arena, room * sizeof *ends);
    cuts = arena_alloc(loader->arena, room * sizeof *cuts);
    new_ends = arena_alloc(loader->arena, room * sizeof *new_ends);
    segment_of = arena_alloc(loader->arena, room * sizeof *segment_of);
    node_of_old = arena_alloc(loader->arena, room * sizeof *node_of_old);
    d->segments = malloc(room * sizeof *d->segments);
    if (ends == NULL || cuts == NULL || new_ends == NULL || segment_of == NULL || node_of_old == NULL ||
        d->segments == NULL) {
        return layout_error(loader->error, loader->size, "out of memory");
    }
    ends[0] = 0.0;
    for (k = 0; k < n_old; k++) {
        ends[k + 1] = ends[k] + old[k].length;
    }
    for (kind = 0; kind < 3; kind++) {
        for (i = 0; i < counts[kind]; i++) {
            double value = stations[kind][i].value;
            if (stations[kind][i].is_node) {
                continue;
            }
            if (value > ends[n_old] + ROTOR_LOADER_NODE_SNAP) {
                return layout_error(loader->error, loader->size,
                                    "%s[%d].position = %g m lies beyond the right end (%g m)",
                            kinds[kind], i, value, ends[n_old]);
            }
            for (k = 0; k < n_old && !(ends[k] <= value && value <= ends[k + 1]); k++) {
            }
            k = k == n_old ? 0 : k;
            double left = value - ends[k], right = ends[k + 1] - value;
            if ((left < right ? left : right) > ROTOR_LOADER_NODE_SNAP) {
                segment_of[n_cuts] = k;
                cuts[n_cuts++] = value;
            }
        }
    }
    new_ends[0] = 0.0;
    node_of_old[0] = 0;
    for (k = 0; k < n_old; k++) {
        double left = ends[k];
        int n_inner = 0;
        for (i = 0; i < n_cuts; i++) {
            if (segment_of[i] == k) {
                n_inner++;
            }
        }
        if (n_inner == 0) {
            d->segments[n_new] = old[k];
            new_ends[++n_new] = ends[k + 1];
        } else {
            /* this segment's cuts, sorted, each once */
            double *points = arena_alloc(loader->arena, ((size_t)n_inner + 1) * sizeof *points);
            int n_points = 0;
            if (points == NULL) {
                return layout_error(loader->error, loader->size, "out of memory");
            }
            for (i = 0; i < n_cuts; i++) {
                if (segment_of[i] == k) {
                    points[n_points++] = cuts[i];
                }
            }
            qsort(points, (size_t)n_points, sizeof *points, compare_doubles);
            for (i = 0, j = 0; i < n_points; i++) {
                if (j == 0 || points[i] != points[j - 1]) {
                    points[j++] = points[i];
                }
            }
            points[j++] = ends[k + 1];
            for (i = 0; i < j; i++) {
                d->segments[n_new] = old[k];
                d->segments[n_new].length = points[i] - left;
                left = points[i];
                new_ends[++n_new] = points[i];
            }
        }
        node_of_old[k + 1] = n_new;
    }
    d->n_segments = n_new;
    for (kind = 0; kind < 3; kind++) {
        for (i = 0; i < counts[kind]; i++) {
            const Station *s = &stations[kind][i];
            if (s->is_node) {
                nodes[kind][i] = node_of_old[s->node];
            } else {
                int best = 0;
                for (j = 1; j <= n_new; j++) {
                    if (fabs(new_ends[j] - s->value) < fabs(new_ends[best] - s->value)) {
                        best = j;
                    }
                }
                nodes[kind][i] = best;
            }
        }
    }
    return ERROR_NONE;
}

/* loader._pair: (xx, yy) of a bearing from the isotropic ``key`` or from ``xx`` [+ ``yy``]. */
static ErrorKind pair(const Loader *loader, const char *where, const Value *t, const char *key, const char *xx,
                      const char *yy, int positive, double *x, double *y)
{
    const Value *iso = layout_get(t, key), *vx = layout_get(t, xx), *vy = layout_get(t, yy);
    ErrorKind failed;
    if (iso != NULL) {
        if (vx != NULL || vy != NULL) {
            return layout_error(loader->error, loader->size, "%s: give either %r or %r/%r, not both", where, key, xx,
                                yy);
        }
        if ((failed = layout_number(loader, where, key, iso, positive, 0, x)) != ERROR_NONE) {
            return failed;
        }
        *y = *x;
        return ERROR_NONE;
    }
    if (vx == NULL) {
        if (positive) {
            return layout_error(loader->error, loader->size, "%s: missing key %r (or %r)", where, key, xx);
        }
        if (vy != NULL) {
            return layout_error(loader->error, loader->size, "%s: %r needs %r", where, yy, xx);
        }
        *x = *y = 0.0;
        return ERROR_NONE;
    }
    if ((failed = layout_number(loader, where, xx, vx, positive, 0, x)) != ERROR_NONE) {
        return failed;
    }
    if (vy == NULL) {
        *y = *x;
        return ERROR_NONE;
    }
    return layout_number(loader, where, yy, vy, positive, 0, y);
}

/* loader._mass, _bearing, _hinge of entry ``i`` of ``kind`` (0, 1, 2) at ``node`` */
static ErrorKind point_element(const Loader *loader, Driveline *d, int kind, int i, const Value *t, int node)
{
    char where[40];
    ErrorKind failed;
    snprintf(where, sizeof where, "%s[%d]", kind == 0 ? "masses" : kind == 1 ? "bearings" : "hinges", i);
    if ((failed = layout_unknown(loader, where, t, kind == 0 ? MASS_KEYS : kind == 1 ? BEARING_KEYS : HINGE_KEYS)) !=
        ERROR_NONE) {
        return failed;
    }
    if (kind == 0) {
        RotorMass *m = &d->masses[d->n_masses];
        m->node = node;
        if (layout_get(t, "mass") == NULL) {
            return layout_error(loader->error, loader->size, "%s: missing key 'mass'", where);
        }
        if ((failed = layout_number(loader, where, "mass", layout_get(t, "mass"), 0, 0, &m->mass)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "polar_inertia", 0.0, 0, &m->polar_inertia)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "diametral_inertia", 0.0, 0, &m->diametral_inertia)) != ERROR_NONE) {
            return failed;
        }
        d->n_masses++;
        return mass_check(m, loader->error, loader->size);
    } else if (kind == 1) {
        RotorBearing *b = &d->bearings[d->n_bearings];
        b->node = node;
        if ((failed = pair(loader, where, t, "stiffness", "kxx", "kyy", 1, &b->kxx, &b->kyy)) != ERROR_NONE ||
            (failed = pair(loader, where, t, "damping", "cxx", "cyy", 0, &b->cxx, &b->cyy)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "kxy", 0.0, 1, &b->kxy)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "kyx", 0.0, 1, &b->kyx)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "cxy", 0.0, 1, &b->cxy)) != ERROR_NONE ||
            (failed = number_or(loader, where, t, "cyx", 0.0, 1, &b->cyx)) != ERROR_NONE) {
            return failed;
        }
        d->n_bearings++;
        return bearing_check(b, loader->error, loader->size);
    } else {
        RotorHinge *h = &d->hinges[d->n_hinges];
        int n_nodes = d->n_segments + 1;
        if (!(0 < node && node < n_nodes - 1)) {
            const Value *at = layout_get(t, "node");
            if (at != NULL) {
                char shown[32];
                snprintf(shown, sizeof shown, "%lld", at->integer);
                return layout_error(loader->error, loader->size,
                                    "%s.node = %s must be an inner node (1..%d), not an end",
                            where, shown, n_nodes - 2);
            }
            return layout_error(loader->error, loader->size,
                                "%s.position = %v m must be an inner node (1..%d), not an end",
                        where, layout_get(t, "position"), n_nodes - 2);
        }
        h->node = node;
        if ((failed = number_or(loader, where, t, "bending_stiffness", 0.0, 0, &h->bending_stiffness)) != ERROR_NONE) {
            return failed;
        }
        d->n_hinges++;
        return element_non_negative("bending_stiffness", h->bending_stiffness, loader->error, loader->size);
    }
}

/* loader's end condition of ``key`` (free when absent) */
static ErrorKind end_condition(const Loader *loader, const Value *data, const char *key, EndCondition *out)
{
    const Value *v = layout_get(data, key);
    int i;
    *out = END_FREE;
    if (v == NULL) {
        return ERROR_NONE;
    }
    for (i = 0; i < 3 && v->kind == V_STRING; i++) {
        if (v->length == strlen(END_NAMES[i]) && memcmp(v->text, END_NAMES[i], v->length) == 0) {
            *out = (EndCondition)i;
            return ERROR_NONE;
        }
    }
    return layout_error(loader->error, loader->size, "%s = %v is not one of: free, pinned, clamped", key, v);
}

/* loader.loads_driveline after the parse: the driveline of the document ``data``. */
static ErrorKind load(const Loader *loader, const Value *data, Driveline *d)
{
    static const char *const kinds[] = {"masses", "bearings", "hinges"};
    static const int limits[] = {ROTOR_LOADER_MAX_POINT_ELEMENTS, ROTOR_LOADER_MAX_POINT_ELEMENTS,
                                 ROTOR_LOADER_MAX_POINT_ELEMENTS};
    const Value *name = layout_get(data, "name"), *segs, *unbs, *tables[3];
    const Item *item;
    Material *mats;
    RotorSegment *old;
    Station *stations[3];
    int *nodes[3], counts[3], n_mats, n_old, n_unb, i, kind;
    double *ends;
    ErrorKind failed;
    if ((failed = layout_unknown(loader, loader->source, data, TOP_KEYS)) != ERROR_NONE) {
        return failed;
    }
    if (name != NULL && name->kind != V_STRING) {
        return layout_error(loader->error, loader->size, "%s: name must be a string, got %v", loader->source, name);
    }
    if ((failed = end_condition(loader, data, "left_end", &d->left)) != ERROR_NONE ||
        (failed = end_condition(loader, data, "right_end", &d->right)) != ERROR_NONE ||
        (failed = materials(loader, data, &mats, &n_mats)) != ERROR_NONE ||
        (failed = layout_counted(loader, data, "segments", ROTOR_LOADER_MAX_SEGMENTS, &segs)) != ERROR_NONE) {
        return failed;
    }
    n_old = list_count(segs);
    if (n_old == 0) {
        return layout_error(loader->error, loader->size, "%s: at least one [[segments]] table is required",
                            loader->source);
    }
    old = arena_alloc(loader->arena, (size_t)n_old * sizeof *old);
    ends = arena_alloc(loader->arena, ((size_t)n_old + 1) * sizeof *ends);
    if (old == NULL || ends == NULL) {
        return layout_error(loader->error, loader->size, "out of memory");
    }
    ends[0] = 0.0;
    for (i = 0, item = segs->first; item != NULL; item = item->next, i++) {
        if ((failed = segment(loader, i, item->value, mats, n_mats, &old[i])) != ERROR_NONE) {
            return failed;
        }
        ends[i + 1] = ends[i] + old[i].length;
    }
    if ((failed = layout_counted(loader, data, "unbalances", ROTOR_LOADER_MAX_POINT_ELEMENTS, &unbs)) != ERROR_NONE) {
        return failed;
    }
    n_unb = list_count(unbs);
    d->unbalances = malloc(((size_t)n_unb + 1) * sizeof *d->unbalances);
    if (d->unbalances == NULL) {
        return layout_error(loader->error, loader->size, "out of memory");
    }
    for (i = 0, item = unbs != NULL ? unbs->first : NULL; item != NULL; item = item->next, i++) {
        if ((failed = unbalance(loader, i, item->value, ends, n_old + 1, &d->unbalances[i])) != ERROR_NONE) {
            return failed;
        }
        d->n_unbalances = i + 1;
    }
    for (kind = 0; kind < 3; kind++) {
        if ((failed = layout_counted(loader, data, kinds[kind], limits[kind], &tables[kind])) != ERROR_NONE) {
            return failed;
        }
        counts[kind] = list_count(tables[kind]);
        stations[kind] = arena_alloc(loader->arena, ((size_t)counts[kind] + 1) * sizeof *stations[kind]);
        nodes[kind] = arena_alloc(loader->arena, ((size_t)counts[kind] + 1) * sizeof *nodes[kind]);
        if (stations[kind] == NULL || nodes[kind] == NULL) {
            return layout_error(loader->error, loader->size, "out of memory");
        }
    }
    for (kind = 0; kind < 3; kind++) {
        for (i = 0, item = tables[kind] != NULL ? tables[kind]->first : NULL; item != NULL; item = item->next, i++) {
            char where[40];
            snprintf(where, sizeof where, "%s[%d]", kinds[kind], i);
            if ((failed = station(loader, where, item->value, n_old + 1, &stations[kind][i])) != ERROR_NONE) {
                return failed;
            }
        }
    }
    if ((failed = cut(loader, old, n_old, stations, counts, d, nodes)) != ERROR_NONE) {
        return failed;
    }
    d->masses = malloc(((size_t)counts[0] + 1) * sizeof *d->masses);
    d->bearings = malloc(((size_t)counts[1] + 1) * sizeof *d->bearings);
    d->hinges = malloc(((size_t)counts[2] + 1) * sizeof *d->hinges);
    if (d->masses == NULL || d->bearings == NULL || d->hinges == NULL) {
        return layout_error(loader->error, loader->size, "out of memory");
    }
    for (kind = 0; kind < 3; kind++) {
        for (i = 0, item = tables[kind] != NULL ? tables[kind]->first : NULL; item != NULL; item = item->next, i++) {
            if ((failed = point_element(loader, d, kind, i, item->value, nodes[kind][i])) != ERROR_NONE) {
                return failed;
            }
        }
    }
    return check_driveline(loader, d);
}

static ErrorKind loads_driveline(const char *text, size_t length, const char *source, void *out, char *error,
                                 size_t size)
{
    return driveline_from_text(text, length, source, out, error, size);
}

/* model.build_driveline for a layout: a ".toml" file or a shipped name (loader.example_path). */
ErrorKind driveline_from_layout(const char *layout, const char *resources, Driveline *out, char *error, size_t size)
{
    static const LayoutNames names = {"driveline file", "example"};
    memset(out, 0, sizeof *out);
    return layout_file_load(layout, resources, &names, loads_driveline, out, error, size);
}

void driveline_free(Driveline *driveline)
{
    free(driveline->segments);
    free(driveline->masses);
    free(driveline->bearings);
    free(driveline->hinges);
    free(driveline->unbalances);
    memset(driveline, 0, sizeof *driveline);
}

ErrorKind driveline_from_text(const char *text, size_t length, const char *source, Driveline *out, char *error,
                              size_t size)
{
    Arena arena = {NULL};
    Loader loader;
    Value *root;
    ErrorKind status;
    memset(out, 0, sizeof *out);
    if (size > 0) {
        error[0] = '\0';
    }
    loader.error = error;
    loader.size = size;
    loader.source = source;
    loader.arena = &arena;
    if ((status = layout_parse(text, length, &loader, &root)) != ERROR_NONE) {
        arena_free(&arena);
        return status;
    }
    status = load(&loader, root, out);
    arena_free(&arena);
    if (status != ERROR_NONE) {
        driveline_free(out);
    }
    return status;
}

/* loader.one_piece_shaft */
ErrorKind driveline_one_piece(const OnePieceShaft *shaft, Driveline *out, char *error, size_t size)
{
    static const char *const names[] = {"L_shaft", "D_outer", "D_inner", "E", "density", "m_joint", "Jp_joint",
                                        "Jd_joint", "k_bearing", "c_bearing"};
    static const int positive[] = {1, 1, 0, 1, 1, 0, 0, 0, 1, 0};
    const double values[] = {shaft->L_shaft,  shaft->D_outer,  shaft->D_inner,  shaft->E,
                             shaft->density,  shaft->m_joint,  shaft->Jp_joint, shaft->Jd_joint,
                             shaft->k_bearing, shaft->c_bearing};
    int i, pass;
    memset(out, 0, sizeof *out);
    if (size > 0) {
        error[0] = '\0';
    }
    for (i = 0; i < 10; i++) {
        if (!isfinite(values[i])) {
            return layout_error(error, size, "%s must be a finite number, got %g", names[i], values[i]);
        }
    }
    for (pass = 1; pass >= 0; pass--) {
        for (i = 0; i < 10; i++) {
            if (positive[i] == pass && (pass ? values[i] <= 0.0 : values[i] < 0.0)) {
                return layout_error(error, size, pass ? "%s must be > 0, got %g" : "%s must be >= 0, got %g", names[i],
                            values[i]);
            }
        }
    }
    if (shaft->D_inner >= shaft->D_outer) {
        return layout_error(error, size, "D_inner (%g) must be smaller than D_outer (%g)", shaft->D_inner,
                            shaft->D_outer);
    }
    out->segments = malloc(sizeof *out->segments);
    out->masses = malloc(2 * sizeof *out->masses);
    out->bearings = malloc(2 * sizeof *out->bearings);
    if (out->segments == NULL || out->masses == NULL || out->bearings == NULL) {
        driveline_free(out);
        return layout_error(error, size, "out of memory");
    }
    out->n_segments = 1;
    out->segments[0].length = shaft->L_shaft;
    out->segments[0].outer_diameter = shaft->D_outer;
    out->segments[0].inner_diameter = shaft->D_inner;
    out->segments[0].youngs_modulus = shaft->E;
    out->segments[0].density = shaft->density;
    out->segments[0].poisson_ratio = 0.3;
    out->segments[0].rotary_inertia = out->segments[0].gyroscopic = 1;
    out->segments[0].shear = shaft->shear != 0;
    out->n_masses = out->n_bearings = 2;
    for (i = 0; i < 2; i++) {
        RotorMass *m = &out->masses[i];
        RotorBearing *b = &out->bearings[i];
        m->node = b->node = i;
        m->mass = shaft->m_joint;
        m->polar_inertia = shaft->Jp_joint;
        m->diametral_inertia = shaft->Jd_joint;
        b->kxx = b->kyy = shaft->k_bearing;
        b->cxx = b->cyy = shaft->c_bearing;
        b->kxy = b->kyx = b->cxy = b->cyx = 0.0;
    }
    out->left = out->right = END_FREE;
    return ERROR_NONE;
}

/* Driveline.length */
double driveline_length(const Driveline *driveline)
{
    double sum;
    const char *failure;
    return segments_length(driveline, &sum, &failure) == ERROR_NONE ? sum : HUGE_VAL;
}
