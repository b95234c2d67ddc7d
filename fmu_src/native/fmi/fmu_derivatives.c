/* Directional and adjoint derivatives over a model's ``jacobian`` hook (FMI 2.0
 * fmi2GetDirectionalDerivative, FMI 3.0 fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative, both
 * interfaces).
 *
 * The unknowns are the Real outputs and the states' derivatives der(<state>), the knowns the Real inputs
 * and the states (model_jacobian_rows, model_jacobian_columns, generated from the spec). At the current
 * time, states and inputs the outputs are evaluated on a copy of the values as Model Exchange evaluates
 * them (internal state reset, the checks of a co-simulation step), the model fills the dense Jacobian J of
 * the outputs, the layer the rows of the states (d state / d state = 1) and of der(<state>) (the row of
 * the variable it is: an input's column, or an output's row), and the call gets J seed or seed^T J of
 * the rows and columns named. In co-simulation this is the map the outputs follow at one instant; the
 * history a step keeps (the Cardan joint's speed samples) does not enter it.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_instance.h"

#define JACOBIAN_SIZE (MODEL_ROW_COUNT * MODEL_COLUMN_COUNT > 0 ? MODEL_ROW_COUNT * MODEL_COLUMN_COUNT : 1)

/* The row of value reference ``reference`` (an unknown), or -1. */
static int row_of(const Instance *instance, uint32_t reference)
{
    int state;
    if (reference < MODEL_VARIABLE_COUNT) {
        return model_jacobian_rows[reference];
    }
    state = instance_derivative_of(instance, reference);
    return state >= 0 ? MODEL_OUTPUT_ROWS + state : -1;
}

static int column_of(uint32_t reference)
{
    return reference < MODEL_VARIABLE_COUNT ? model_jacobian_columns[reference] : -1;
}

/* 1 when each of the ``n`` references is an unknown (``unknowns`` 1) or a known; else Error naming it. */
static int all_named(Instance *instance, const char *function, const uint32_t vr[], size_t n, int unknowns)
{
    char number[24];
    size_t i;
    for (i = 0; i < n; i++) {
        if ((unknowns ? row_of(instance, vr[i]) : column_of(vr[i])) < 0) {
            snprintf(number, sizeof number, "%lu", (unsigned long)vr[i]);
            instance_fail(instance, instance->fmi_prefix, function, ": value reference ", number,
                          vr[i] < MODEL_VARIABLE_COUNT ? " (" : "",
                          vr[i] < MODEL_VARIABLE_COUNT ? model_variables[vr[i]].name : "",
                          vr[i] < MODEL_VARIABLE_COUNT ? ")" : "",
                          unknowns ? " is no unknown (a Real output or a state derivative)"
                                   : " is no known (a Real input or a continuous state)",
                          (const char *)NULL);
            return 0;
        }
    }
    return 1;
}

/* 1 when the arguments are usable: arrays given, sizes as the unknowns and knowns say, seeds finite. */
static int arguments_usable(Instance *instance, const char *function, const uint32_t unknowns[], size_t n_unknowns,
                            const uint32_t knowns[], size_t n_knowns, const double seed[], size_t n_seed,
                            const double sensitivity[], size_t n_sensitivity, int adjoint)
{
    char expected[24], given[24], shown[40];
    size_t i;
    if ((n_unknowns > 0 && unknowns == NULL) || (n_knowns > 0 && knowns == NULL) || (n_seed > 0 && seed == NULL) ||
        (n_sensitivity > 0 && sensitivity == NULL)) {
        instance_fail(instance, instance->fmi_prefix, function, ": null array", (const char *)NULL);
        return 0;
    }
    if (n_seed != (adjoint ? n_unknowns : n_knowns) || n_sensitivity != (adjoint ? n_knowns : n_unknowns)) {
        snprintf(expected, sizeof expected, "%lu, %lu", (unsigned long)(adjoint ? n_unknowns : n_knowns),
                 (unsigned long)(adjoint ? n_knowns : n_unknowns));
        snprintf(given, sizeof given, "%lu, %lu", (unsigned long)n_seed, (unsigned long)n_sensitivity);
        instance_fail(instance, instance->fmi_prefix, function, ": nSeed, nSensitivity = ", given, " where the ",
                      adjoint ? "unknowns and knowns" : "knowns and unknowns", " give ", expected,
                      " (scalar variables only)", (const char *)NULL);
        return 0;
    }
    for (i = 0; i < n_seed; i++) {
        if (!isfinite(seed[i])) {
            snprintf(expected, sizeof expected, "%lu", (unsigned long)i);
            python_float_repr(seed[i], shown, sizeof shown);
            instance_fail(instance, instance->fmi_prefix, function, ": seed[", expected, "] = ", shown,
                          " is not finite", (const char *)NULL);
            return 0;
        }
    }
    return all_named(instance, function, unknowns, n_unknowns, 1) && all_named(instance, function, knowns, n_knowns, 0);
}

/* The layer's rows: a state's own (1 on its column), der(<state>)'s (its variable's row or column). */
static void state_rows(double partial[])
{
#if MODEL_STATE_COUNT > 0
    int k, j, row, source;
    for (k = 0; k < MODEL_STATE_COUNT; k++) {
        partial[model_jacobian_rows[model_states[k]] * MODEL_COLUMN_COUNT + model_jacobian_columns[model_states[k]]] =
            1.0;
    }
    for (k = 0; k < MODEL_STATE_COUNT; k++) {
        row = MODEL_OUTPUT_ROWS + k;
        source = model_state_derivatives[k];
        for (j = 0; j < MODEL_COLUMN_COUNT; j++) {
            partial[row * MODEL_COLUMN_COUNT + j] =
                model_jacobian_rows[source] >= 0 ? partial[model_jacobian_rows[source] * MODEL_COLUMN_COUNT + j]
                                                 : (double)(j == model_jacobian_columns[source]);
        }
    }
#else
    (void)partial;
#endif
}

