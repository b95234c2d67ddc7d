/* The layouts of a powertrain on its mounts (port of driveline/mounts/layout.py), read with the layout
 * reader of lib/toml.h (driveline/layout_files.py's rules), with the Python loader's messages. */
#include "mounts.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static const char *const TOP_KEYS[] = {"centre_of_gravity", "inertia", "loss_factor_frequency", "mass", "mounts",
                                       "name", NULL};
static const char *const MOUNT_KEYS[] = {"damping",  "dynamic_ratio", "gap",       "label",      "loss_factor",
                                         "orientation", "position",  "stiffness", "stop_blend", "stop_rate", NULL};

/* layout._vector */
static ErrorKind vector3(const Loader *loader, const char *where, const char *key, const Value *value, int signed_,
                         double out[3])
{
    char name[64];
    const Item *item;
    int i = 0;
    ErrorKind failed;
    if (value->kind != V_ARRAY || value->count != 3) {
        return layout_error(loader->error, loader->size, "%s.%s must be an array of 3 numbers, got %v", where, key,
                            value);
    }
    for (item = value->first; item != NULL; item = item->next, i++) {
        snprintf(name, sizeof name, "%s[%d]", key, i);
        if ((failed = layout_number(loader, where, name, item->value, 0, signed_, &out[i])) != ERROR_NONE) {
            return failed;
        }
    }
    return ERROR_NONE;
}

