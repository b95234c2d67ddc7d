/* Checks of the native FMUs' shared layer (SteppedModel.parameter_errors,
 * input_errors, output_errors of driveline/model.py), with the Python core's wording. */
#include "fmu_instance.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* A number as a message shows it: an Integer's digits, a Real's repr(), or in the display unit. */
static void show(double value, int integer, int display, const VariableInfo *v, char *out, size_t size)
{
    if (display) {
        python_format_g(v->display_factor * value + v->display_offset, 6, out, size);
    } else if (integer) {
        snprintf(out, size, "%ld", (long)value);
    } else {
        python_float_repr(value, out, size);
    }
}

/* Fills a generated template with ``value`` (of variable ``v``) and ``bound``. */
static void add_message(Messages *out, const MessageTemplate *message, const VariableInfo *v, double value,
                        double bound, int integer_bound)
{
    char text[FMU_MESSAGE_SIZE] = "", shown[40];
    int i;
    for (i = 0; i < 3; i++) {
        const MessagePiece *piece = &message->pieces[i];
        strncat(text, piece->text, sizeof text - strlen(text) - 1);
        if (piece->slot == SLOT_END) {
            break;
        }
        if (piece->slot == SLOT_VALUE_REPR || piece->slot == SLOT_VALUE_DISPLAY) {
            show(value, v->type == VAR_INTEGER, piece->slot == SLOT_VALUE_DISPLAY, v, shown, sizeof shown);
        } else {
            show(bound, integer_bound, piece->slot == SLOT_BOUND_DISPLAY, v, shown, sizeof shown);
        }
        strncat(text, shown, sizeof text - strlen(text) - 1);
    }
    messages_add(out, text, (const char *)NULL);
}

#if MODEL_EXTRA_MESSAGE_COUNT > 0 || MODEL_RELATION_COUNT > 0 /* what the model's own checks and its relations read */
static double value_of(const ModelData *data, int variable)
{
    VariableType type = model_variables[variable].type;
    return type == VAR_INTEGER || type == VAR_BOOLEAN ? (double)data->int_value[variable]
                                                      : data->real_value[variable];
}
#endif

#if MODEL_EXTRA_MESSAGE_COUNT > 0
void messages_add_extra(Messages *out, const ModelData *data, int message)
{
    const ExtraMessage *extra = &model_extra_messages[message];
    add_message(out, &extra->message, &model_variables[extra->variable], value_of(data, extra->variable), 0.0, 0);
}
#endif

/* ---- checks (SteppedModel.parameter_errors, input_errors, output_errors) --------------- */

/* The groups of model_checked_ranges (model_checked_from): the parameters, the inputs, the outputs and locals. */
typedef enum { CHECKED_PARAMETERS, CHECKED_INPUTS, CHECKED_COMPUTED } CheckedGroup;

static const char *causality_name(Causality causality)
{
    static const char *const names[] = {"parameter", "input", "output", "local"};
    return names[causality];
}

/* SteppedModel._range_error for every variable of ``group``: finite, then the declared bounds (the
 * generated list of the variables that have a check of these; the outputs' finiteness: output_errors). */
static void range_errors(const ModelData *data, CheckedGroup group, Messages *out)
{
    int k;
    for (k = model_checked_from[group]; k < model_checked_from[group + 1]; k++) {
        const CheckedRange *range = &model_checked_ranges[k];
        const VariableInfo *v;
        const MessageTemplate *message = NULL;
        double value = range->real ? data->real_value[range->variable] : (double)data->int_value[range->variable];
        if (value >= range->low && value <= range->high) {
            continue; /* the common case: nothing to say */
        }
        v = &model_variables[range->variable];
        if (v->type == VAR_REAL && !isfinite(value)) {
            message = &v->not_finite;
        } else if (v->has_min && (v->min_exclusive ? !(value > v->min) : value < v->min)) {
            message = &v->outside_min;
        } else if (v->has_max && (v->max_exclusive ? !(value < v->max) : value > v->max)) {
            message = &v->outside_max;
        }
        if (message != NULL) {
            add_message(out, message, v, value, 0.0, 0);
        }
    }
}

/* SteppedModel._relation_error for every declared relation checked with the inputs (``inputs``)
 * or with the parameters. */
static void relation_errors(const ModelData *data, int inputs, Messages *out)
{
#if MODEL_RELATION_COUNT > 0
    int i;
    for (i = 0; i < MODEL_RELATION_COUNT; i++) {
        const RelationInfo *r = &model_relations[i];
        double left, right, bound;
        int holds;
        if (r->involves_input != inputs) { /* the other group's */
            continue;
        }
        left = value_of(data, r->lhs);
        right = r->rhs >= 0 ? value_of(data, r->rhs) : r->constant;
        bound = r->scale == 1.0 && r->offset == 0.0 ? right : r->scale * right + r->offset;
        holds = r->op == OP_LT ? left < bound : r->op == OP_LE ? left <= bound : r->op == OP_GT ? left > bound
                                                                                   : left >= bound;
        if (!holds) {
            add_message(out, &r->message, &model_variables[r->lhs], left, bound, r->integer_bound);
        }
    }
#else
    (void)data;
    (void)inputs;
    (void)out;
#endif
}

