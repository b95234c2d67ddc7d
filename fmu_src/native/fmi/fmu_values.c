/* Values of the native FMUs' shared layer: getting and setting variables by value reference,
 * with the accessibility checks of each mode; debug logging categories. */
#include "fmu_instance.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- values ------------------------------------------------------------------------------- */

static const char *type_name(VariableType type)
{
    static const char *const names[] = {"Real", "Integer", "Boolean", "String"};
    return names[type];
}

static int is_time(const Instance *instance, uint32_t reference)
{
    return reference == MODEL_VARIABLE_COUNT && instance->fmi_prefix[3] == '3';
}

#if MODEL_STATE_COUNT > 0
#define DERIVATIVE_VALUE(k) (values->real_value[model_state_derivatives[k]])
#else
#define DERIVATIVE_VALUE(k) 0.0 /* no state: never used */
#endif

/* The state k whose derivative der(<state>) has value reference ``reference`` (after the spec's
 * variables and FMI 3.0's time), or -1; a model without states has none (no comparison with a count 0). */
int instance_derivative_of(const Instance *instance, uint32_t reference)
{
#if MODEL_STATE_COUNT > 0
    uint32_t first = MODEL_VARIABLE_COUNT + (instance->fmi_prefix[3] == '3' ? 1u : 0u);
    return reference >= first && reference - first < (uint32_t)MODEL_STATE_COUNT ? (int)(reference - first) : -1;
#else
    (void)instance;
    (void)reference;
    return -1;
#endif
}

/* 1 when ``reference`` names a variable of ``type`` that may be got (``setting`` 0) or set now;
 * else Error, with the reason logged. FMI 3.0's independent variable time and the states'
 * derivatives are Reals to get only. */
static int accessible(Instance *instance, const char *function, uint32_t reference, VariableType type, int setting)
{
    const VariableInfo *v = reference < MODEL_VARIABLE_COUNT ? &model_variables[reference] : NULL;
    const char *problem = NULL;
    char number[24];
    if (is_time(instance, reference)) {
        problem = type == VAR_REAL && !setting ? NULL : " is the independent variable time, a Real that cannot be set";
    } else if (instance_derivative_of(instance, reference) >= 0) {
        problem = type == VAR_REAL && !setting ? NULL : " is a state derivative, a Real that cannot be set";
    } else if (v == NULL) {
        problem = " is unknown";
    } else if (v->type != type) {
        problem = type == VAR_REAL      ? " is not of type Real"
                  : type == VAR_INTEGER ? " is not of type Integer"
                  : type == VAR_BOOLEAN ? " is not of type Boolean"
                                        : " is not of type String";
    } else if (setting && v->causality == CAUSALITY_OUTPUT) {
        problem = " is an output and cannot be set";
    } else if (setting && v->causality == CAUSALITY_LOCAL) {
        problem = " is a local variable and cannot be set";
    } else if (setting && instance->mode == MODE_STEP && v->causality == CAUSALITY_PARAMETER && !v->tunable) {
        problem = " is a fixed parameter and cannot be changed after initialisation";
    }
    if (problem == NULL) {
        return 1;
    }
    snprintf(number, sizeof number, "%lu", (unsigned long)reference); /* formatted for a failure only */
    instance_fail(instance, instance->fmi_prefix, function, ": value reference ", number,
                  v != NULL ? " (" : "", v != NULL ? v->name : "", v != NULL ? ")" : "", problem, (const char *)NULL);
    return 0;
}

#define SETTABLE_MODES (MODE_BIT(MODE_INSTANTIATED) | MODE_BIT(MODE_INITIALIZATION) | MODE_BIT(MODE_STEP))

/* 1 when the call is the common case (a mode that allows it, arrays given, every reference one of the spec's
 * variables of ``type``: any to get, an input to set), which needs no message. */