/* The Jacobian at the instance's point into ``partial``; the reasons of a refusal in the instance's messages. */
static void jacobian_at_point(Instance *instance, double partial[])
{
    ModelData point = instance->data;
    char shown[40];
    Failure failure;
    int i, finite = 1;
    model_exchange_evaluate(instance, &point);
    if (instance->messages.count) {
        return;
    }
    for (i = 0; i < JACOBIAN_SIZE; i++) {
        partial[i] = 0.0;
    }
    failure = model_hooks.jacobian(&point, partial);
    state_rows(partial);
    for (i = 0; i < JACOBIAN_SIZE; i++) {
        finite = finite && isfinite(partial[i]);
    }
    python_float_repr(point.time, shown, sizeof shown);
    if (failure.kind != ERROR_NONE) {
        messages_add(&instance->messages, "the partial derivatives at t = ", shown, " s could not be computed (",
                     ERROR_KIND_NAME(failure.kind), ": ", failure.message, ")", (const char *)NULL);
    } else if (!finite) {
        messages_add(&instance->messages, "the partial derivatives at t = ", shown, " s are not all finite",
                     (const char *)NULL);
    }
}

/* 1 when the instance's point is the one its kept Jacobian was computed at. */
static int same_point(const Instance *instance)
{
    const ModelData *now = &instance->data, *then = &instance->jacobian_point;
    return instance->jacobian_valid && instance->jacobian_epoch == instance->epoch &&
           memcmp(&now->time, &then->time, sizeof now->time) == 0 &&
           memcmp(now->real_value, then->real_value, sizeof now->real_value) == 0 &&
           memcmp(now->int_value, then->int_value, sizeof now->int_value) == 0;
}

/* The Jacobian at the instance's point: the kept one while the point is the same (a host asking for it
 * column by column), else computed and kept; NULL with the reasons in the instance's messages. */
static const double *jacobian_now(Instance *instance)
{
    if (instance->jacobian == NULL) {
        instance->jacobian = malloc(JACOBIAN_SIZE * sizeof *instance->jacobian);
        if (instance->jacobian == NULL) {
            messages_add(&instance->messages, "out of memory for the partial derivatives", (const char *)NULL);
            return NULL;
        }
    }
    if (same_point(instance)) {
        return instance->jacobian;
    }
    instance->jacobian_valid = 0;
    jacobian_at_point(instance, instance->jacobian);
    if (instance->messages.count) {
        return NULL;
    }
    instance->jacobian_point = instance->data;
    instance->jacobian_epoch = instance->epoch;
    instance->jacobian_valid = 1;
    return instance->jacobian;
}

Failure jacobian_of_time_alone(const ModelData *data UNUSED, double partial[] UNUSED)
{
    return NO_FAILURE; /* every partial derivative is zero but the states' own, which are the layer's */
}

/* d unknowns[u] / d knowns[k] of the call */
#define ENTRY(u, k) (partial[row_of(instance, unknowns[u]) * MODEL_COLUMN_COUNT + column_of(knowns[k])])

/* sensitivity[i] of the call: row i of J times the seed, or the seed times column i of J (``adjoint``) */
static double sensitivity_of(Instance *instance, const double *partial, const uint32_t unknowns[],
                             const uint32_t knowns[], const double seed[], size_t n_seed, size_t i, int adjoint)
{
    double value = 0.0;
    size_t j;
    for (j = 0; j < n_seed; j++) {
        if (seed[j] != 0.0) { /* a unit seed's zeros add nothing: a column costs one pass of the rows */
            value += seed[j] * (adjoint ? ENTRY(j, i) : ENTRY(i, j));
        }
    }
    return value;
}

Status derivatives_get(Instance *instance, const char *function, const uint32_t unknowns[], size_t n_unknowns,
                       const uint32_t knowns[], size_t n_knowns, const double seed[], size_t n_seed,
                       double sensitivity[], size_t n_sensitivity, int adjoint)
{
    const double *partial;
    char shown[40];
    size_t i;
    if (model_hooks.jacobian == NULL || model_hooks.evaluate == NULL) {
        return instance_unsupported(instance, function);
    }
    if (!instance_allows(instance, MODE_BIT(MODE_STEP), function) ||
        !arguments_usable(instance, function, unknowns, n_unknowns, knowns, n_knowns, seed, n_seed, sensitivity,
                          n_sensitivity, adjoint)) {
        return STATUS_ERROR;
    }
    instance->messages.count = 0; /* the messages are this call's: an earlier refusal's are not */
    partial = jacobian_now(instance);
    if (partial == NULL) {
        return instance_refusal(instance);
    }
    for (i = 0; i < n_sensitivity; i++) { /* finite partials and seeds whose products overflow: none is written */
        if (!isfinite(sensitivity_of(instance, partial, unknowns, knowns, seed, n_seed, i, adjoint))) {
            python_float_repr(instance->data.time, shown, sizeof shown);
            messages_add(&instance->messages, "the ", adjoint ? "adjoint" : "directional", " derivative at t = ",
                         shown, " s overflows: the seed is too large", (const char *)NULL);
            return instance_refusal(instance);
        }
    }
    for (i = 0; i < n_sensitivity; i++) {
        sensitivity[i] = sensitivity_of(instance, partial, unknowns, knowns, seed, n_seed, i, adjoint);
    }
    return instance_refusal(instance);
}