/* The checks of one causality in the core's order: bounds, then relations, then the model's own
 * (each only if the ones before found nothing). */
static void causality_errors(const ModelData *data, CheckedGroup group, int inputs,
                             void (*extra)(const ModelData *, Messages *), Messages *out)
{
    int before = out->count;
    range_errors(data, group, out);
    if (out->count == before) {
        relation_errors(data, inputs, out);
    }
    if (out->count == before && extra != NULL) {
        extra(data, out);
    }
}

void parameter_errors(const ModelData *data, Messages *out)
{
    causality_errors(data, CHECKED_PARAMETERS, 0, model_hooks.extra_parameter_errors, out);
}

void instance_parameter_errors(Instance *instance, const ModelData *data)
{
    int before = instance->messages.count;
    if (!instance->parameters_checked) {
        parameter_errors(data, &instance->messages);
        instance->parameters_checked = instance->messages.count == before;
    }
}

void input_errors(const ModelData *data, Messages *out)
{
    causality_errors(data, CHECKED_INPUTS, 1, model_hooks.extra_input_errors, out);
}

typedef enum { SUM_FINITE, SUM_NOT_FINITE, SUM_FAILED } SumOutcome;

/* Whether the Real outputs and locals are finite values whose partial sums stay far from overflow, in any
 * order (their magnitudes' sum, in four running sums, at most DBL_MAX / 4; a value that is not finite makes it
 * NaN or infinite): then math.fsum of them is finite, whatever fsum_outcome would find. */
static int far_from_overflow(const ModelData *data)
{
    double sums[4] = {0.0, 0.0, 0.0, 0.0};
    const int *names = model_real_computed;
    int i;
    for (i = 0; i + 4 <= MODEL_REAL_COMPUTED_COUNT; i += 4) {
        sums[0] += fabs(data->real_value[names[i]]);
        sums[1] += fabs(data->real_value[names[i + 1]]);
        sums[2] += fabs(data->real_value[names[i + 2]]);
        sums[3] += fabs(data->real_value[names[i + 3]]);
    }
    for (; i < MODEL_REAL_COMPUTED_COUNT; i++) {
        sums[0] += fabs(data->real_value[names[i]]);
    }
    return (sums[0] + sums[1]) + (sums[2] + sums[3]) <= DBL_MAX / 4.0;
}

/* What Python's math.fsum does with these values (output_errors sums the Real outputs and locals with it), once
 * far_from_overflow could not tell. */
static SumOutcome fsum_outcome(const double values[], int count, Failure *failure)
{
    double sum = 0.0;
    const char *message;
    ErrorKind kind = python_fsum(values, count, &sum, &message);
    if (kind != ERROR_NONE) {
        *failure = FAILURE(kind, message);
        return SUM_FAILED;
    }
    return isfinite(sum) ? SUM_FINITE : SUM_NOT_FINITE;
}

/* SteppedModel.output_errors of the outputs and locals (not finite, then beyond the declared bounds); an
 * arithmetic failure of the sum itself becomes ``failure``. */
void output_errors(const ModelData *data, Messages *out, Failure *failure)
{
    double values[MODEL_REAL_COMPUTED_COUNT + 1];
    const int *names = model_real_computed;
    int count = MODEL_REAL_COMPUTED_COUNT, i;
    char shown[40];
    SumOutcome outcome;
    if (far_from_overflow(data)) { /* the common case: no copy, no exact sum */
        range_errors(data, CHECKED_COMPUTED, out);
        return;
    }
    for (i = 0; i < count; i++) {
        values[i] = data->real_value[names[i]];
    }
    outcome = fsum_outcome(values, count, failure);
    if (outcome == SUM_FINITE) {
        range_errors(data, CHECKED_COMPUTED, out);
    } else if (outcome == SUM_NOT_FINITE) {
        for (i = 0; i < count; i++) {
            if (!isfinite(values[i])) {
                const VariableInfo *v = &model_variables[names[i]];
                python_float_repr(values[i], shown, sizeof shown);
                messages_add(out, causality_name(v->causality), " ", v->name, " is not finite (", shown,
                             "); the step was not taken", (const char *)NULL);
            }
        }
    }
}


/* SteppedModel.state_from_saved's check of the values a serialized state restores, as the model could have
 * left them: the times finite, then every Real output and local finite, then each within its bounds. */
void restored_errors(const ModelData *data, double start_time, Messages *out)
{
    char shown[40];
    int i;
    if (!isfinite(start_time) || !isfinite(data->time)) {
        python_float_repr(isfinite(start_time) ? data->time : start_time, shown, sizeof shown);
        messages_add(out, isfinite(start_time) ? "time = " : "start time = ", shown, " is not finite",
                     (const char *)NULL);
        return;
    }
    for (i = 0; i < MODEL_REAL_COMPUTED_COUNT; i++) {
        const VariableInfo *v = &model_variables[model_real_computed[i]];
        if (!isfinite(data->real_value[model_real_computed[i]])) {
            python_float_repr(data->real_value[model_real_computed[i]], shown, sizeof shown);
            messages_add(out, causality_name(v->causality), " ", v->name, " = ", shown, " is not finite",
                         (const char *)NULL);
            return;
        }
    }
    range_errors(data, CHECKED_COMPUTED, out);
}