static int commonly_accessible(const Instance *instance, const uint32_t vr[], size_t n, const void *values,
                               VariableType type, int setting)
{
    size_t i;
    if (!((setting ? SETTABLE_MODES : ANY_MODE) & MODE_BIT(instance->mode)) ||
        (n > 0 && (vr == NULL || values == NULL))) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        const VariableInfo *v;
        if (vr[i] >= MODEL_VARIABLE_COUNT) {
            return 0;
        }
        v = &model_variables[vr[i]];
        if (v->type != type || (setting && v->causality != CAUSALITY_INPUT)) {
            return 0;
        }
    }
    return 1;
}

/* all_accessible beyond the common case: each reference checked, the first refusal logged; a parameter set
 * has the parameters checked again at the next step. */
static int checked_accessible(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                              const void *values, VariableType type, int setting)
{
    size_t i;
    if (!((setting ? SETTABLE_MODES : ANY_MODE) & MODE_BIT(instance->mode)) &&
        !instance_allows(instance, setting ? SETTABLE_MODES : ANY_MODE, function)) { /* logs the misuse */
        return 0;
    }
    if (n > 0 && (vr == NULL || values == NULL)) {
        instance_fail(instance, instance->fmi_prefix, function, ": null array of value references or values",
                      (const char *)NULL);
        return 0;
    }
    for (i = 0; i < n; i++) {
        const VariableInfo *v = vr[i] < MODEL_VARIABLE_COUNT ? &model_variables[vr[i]] : NULL;
        if (!accessible(instance, function, vr[i], type, setting)) {
            return 0;
        }
        if (setting && v != NULL && v->causality == CAUSALITY_PARAMETER) {
            instance->parameters_checked = 0; /* the next step checks the parameters again */
        }
    }
    return 1;
}

/* 1 when the call may get or set these ``n`` references now (checked before any value moves). */
static int all_accessible(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                          const void *values, VariableType type, int setting)
{
    if (!commonly_accessible(instance, vr, n, values, type, setting) &&
        !checked_accessible(instance, function, vr, n, values, type, setting)) {
        return 0;
    }
    if (setting) {
        instance->stale = 1; /* Model Exchange: the outputs follow at the next get */
    }
    return 1;
}

/* The values a get reads now and the status it returns with them: Model Exchange's outputs brought up to date
 * (model_exchange_update), Initialization Mode's computed (instance_readable); else the instance's, OK. */
static const ModelData *values_to_get(Instance *instance, Status *status)
{
    Status initial;
    const ModelData *values;
    *status = instance->model_exchange ? model_exchange_update(instance) : STATUS_OK;
    if (instance->mode != MODE_INITIALIZATION) {
        return &instance->data;
    }
    values = instance_readable(instance, &initial);
    *status = *status > initial ? *status : initial;
    return values;
}

Status instance_set_real(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                         const double value[])
{
    size_t i;
    if (n == 1 && commonly_accessible(instance, vr, 1, value, VAR_REAL, 1)) { /* a container's call, inlined */
        instance->data.real_value[vr[0]] = value[0];
        instance->stale = 1;
        return STATUS_OK;
    }
    if (!all_accessible(instance, function, vr, n, value, VAR_REAL, 1)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        instance->data.real_value[vr[i]] = value[i];
    }
    return STATUS_OK;
}

Status instance_set_input_derivatives(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                                      const int32_t order[], const double value[])
{
#if MODEL_INPUT_DERIVATIVE_COUNT > 0
    uint32_t target[MODEL_INPUT_DERIVATIVE_COUNT];
    size_t i;
    int k;
    if (n > 0 && (vr == NULL || order == NULL || value == NULL)) {
        return instance_fail(instance, instance->fmi_prefix, function, ": a NULL array", (const char *)NULL);
    }
    if (n > MODEL_INPUT_DERIVATIVE_COUNT) {
        return instance_fail(instance, instance->fmi_prefix, function,
                             ": more derivatives than the model's inputs hold", (const char *)NULL);
    }
    for (i = 0; i < n; i++) {
        for (k = 0; k < MODEL_INPUT_DERIVATIVE_COUNT; k++) {
            const InputDerivative *d = &model_input_derivatives[k];
            if ((uint32_t)d->input == vr[i] && d->order == order[i]) {
                target[i] = (uint32_t)d->target;
                break;
            }
        }
        if (k == MODEL_INPUT_DERIVATIVE_COUNT) {
            return instance_fail(instance, instance->fmi_prefix, function,
                                 ": no input holds that derivative (input and order: see the model's inputs "
                                 "with a derivative)", (const char *)NULL);
        }
    }
    return instance_set_real(instance, function, target, n, value);
#else
    (void)vr;
    (void)n;
    (void)order;
    (void)value;
    return instance_unsupported(instance, function);
#endif
}