/* not const: C99 passes no double[3][3] for a const one (nor in state_and_inputs) */
static double det3(double a[3][3])
{
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* layout._orientation */
static ErrorKind orientation(const Loader *loader, const char *where, const Value *value, double axes[3][3])
{
    char key[32], deviation_text[40], det_text[40];
    const Item *item;
    double deviation = 0.0, det;
    int i = 0, j, k;
    ErrorKind failed;
    if (value->kind != V_ARRAY || value->count != 3) {
        return layout_error(loader->error, loader->size,
                            "%s.orientation must be an array of 3 rows of 3 numbers, got %v", where, value);
    }
    for (item = value->first; item != NULL; item = item->next, i++) {
        snprintf(key, sizeof key, "orientation[%d]", i);
        if ((failed = vector3(loader, where, key, item->value, 1, axes[i])) != ERROR_NONE) {
            return failed;
        }
    }
    for (i = 0; i < 3; i++) {
        for (j = 0; j < 3; j++) {
            double dot = 0.0;
            for (k = 0; k < 3; k++) {
                dot += axes[i][k] * axes[j][k];
            }
            deviation = fmax(deviation, fabs(dot - (i == j)));
        }
    }
    det = det3(axes);
    if (!(deviation <= MOUNTS_LAYOUT_ROTATION_TOLERANCE && fabs(det - 1.0) <= MOUNTS_LAYOUT_ROTATION_TOLERANCE)) {
        python_format_g(deviation, 3, deviation_text, sizeof deviation_text);
        python_format_g(det, 6, det_text, sizeof det_text);
        return layout_error(loader->error, loader->size,
                            "%s.orientation is not a rotation: its rows must be orthonormal and right-handed "
                            "(|R R^T - I| = %s, det R = %s)", where, deviation_text, det_text);
    }
    return ERROR_NONE;
}

/* layout._branches: the Maxwell weights of a mount's loss_factor in (0, 1) and dynamic_ratio >= 1 */
static ErrorKind branches(const Loader *loader, const char *where, const Value *t, Mount *m)
{
    const Value *loss = layout_get(t, "loss_factor"), *ratio_value = layout_get(t, "dynamic_ratio");
    double eta, ratio;
    RubberFit fit;
    int j;
    ErrorKind failed;
    if (loss == NULL) {
        return layout_error(loader->error, loader->size,
                            "%s.dynamic_ratio needs the key 'loss_factor' (the loss factor its branches fit)", where);
    }
    if ((failed = layout_number(loader, where, "loss_factor", loss, 0, 0, &eta)) != ERROR_NONE) {
        return failed;
    }
    if (!(0.0 < eta && eta < 1.0)) {
        return layout_error(loader->error, loader->size, "%s.loss_factor must lie in (0, 1) for rubber damping, got %v",
                            where, loss);
    }
    if ((failed = layout_number(loader, where, "dynamic_ratio", ratio_value, 0, 0, &ratio)) != ERROR_NONE) {
        return failed;
    }
    if (!(ratio >= 1.0)) {
        return layout_error(loader->error, loader->size,
                            "%s.dynamic_ratio must be >= 1 (dynamic over static rate), got %v", where, ratio_value);
    }
    rubber_fit(eta, ratio, &fit);
    if (rubber_fit_error(where, &fit, eta, ratio, loader->error, loader->size)) {
        return ERROR_VALUE;
    }
    m->branch_count = MOUNTS_RUBBER_BRANCHES;
    for (j = 0; j < MOUNTS_RUBBER_BRANCHES; j++) {
        m->branches[j] = fit.weights[j];
    }
    return ERROR_NONE;
}

/* layout._stop: a mount's snubber, gap >= 0 and stop_rate given together, the characteristic monotonic */
static ErrorKind stop(const Loader *loader, const char *where, const Value *t, Mount *m)
{
    const Value *gap = layout_get(t, "gap"), *rate = layout_get(t, "stop_rate"), *blend = layout_get(t, "stop_blend");
    char rate_text[40], sum_text[40];
    int k;
    ErrorKind failed;
    if ((gap == NULL) != (rate == NULL)) {
        return layout_error(loader->error, loader->size, "%s.%s needs the key %r (a snubber has both)", where,
                            gap != NULL ? "gap" : "stop_rate", gap != NULL ? "stop_rate" : "gap");
    }
    m->stop_blend = MOUNTS_LAYOUT_STOP_BLEND;
    if (blend != NULL && (failed = layout_number(loader, where, "stop_blend", blend, 1, 0, &m->stop_blend))) {
        return failed;
    }
    if (gap == NULL) {
        return ERROR_NONE;
    }
    if ((failed = vector3(loader, where, "gap", gap, 0, m->gap)) != ERROR_NONE ||
        (failed = vector3(loader, where, "stop_rate", rate, 1, m->stop_rate)) != ERROR_NONE) {
        return failed;
    }
    for (k = 0; k < 3; k++) {
        if (m->stiffness[k] + m->stop_rate[k] < 0.0) {
            python_float_repr(m->stop_rate[k], rate_text, sizeof rate_text);
            python_float_repr(m->stiffness[k] + m->stop_rate[k], sum_text, sizeof sum_text);
            return layout_error(loader->error, loader->size,
                                "%s.stop_rate[%d] %s makes the characteristic not monotonic: stiffness[%d] + "
                                "stop_rate[%d] = %s < 0 beyond the gap", where, k, rate_text, k, k, sum_text);
        }
    }
    return ERROR_NONE;
}

int mount_progressive(const Mount *m)
{
    return m->stop_rate[0] != 0.0 || m->stop_rate[1] != 0.0 || m->stop_rate[2] != 0.0;
}

/* layout._mount; ``loss_frequency`` < 0: the layout gives none */
static ErrorKind mount(const Loader *loader, int i, const Value *t, double loss_frequency, Mount *m)
{
    static const char *const required[] = {"position", "stiffness"};
    const Value *damping = layout_get(t, "damping"), *loss = layout_get(t, "loss_factor");
    const Value *label = layout_get(t, "label"), *axes = layout_get(t, "orientation");
    char where[32];
    double factor;
    int k;
    ErrorKind failed;
    snprintf(where, sizeof where, "mounts[%d]", i);
    if ((failed = layout_unknown(loader, where, t, MOUNT_KEYS)) != ERROR_NONE) {
        return failed;
    }
    for (k = 0; k < 2; k++) {
        if (layout_get(t, required[k]) == NULL) {
            return layout_error(loader->error, loader->size, "%s: missing key %r", where, required[k]);
        }
    }
    if ((failed = vector3(loader, where, "stiffness", layout_get(t, "stiffness"), 0, m->stiffness)) != ERROR_NONE) {
        return failed;
    }
    if (damping != NULL && loss != NULL) {
        return layout_error(loader->error, loader->size, "%s: give either 'damping' or 'loss_factor', not both", where);
    }
    if (layout_get(t, "dynamic_ratio") != NULL) {
        if ((failed = branches(loader, where, t, m)) != ERROR_NONE) {
            return failed;
        }
    } else if (loss != NULL) {
        if (loss_frequency < 0.0) {
            return layout_error(loader->error, loader->size,
                                "%s.loss_factor needs the top-level key 'loss_factor_frequency'", where);
        }
        if ((failed = layout_number(loader, where, "loss_factor", loss, 0, 0, &factor)) != ERROR_NONE) {
            return failed;
        }
        for (k = 0; k < 3; k++) {
            m->damping[k] = factor * m->stiffness[k] / (2.0 * FMU_PI * loss_frequency);
        }
    } else if (damping != NULL) {
        if ((failed = vector3(loader, where, "damping", damping, 0, m->damping)) != ERROR_NONE) {
            return failed;
        }
    }
    if (label != NULL && label->kind != V_STRING) {
        return layout_error(loader->error, loader->size, "%s.label must be a string, got %v", where, label);
    }
    for (k = 0; k < 3; k++) {
        m->axes[k][0] = k == 0;
        m->axes[k][1] = k == 1;
        m->axes[k][2] = k == 2;
    }
    if (axes != NULL && (failed = orientation(loader, where, axes, m->axes)) != ERROR_NONE) {
        return failed;
    }
    if ((failed = stop(loader, where, t, m)) != ERROR_NONE) {
        return failed;
    }
    return vector3(loader, where, "position", layout_get(t, "position"), 1, m->position);
}

/* layout.inertia_tensor and its positive definiteness */
static ErrorKind inertia(const Loader *loader, const Value *value, double tensor[3][3])
{
    char name[32], shown[256], moments[128], piece[40];
    const Item *item;
    double v[6], a[9], vectors[9];
    size_t used = 0;
    int i = 0;
    ErrorKind failed;
    if (value->kind != V_ARRAY || value->count != 6) {
        return layout_error(loader->error, loader->size,
                            "%s: inertia must be an array of 6 numbers [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], got %v",
                            loader->source, value);
    }
    for (item = value->first; item != NULL; item = item->next, i++) {
        snprintf(name, sizeof name, "inertia[%d]", i);
        if ((failed = layout_number(loader, loader->source, name, item->value, 0, 1, &v[i])) != ERROR_NONE) {
            return failed;
        }
    }
    tensor[0][0] = v[0], tensor[1][1] = v[1], tensor[2][2] = v[2];
    tensor[0][1] = tensor[1][0] = -v[3];
    tensor[0][2] = tensor[2][0] = -v[4];
    tensor[1][2] = tensor[2][1] = -v[5];
    memcpy(a, tensor, sizeof a);
    dense_symmetric_eigen(a, vectors, 3);
    if (a[0] > 0.0 && a[4] > 0.0 && a[8] > 0.0) {
        return ERROR_NONE;
    }
    shown[0] = moments[0] = '\0';
    text_append(shown, sizeof shown, &used, "[", 1);
    for (i = 0; i < 6; i++) {
        python_float_repr(v[i], piece, sizeof piece);
        text_append(shown, sizeof shown, &used, piece, strlen(piece));
        text_append(shown, sizeof shown, &used, i < 5 ? ", " : "]", i < 5 ? 2 : 1);
    }
    used = 0;
    for (i = 0; i < 3; i++) {
        python_format_g(a[4 * i], 6, piece, sizeof piece);
        text_append(moments, sizeof moments, &used, piece, strlen(piece));
        text_append(moments, sizeof moments, &used, i < 2 ? ", " : "", i < 2 ? 2 : 0);
    }
    return layout_error(loader->error, loader->size,
                        "%s: inertia %s is not positive definite (principal moments %s kg m2)", loader->source, shown,
                        moments);
}

ErrorKind loads_layout(const char *text, size_t length, const char *source, void *out, char *error, size_t size)
{
    static const char *const required[] = {"mass", "centre_of_gravity", "inertia"};
    Layout *layout = out;
    Arena arena = {NULL};
    Loader loader;
    Value *root;
    const Value *name, *frequency, *tables;
    const Item *item;
    double loss_frequency = -1.0;
    int k;
    ErrorKind failed;
    loader.error = error;
    loader.size = size;
    loader.source = source;
    loader.arena = &arena;
    memset(layout, 0, sizeof *layout);
    failed = layout_parse(text, length, &loader, &root);
    failed = failed ? failed : layout_unknown(&loader, source, root, TOP_KEYS);
    for (k = 0; !failed && k < 3; k++) {
        if (layout_get(root, required[k]) == NULL) {
            failed = layout_error(error, size, "%s: missing key %r", source, required[k]);
        }
    }
    name = failed ? NULL : layout_get(root, "name");
    if (name != NULL && name->kind != V_STRING) {
        failed = layout_error(error, size, "%s: name must be a string, got %v", source, name);
    }
    failed = failed ? failed : layout_number(&loader, source, "mass", layout_get(root, "mass"), 1, 0, &layout->mass);
    failed = failed ? failed : inertia(&loader, layout_get(root, "inertia"), layout->inertia);
    frequency = failed ? NULL : layout_get(root, "loss_factor_frequency");
    if (frequency != NULL) {
        failed = layout_number(&loader, source, "loss_factor_frequency", frequency, 1, 0, &loss_frequency);
    }
    failed = failed ? failed : layout_counted(&loader, root, "mounts", MOUNTS_LAYOUT_MAX_MOUNTS, &tables);
    if (!failed && (tables == NULL || tables->count == 0)) {
        failed = layout_error(error, size, "%s: at least one [[mounts]] table is required", source);
    }
    for (item = failed ? NULL : tables->first; item != NULL && !failed; item = item->next, layout->count++) {
        failed = mount(&loader, layout->count, item->value, loss_frequency, &layout->mounts[layout->count]);
    }
    if (!failed) {
        failed = vector3(&loader, source, "centre_of_gravity", layout_get(root, "centre_of_gravity"), 1,
                         layout->centre);
    }
    arena_free(&arena);
    return failed;
}