Status instance_set_integer(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                            const int32_t value[])
{
    size_t i;
    if (!all_accessible(instance, function, vr, n, value, VAR_INTEGER, 1)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        instance->data.int_value[vr[i]] = value[i];
    }
    return STATUS_OK;
}

Status instance_get_real(Instance *instance, const char *function, const uint32_t vr[], size_t n, double value[])
{
    size_t i;
    Status status;
    const ModelData *values;
    int k;
    if (n == 1 && !instance->model_exchange && instance->mode != MODE_INITIALIZATION &&
        commonly_accessible(instance, vr, 1, value, VAR_REAL, 0)) { /* a container's call: the value as it is */
        value[0] = instance->data.real_value[vr[0]];
        return STATUS_OK;
    }
    if (!all_accessible(instance, function, vr, n, value, VAR_REAL, 0)) {
        return STATUS_ERROR;
    }
    values = values_to_get(instance, &status);
    for (i = 0; i < n; i++) {
        if (vr[i] < MODEL_VARIABLE_COUNT) {
            value[i] = values->real_value[vr[i]];
            continue;
        }
        k = instance_derivative_of(instance, vr[i]);
        value[i] = k >= 0 ? DERIVATIVE_VALUE(k) : values->time;
    }
    return status;
}

Status instance_get_integer(Instance *instance, const char *function, const uint32_t vr[], size_t n, int32_t value[])
{
    size_t i;
    Status status;
    const ModelData *values;
    if (!all_accessible(instance, function, vr, n, value, VAR_INTEGER, 0)) {
        return STATUS_ERROR;
    }
    values = values_to_get(instance, &status);
    for (i = 0; i < n; i++) {
        value[i] = values->int_value[vr[i]];
    }
    return status;
}

static int boolean_at(const void *values, size_t size, size_t i)
{
    const unsigned char *bytes = (const unsigned char *)values + i * size;
    size_t k;
    for (k = 0; k < size; k++) {
        if (bytes[k] != 0) {
            return 1;
        }
    }
    return 0;
}

Status instance_set_boolean(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                            const void *value, size_t size)
{
    size_t i;
    if (!all_accessible(instance, function, vr, n, value, VAR_BOOLEAN, 1)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        instance->data.int_value[vr[i]] = boolean_at(value, size, i);
    }
    return STATUS_OK;
}

Status instance_get_boolean(Instance *instance, const char *function, const uint32_t vr[], size_t n, void *value,
                            size_t size)
{
    size_t i;
    Status status;
    const ModelData *values;
    if (!all_accessible(instance, function, vr, n, value, VAR_BOOLEAN, 0)) {
        return STATUS_ERROR;
    }
    values = values_to_get(instance, &status);
    for (i = 0; i < n; i++) {
        unsigned char *at = (unsigned char *)value + i * size;
        int truth = values->int_value[vr[i]] != 0;
        if (size == sizeof(int)) {
            memcpy(at, &truth, sizeof truth);
        } else {
            memset(at, 0, size);
            at[0] = (unsigned char)truth;
        }
    }
    return status;
}

/* Characters (code points, as Python's len()) of the UTF-8 ``text`` of ``length`` bytes. */
size_t characters(const char *text, size_t length)
{
    size_t count = 0, at;
    for (at = 0; at < length; at++) {
        count += ((unsigned char)text[at] & 0xC0u) != 0x80u;
    }
    return count;
}

Status instance_set_string(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                           const char *const value[])
{
    char *copies[MODEL_VARIABLE_COUNT] = {NULL};
    char number[24], limit[24];
    size_t i, count;
    if (!all_accessible(instance, function, vr, n, value, VAR_STRING, 1)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        if (value[i] == NULL) {
            return instance_fail(instance, instance->fmi_prefix, function, ": null string for ",
                                 model_variables[vr[i]].name, (const char *)NULL);
        }
        count = characters(value[i], strlen(value[i]));
        if (count > FMU_MAX_STRING) { /* model_adapter's refusal */
            snprintf(number, sizeof number, "%lu", (unsigned long)count);
            snprintf(limit, sizeof limit, "%d", FMU_MAX_STRING);
            return instance_fail(instance, instance->fmi_prefix, function, ": ", model_variables[vr[i]].name, " is ",
                                 number, " characters long (at most ", limit, ")", (const char *)NULL);
        }
    }
    for (i = 0; i < n; i++) { /* all or nothing: a later copy may fail for memory */
        free(copies[vr[i]]);
        copies[vr[i]] = copy_text(value[i], strlen(value[i]));
        if (copies[vr[i]] == NULL) {
            free_strings(copies);
            return instance_fail(instance, instance->fmi_prefix, function, ": out of memory", (const char *)NULL);
        }
    }
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (copies[i] != NULL) {
            free(instance->data.string_value[i]);
            instance->data.string_value[i] = copies[i];
        }
    }
    instance->epoch++;
    return STATUS_OK;
}

Status instance_get_string(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                           const char *value[])
{
    size_t i;
    if (!all_accessible(instance, function, vr, n, value, VAR_STRING, 0)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        value[i] = instance->data.string_value[vr[i]];
    }
    return STATUS_OK;
}

Status instance_no_variables_of(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                                const char *type, int setting)
{
    char number[24];
    if (!all_accessible(instance, function, vr, 0, NULL, VAR_REAL, setting)) {
        return STATUS_ERROR;
    }
    if (n == 0) {
        return STATUS_OK;
    }
    if (vr == NULL) {
        return instance_fail(instance, instance->fmi_prefix, function, ": null array of value references",
                             (const char *)NULL);
    }
    snprintf(number, sizeof number, "%lu", (unsigned long)vr[0]);
    if (vr[0] < MODEL_VARIABLE_COUNT) {
        return instance_fail(instance, instance->fmi_prefix, function, ": variable ", model_variables[vr[0]].name,
                             " (value reference ", number, ") is of type ", type_name(model_variables[vr[0]].type),
                             ", not ", type, (const char *)NULL);
    }
    return instance_fail(instance, instance->fmi_prefix, function, ": value reference ", number,
                         " is not a variable of type ", type, (const char *)NULL);
}

static const char *const LOG_CATEGORIES[] = {"logStatusWarning", "logStatusDiscard", "logStatusError",
                                             "logStatusFatal", "logAll"};

Status instance_set_debug_logging(Instance *instance, const char *function, int logging_on, size_t n,
                                  const char *const categories[])
{
    size_t i, j;
    if (n > 0 && categories == NULL) {
        return instance_fail(instance, instance->fmi_prefix, function, ": null array of categories",
                             (const char *)NULL);
    }
    for (i = 0; i < n; i++) {
        int known = 0;
        for (j = 0; j < sizeof LOG_CATEGORIES / sizeof LOG_CATEGORIES[0]; j++) {
            known = known || (categories[i] != NULL && strcmp(categories[i], LOG_CATEGORIES[j]) == 0);
        }
        if (!known) {
            return instance_fail(instance, instance->fmi_prefix, function, ": unknown log category '",
                                 categories[i] ? categories[i] : "(null)", "'", (const char *)NULL);
        }
    }
    instance->logging_on = logging_on;
    return STATUS_OK;
}

Status instance_unsupported(Instance *instance, const char *function)
{
    return instance_fail(instance, instance->fmi_prefix, function,
                         " is not supported by this FMU", (const char *)NULL);
}

