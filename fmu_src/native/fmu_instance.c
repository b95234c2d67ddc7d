/* Shared core of the native co-simulation FMUs: life cycle, checks, stepping, values, FMU state.
 *
 * Stepping mirrors driveline/model.py (SteppedModel.initialize, step, _undoable, output_errors),
 * including the wording of every reason, so a host sees the same refusals from either FMU.
 */
#include "fmu_instance.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- text -------------------------------------------------------------------------------- */

static void append_pieces(char *out, size_t size, const char *first, va_list pieces)
{
    size_t used = strlen(out);
    const char *piece;
    for (piece = first; piece != NULL; piece = va_arg(pieces, const char *)) {
        size_t length = strlen(piece);
        if (used + 1 >= size) {
            break;
        }
        if (length > size - 1 - used) {
            length = size - 1 - used;
        }
        memcpy(out + used, piece, length);
        used += length;
        out[used] = '\0';
    }
}

void messages_add(Messages *out, const char *first, ...)
{
    va_list pieces;
    if (out->count >= FMU_MAX_MESSAGES) {
        return;
    }
    out->text[out->count][0] = '\0';
    va_start(pieces, first);
    append_pieces(out->text[out->count], FMU_MESSAGE_SIZE, first, pieces);
    va_end(pieces);
    out->count++;
}

/* Python's format(value, '.6g') (glibc would print a negative NaN as "-nan"). */
static void python_g6(double value, char *out, size_t size)
{
    if (isnan(value)) {
        snprintf(out, size, "nan");
    } else {
        snprintf(out, size, "%.6g", value);
    }
}

/* A number as a message shows it: an Integer's digits, a Real's repr(), or in the display unit. */
static void show(double value, int integer, int display, const VariableInfo *v, char *out, size_t size)
{
    if (display) {
        python_g6(v->display_factor * value + v->display_offset, out, size);
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

static double value_of(const ModelData *data, int variable)
{
    VariableType type = model_variables[variable].type;
    return type == VAR_INTEGER || type == VAR_BOOLEAN ? (double)data->int_value[variable]
                                                      : data->real_value[variable];
}

#if MODEL_EXTRA_MESSAGE_COUNT > 0
void messages_add_extra(Messages *out, const ModelData *data, int message)
{
    const ExtraMessage *extra = &model_extra_messages[message];
    add_message(out, &extra->message, &model_variables[extra->variable], value_of(data, extra->variable), 0.0, 0);
}
#endif

/* ---- checks (SteppedModel.parameter_errors, input_errors, output_errors) --------------- */

/* SteppedModel._range_error for every variable of ``causality``: finite, then the declared bounds. */
static void range_errors(const ModelData *data, Causality causality, Messages *out)
{
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        const VariableInfo *v = &model_variables[i];
        const MessageTemplate *message = NULL;
        double value = value_of(data, i);
        if (v->causality != causality) {
            continue;
        }
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
        double left = value_of(data, r->lhs), right = r->rhs >= 0 ? value_of(data, r->rhs) : r->constant;
        double bound = r->scale == 1.0 && r->offset == 0.0 ? right : r->scale * right + r->offset;
        int holds = r->op == OP_LT ? left < bound : r->op == OP_LE ? left <= bound : r->op == OP_GT ? left > bound
                                                                                                     : left >= bound;
        if (r->involves_input == inputs && !holds) {
            add_message(out, &r->message, &model_variables[r->lhs], left, bound, r->integer_bound);
        }
    }
#else
    (void)data;
    (void)inputs;
    (void)out;
#endif
}

static void parameter_errors(const ModelData *data, Messages *out)
{
    int before = out->count;
    range_errors(data, CAUSALITY_PARAMETER, out);
    if (out->count == before) {
        relation_errors(data, 0, out);
    }
    if (out->count == before && model_hooks.extra_parameter_errors != NULL) {
        model_hooks.extra_parameter_errors(data, out);
    }
}

static void input_errors(const ModelData *data, Messages *out)
{
    int before = out->count;
    range_errors(data, CAUSALITY_INPUT, out);
    if (out->count == before) {
        relation_errors(data, 1, out);
    }
    if (out->count == before && model_hooks.extra_input_errors != NULL) {
        model_hooks.extra_input_errors(data, out);
    }
}

typedef enum { SUM_FINITE, SUM_NOT_FINITE, SUM_OVERFLOW, SUM_OPPOSITE_INFINITIES } SumOutcome;

/* What Python's math.fsum does with these values (output_errors sums the Real outputs with it);
 * exactly only where a partial sum could come near overflow. */
static SumOutcome fsum_outcome(const double values[], int count)
{
    double magnitude = 0.0, sum = 0.0;
    const char *failure;
    int i;
    for (i = 0; i < count; i++) {
        magnitude += fabs(values[i]);
    }
    if (magnitude <= DBL_MAX / 4.0) { /* finite values whose partial sums stay far from overflow */
        return SUM_FINITE;
    }
    failure = python_fsum(values, count, &sum);
    if (failure != NULL) {
        return failure[0] == 'i' ? SUM_OVERFLOW : SUM_OPPOSITE_INFINITIES;
    }
    return isfinite(sum) ? SUM_FINITE : SUM_NOT_FINITE;
}

/* SteppedModel.output_errors (not finite, then beyond the declared bounds); an arithmetic failure
 * of the sum itself becomes ``failure``. */
static void output_errors(const ModelData *data, Messages *out, const char **failure)
{
    double values[MODEL_VARIABLE_COUNT];
    int names[MODEL_VARIABLE_COUNT], count = 0, i;
    char shown[40];
    SumOutcome outcome;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].causality == CAUSALITY_OUTPUT && model_variables[i].type == VAR_REAL) {
            names[count] = i;
            values[count++] = data->real_value[i];
        }
    }
    outcome = fsum_outcome(values, count);
    if (outcome == SUM_OVERFLOW) {
        *failure = "OverflowError: intermediate overflow in fsum";
    } else if (outcome == SUM_OPPOSITE_INFINITIES) {
        *failure = "ValueError: -inf + inf in fsum";
    } else if (outcome == SUM_FINITE) {
        range_errors(data, CAUSALITY_OUTPUT, out);
    } else if (outcome == SUM_NOT_FINITE) {
        for (i = 0; i < count; i++) {
            if (!isfinite(values[i])) {
                python_float_repr(values[i], shown, sizeof shown);
                messages_add(out, "output ", model_variables[names[i]].name, " is not finite (", shown,
                             "); the step was not taken", (const char *)NULL);
            }
        }
    }
}

/* ---- stepping (SteppedModel.initialize, step, _undoable) --------------------------------- */

typedef enum { ACTION_START, ACTION_ADVANCE } Action;

/* Runs the action; if it fails arithmetically or leaves a non-finite output, undoes it and says why
 * ("the start values ..." or "the step from t = ... s ...", formatted only then). */
static void undoable(Instance *instance, Action action, double time, double step_size)
{
    ModelData snapshot = instance->data;
    Messages *out = &instance->messages;
    int before = out->count;
    char shown[40];
    const char *failure;
    if (model_hooks.at_time != NULL) {
        failure = model_hooks.at_time(&instance->data, action == ACTION_START ? time : time + step_size);
    } else if (action == ACTION_START) {
        failure = model_hooks.start(&instance->data, time);
    } else {
        failure = model_hooks.advance(&instance->data, time, step_size);
    }
    if (failure == NULL) {
        output_errors(&instance->data, out, &failure);
    }
    if (failure != NULL && action == ACTION_START) {
        messages_add(out, "the start values could not be computed (", failure, ")", (const char *)NULL);
    } else if (failure != NULL) {
        python_float_repr(time, shown, sizeof shown);
        messages_add(out, "the step from t = ", shown, " s could not be computed (", failure, ")", (const char *)NULL);
    }
    if (out->count != before) {
        instance->data = snapshot;
    }
}

static void initialize(Instance *instance, double start_time)
{
    Messages *out = &instance->messages;
    parameter_errors(&instance->data, out);
    input_errors(&instance->data, out);
    if (out->count) {
        return;
    }
    instance->data.time = start_time;
    undoable(instance, ACTION_START, start_time, 0.0);
    instance->data.initialized = out->count == 0;
}

static void step(Instance *instance, double current_time, double step_size)
{
    Messages *out = &instance->messages;
    char shown[40];
    if (!instance->data.initialized) {
        initialize(instance, current_time);
        if (out->count) {
            return;
        }
    }
    if (!(isfinite(step_size) && step_size > 0.0)) {
        python_float_repr(step_size, shown, sizeof shown);
        messages_add(out, "communication step size must be positive and finite, got ", shown, (const char *)NULL);
        return;
    }
    parameter_errors(&instance->data, out);
    input_errors(&instance->data, out);
    if (out->count) {
        return;
    }
    undoable(instance, ACTION_ADVANCE, current_time, step_size);
    if (out->count == 0) {
        instance->data.time = current_time + step_size;
    }
}

/* ---- logging ------------------------------------------------------------------------------ */

static const char *category_of(Status status)
{
    return status == STATUS_ERROR ? "logStatusError" : status == STATUS_DISCARD ? "logStatusDiscard" : "logAll";
}

void instance_log(Instance *instance, Status status, const char *first, ...)
{
    char message[FMU_MESSAGE_SIZE] = "";
    va_list pieces;
    va_start(pieces, first);
    append_pieces(message, sizeof message, first, pieces);
    va_end(pieces);
    instance->emit(instance, status, category_of(status), message);
}

void instance_log_messages(Instance *instance, Status status)
{
    int i;
    for (i = 0; i < instance->messages.count; i++) {
        instance->emit(instance, status, category_of(status), instance->messages.text[i]);
    }
}

Status instance_fail(Instance *instance, const char *first, ...)
{
    char message[FMU_MESSAGE_SIZE] = "";
    va_list pieces;
    va_start(pieces, first);
    append_pieces(message, sizeof message, first, pieces);
    va_end(pieces);
    if (instance->mode != MODE_ERROR || strcmp(message, instance->refusal) != 0) { /* repeated: logged once */
        instance->emit(instance, STATUS_ERROR, "logStatusError", message);
        strcpy(instance->refusal, message);
    }
    instance->mode = MODE_ERROR;
    return STATUS_ERROR;
}

static const char *mode_name(Mode mode)
{
    static const char *const names[] = {"Instantiated", "InitializationMode", "StepMode", "Terminated", "Error"};
    return names[mode];
}

int instance_allows(Instance *instance, unsigned allowed, const char *function)
{
    if (allowed & MODE_BIT(instance->mode)) {
        return 1;
    }
    instance_fail(instance, instance->fmi_prefix, function, " is not allowed in ", mode_name(instance->mode),
                  instance->mode == MODE_ERROR ? " (after an error only reset, free, set FMU state and get are)" : "",
                  (const char *)NULL);
    return 0;
}

/* ---- life cycle ------------------------------------------------------------------------------ */

/* A copy of ``text`` (``length`` bytes), or NULL without memory. */
static char *copy_text(const char *text, size_t length)
{
    char *copy = malloc(length + 1);
    if (copy != NULL) {
        memcpy(copy, text, length);
        copy[length] = '\0';
    }
    return copy;
}

static void free_strings(char *strings[MODEL_VARIABLE_COUNT])
{
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        free(strings[i]);
        strings[i] = NULL;
    }
}

/* Copies of the String variables of ``from`` (their start values where ``from`` is NULL) into
 * ``to``; 0 (nothing allocated) without memory. */
static int copy_strings(char *const from[MODEL_VARIABLE_COUNT], char *to[MODEL_VARIABLE_COUNT])
{
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        to[i] = NULL;
    }
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        const char *text = from != NULL ? from[i] : model_variables[i].start_string;
        if (model_variables[i].type == VAR_STRING) {
            to[i] = copy_text(text != NULL ? text : "", text != NULL ? strlen(text) : 0);
            if (to[i] == NULL) {
                free_strings(to);
                return 0;
            }
        }
    }
    return 1;
}

/* Drops the model's derived data (rebuilt at the next check). */
static void clear_cache(Instance *instance)
{
    if (instance->cache.derived != NULL && model_hooks.free_derived != NULL) {
        model_hooks.free_derived(instance->cache.derived);
    }
    instance->cache.derived = NULL;
}

Status instance_reset(Instance *instance)
{
    char *strings[MODEL_VARIABLE_COUNT];
    int i;
    if (!copy_strings(NULL, strings)) {
        return instance_fail(instance, instance->fmi_prefix, "Reset: out of memory", (const char *)NULL);
    }
    free_strings(instance->data.string_value);
    clear_cache(instance);
    memset(&instance->data, 0, sizeof instance->data);
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        instance->data.real_value[i] = model_variables[i].start;
        instance->data.int_value[i] = (int32_t)model_variables[i].start;
        instance->data.string_value[i] = strings[i];
    }
    instance->data.cache = &instance->cache;
    if (model_hooks.reset_internal != NULL) {
        model_hooks.reset_internal(&instance->data);
    }
    instance->start_time = 0.0;
    instance->terminated = 0;
    instance->refusal[0] = '\0';
    instance->mode = MODE_INSTANTIATED;
    return STATUS_OK;
}

Status instance_set_start_time(Instance *instance, const char *function, double start_time)
{
    char shown[40];
    if (!isfinite(start_time)) {
        python_float_repr(start_time, shown, sizeof shown);
        return instance_fail(instance, instance->fmi_prefix, function, ": startTime = ", shown, " is not finite",
                             (const char *)NULL);
    }
    instance->start_time = start_time;
    instance->data.time = start_time;
    return STATUS_OK;
}

Status instance_exit_initialization(Instance *instance)
{
    if (!instance_allows(instance, MODE_BIT(MODE_INITIALIZATION), "ExitInitializationMode")) {
        return STATUS_ERROR;
    }
    instance->messages.count = 0;
    parameter_errors(&instance->data, &instance->messages);
    if (instance->messages.count) { /* parameters that no input can make valid: Error */
        instance_log_messages(instance, STATUS_ERROR);
        instance->mode = MODE_ERROR;
        return STATUS_ERROR;
    }
    initialize(instance, instance->start_time);
    instance_log_messages(instance, STATUS_ERROR); /* inputs the host may still correct: logged, and OK */
    instance->mode = MODE_STEP;
    return STATUS_OK;
}

Status instance_terminate(Instance *instance)
{
    if (!instance_allows(instance, MODE_BIT(MODE_STEP), "Terminate")) {
        return STATUS_ERROR;
    }
    instance->mode = MODE_TERMINATED;
    return STATUS_OK;
}

Status instance_do_step(Instance *instance, double current_time, double step_size)
{
    char shown[40];
    if (!isfinite(current_time)) {
        python_float_repr(current_time, shown, sizeof shown);
        return instance_fail(instance, instance->fmi_prefix, "DoStep: currentCommunicationPoint = ", shown,
                             " is not finite", (const char *)NULL);
    }
    if (current_time < instance->data.time - MODEL_TIME_TOLERANCE * fmax(1.0, fabs(instance->data.time))) {
        char reached[40];
        python_float_repr(current_time, shown, sizeof shown);
        python_float_repr(instance->data.time, reached, sizeof reached);
        return instance_fail(instance, instance->fmi_prefix, "DoStep: currentCommunicationPoint = ", shown,
                             " is before the time the FMU reached, ", reached, (const char *)NULL);
    }
    instance->messages.count = 0;
    step(instance, current_time, step_size);
    instance->terminated = instance->messages.count > 0;
    if (instance->terminated) { /* the same call would be refused again: its reasons are logged once */
        if (strcmp(instance->refusal, instance->messages.text[0]) != 0) {
            instance_log_messages(instance, STATUS_ERROR);
            strcpy(instance->refusal, instance->messages.text[0]);
        }
        return STATUS_DISCARD;
    }
    instance->refusal[0] = '\0';
    return STATUS_OK;
}

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

/* 1 when ``reference`` names a variable of ``type`` that may be got (``setting`` 0) or set now;
 * else Error, with the reason logged. FMI 3.0's independent variable time is a Real to get only. */
static int accessible(Instance *instance, const char *function, uint32_t reference, VariableType type, int setting)
{
    const VariableInfo *v = reference < MODEL_VARIABLE_COUNT ? &model_variables[reference] : NULL;
    const char *problem = NULL;
    char number[24];
    if (is_time(instance, reference)) {
        problem = type == VAR_REAL && !setting ? NULL : " is the independent variable time, a Real that cannot be set";
    } else if (v == NULL) {
        problem = " is unknown";
    } else if (v->type != type) {
        problem = type == VAR_REAL      ? " is not of type Real"
                  : type == VAR_INTEGER ? " is not of type Integer"
                  : type == VAR_BOOLEAN ? " is not of type Boolean"
                                        : " is not of type String";
    } else if (setting && v->causality == CAUSALITY_OUTPUT) {
        problem = " is an output and cannot be set";
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

/* 1 when the call may get or set these ``n`` references now (checked before any value moves). */
static int all_accessible(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                          const void *values, VariableType type, int setting)
{
    size_t i;
    if (!instance_allows(instance, setting ? SETTABLE_MODES : ANY_MODE, function)) {
        return 0;
    }
    if (n > 0 && (vr == NULL || values == NULL)) {
        instance_fail(instance, instance->fmi_prefix, function, ": null array of value references or values",
                      (const char *)NULL);
        return 0;
    }
    for (i = 0; i < n; i++) {
        if (!accessible(instance, function, vr[i], type, setting)) {
            return 0;
        }
    }
    return 1;
}

Status instance_set_real(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                         const double value[])
{
    size_t i;
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
        return instance_fail(instance, instance->fmi_prefix, function, ": more derivatives than the model's inputs hold",
                             (const char *)NULL);
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
    if (!all_accessible(instance, function, vr, n, value, VAR_REAL, 0)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        value[i] = is_time(instance, vr[i]) ? instance->data.time : instance->data.real_value[vr[i]];
    }
    return STATUS_OK;
}

Status instance_get_integer(Instance *instance, const char *function, const uint32_t vr[], size_t n, int32_t value[])
{
    size_t i;
    if (!all_accessible(instance, function, vr, n, value, VAR_INTEGER, 0)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        value[i] = instance->data.int_value[vr[i]];
    }
    return STATUS_OK;
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
    if (!all_accessible(instance, function, vr, n, value, VAR_BOOLEAN, 0)) {
        return STATUS_ERROR;
    }
    for (i = 0; i < n; i++) {
        unsigned char *at = (unsigned char *)value + i * size;
        int truth = instance->data.int_value[vr[i]] != 0;
        if (size == sizeof(int)) {
            memcpy(at, &truth, sizeof truth);
        } else {
            memset(at, 0, size);
            at[0] = (unsigned char)truth;
        }
    }
    return STATUS_OK;
}

/* Characters (code points, as Python's len()) of the UTF-8 ``text`` of ``length`` bytes. */
static size_t characters(const char *text, size_t length)
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

Status instance_set_debug_logging(Instance *instance, const char *function, size_t n, const char *const categories[])
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
    return STATUS_OK;
}

Status instance_unsupported(Instance *instance, const char *function)
{
    return instance_fail(instance, instance->fmi_prefix, function,
                         " is not supported by this co-simulation FMU", (const char *)NULL);
}

/* ---- FMU state ---------------------------------------------------------------------------- */

#define STATE_TAG 0x4452564C53544154ull /* marks a live StoredState */
#define STATE_FORMAT 4u /* 4: eleven internal slots (3: String values; 2: six internal slots; 1 had four) */
static const char STATE_MAGIC[8] = {'D', 'R', 'V', 'L', 'S', 'T', 'A', 'T'};

/* A stored state owns the copies of its strings; its ``data.cache`` is NULL. */
struct StoredState {
    uint64_t tag;
    Mode mode;
    double start_time;
    ModelData data;
};

static const StoredState *live_state(Instance *instance, const char *function, const void *state)
{
    const StoredState *stored = state;
    if (stored == NULL || stored->tag != STATE_TAG) {
        instance_fail(instance, instance->fmi_prefix, function, ": not an FMU state of this FMU (or already freed)",
                      (const char *)NULL);
        return NULL;
    }
    return stored;
}

/* Where a state goes: the live state the host hands back to be overwritten (the standard allows
 * it), or a new one; NULL (Error logged) if neither. */
static StoredState *state_slot(Instance *instance, const char *function, void *given)
{
    StoredState *slot;
    if (given != NULL) {
        return live_state(instance, function, given) != NULL ? given : NULL;
    }
    slot = calloc(1, sizeof *slot);
    if (slot == NULL) {
        instance_fail(instance, instance->fmi_prefix, function, ": out of memory", (const char *)NULL);
    }
    return slot;
}

/* Stores ``data`` (whose strings become the state's) in ``slot``, dropping what it held. */
static void store(StoredState *slot, Mode mode, double start_time, const ModelData *data)
{
    if (slot->tag == STATE_TAG) {
        free_strings(slot->data.string_value);
    }
    slot->tag = STATE_TAG;
    slot->mode = mode;
    slot->start_time = start_time;
    slot->data = *data;
    slot->data.cache = NULL;
}

Status state_get(Instance *instance, const char *function, void **state)
{
    StoredState *stored;
    ModelData data;
    if (!instance_allows(instance, ANY_MODE & ~MODE_BIT(MODE_ERROR), function)) {
        return STATUS_ERROR;
    }
    if (state == NULL) {
        return instance_fail(instance, instance->fmi_prefix, function, ": null state pointer", (const char *)NULL);
    }
    data = instance->data;
    if (!copy_strings(instance->data.string_value, data.string_value)) {
        return instance_fail(instance, instance->fmi_prefix, function, ": out of memory", (const char *)NULL);
    }
    stored = state_slot(instance, function, *state);
    if (stored == NULL) {
        free_strings(data.string_value);
        return STATUS_ERROR;
    }
    store(stored, instance->mode, instance->start_time, &data);
    *state = stored;
    return STATUS_OK;
}

/* The model's derived data stays: the model rebuilds it at the next check if the restored
 * parameters differ from those it was built for. */
Status state_set(Instance *instance, const char *function, const void *state)
{
    const StoredState *stored = live_state(instance, function, state);
    char *strings[MODEL_VARIABLE_COUNT];
    int i;
    if (stored == NULL) {
        return STATUS_ERROR;
    }
    if (!copy_strings(stored->data.string_value, strings)) {
        return instance_fail(instance, instance->fmi_prefix, function, ": out of memory", (const char *)NULL);
    }
    free_strings(instance->data.string_value);
    instance->mode = stored->mode;
    instance->start_time = stored->start_time;
    instance->data = stored->data;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        instance->data.string_value[i] = strings[i];
    }
    instance->data.cache = &instance->cache;
    instance->terminated = 0;
    instance->refusal[0] = '\0';
    return STATUS_OK;
}

Status state_free(Instance *instance, const char *function, void **state)
{
    StoredState *stored;
    if (state == NULL || *state == NULL) {
        return STATUS_OK;
    }
    if (live_state(instance, function, *state) == NULL) {
        return STATUS_ERROR;
    }
    stored = *state;
    free_strings(stored->data.string_value);
    stored->tag = 0;
    free(stored);
    *state = NULL;
    return STATUS_OK;
}

/* Serialized layout: magic, format, byte-order mark, token length and token, variable and slot
 * counts, mode, start time, time, initialized, Real values, Integer and Boolean values, internal
 * slots, each String variable's length (uint32) and bytes in value reference order, then an
 * FNV-1a checksum of everything before it. */
static size_t token_length(void)
{
    return strlen(MODEL_TOKEN);
}

/* The size of everything but the strings' lengths and bytes. */
static size_t fixed_serialized_size(void)
{
    return sizeof STATE_MAGIC + 5 * sizeof(uint32_t) + token_length() + 2 * sizeof(int32_t) + 2 * sizeof(double) +
           MODEL_VARIABLE_COUNT * (sizeof(double) + sizeof(int32_t)) + FMU_INTERNAL_SLOTS * sizeof(double) +
           sizeof(uint64_t);
}

static size_t state_serialized_size(const StoredState *stored)
{
    size_t size = fixed_serialized_size();
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].type == VAR_STRING) {
            size += sizeof(uint32_t) + strlen(stored->data.string_value[i]);
        }
    }
    return size;
}

Status state_size(Instance *instance, const char *function, const void *state, size_t *size)
{
    const StoredState *stored = live_state(instance, function, state);
    if (stored == NULL) {
        return STATUS_ERROR;
    }
    if (size == NULL) {
        return instance_fail(instance, instance->fmi_prefix, function, ": null size pointer", (const char *)NULL);
    }
    *size = state_serialized_size(stored);
    return STATUS_OK;
}

static uint64_t checksum(const char *bytes, size_t size)
{
    uint64_t hash = 14695981039346656037ull;
    size_t i;
    for (i = 0; i < size; i++) {
        hash = (hash ^ (unsigned char)bytes[i]) * 1099511628211ull;
    }
    return hash;
}

typedef struct {
    char *bytes;
    const char *read;
    size_t at;
} Cursor;

static void put(Cursor *cursor, const void *value, size_t size)
{
    memcpy(cursor->bytes + cursor->at, value, size);
    cursor->at += size;
}

static void take(Cursor *cursor, void *value, size_t size)
{
    memcpy(value, cursor->read + cursor->at, size);
    cursor->at += size;
}

static void header(uint32_t words[4])
{
    words[0] = STATE_FORMAT;
    words[1] = 0x01020304u; /* byte order */
    words[2] = (uint32_t)token_length();
    words[3] = MODEL_VARIABLE_COUNT;
}

Status state_serialize(Instance *instance, const char *function, const void *state, char *bytes, size_t size)
{
    const StoredState *stored = live_state(instance, function, state);
    Cursor cursor = {NULL, NULL, 0};
    uint32_t words[4], slots = FMU_INTERNAL_SLOTS, length;
    int32_t mode, initialized;
    uint64_t sum;
    int i;
    if (stored == NULL) {
        return STATUS_ERROR;
    }
    if (bytes == NULL || size < state_serialized_size(stored)) {
        return instance_fail(instance, instance->fmi_prefix, function, ": the buffer is smaller than the state size",
                             (const char *)NULL);
    }
    cursor.bytes = bytes;
    header(words);
    mode = (int32_t)stored->mode;
    initialized = stored->data.initialized;
    put(&cursor, STATE_MAGIC, sizeof STATE_MAGIC);
    put(&cursor, words, sizeof words);
    put(&cursor, MODEL_TOKEN, token_length());
    put(&cursor, &slots, sizeof slots);
    put(&cursor, &mode, sizeof mode);
    put(&cursor, &initialized, sizeof initialized);
    put(&cursor, &stored->start_time, sizeof(double));
    put(&cursor, &stored->data.time, sizeof(double));
    put(&cursor, stored->data.real_value, sizeof stored->data.real_value);
    put(&cursor, stored->data.int_value, sizeof stored->data.int_value);
    put(&cursor, stored->data.internal, sizeof stored->data.internal);
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].type == VAR_STRING) {
            length = (uint32_t)strlen(stored->data.string_value[i]);
            put(&cursor, &length, sizeof length);
            put(&cursor, stored->data.string_value[i], length);
        }
    }
    sum = checksum(bytes, cursor.at);
    put(&cursor, &sum, sizeof sum);
    return STATUS_OK;
}

static Status refuse_bytes(Instance *instance, const char *function, const char *why)
{
    return instance_fail(instance, instance->fmi_prefix, function, ": refused: ", why, (const char *)NULL);
}

/* The String values of a serialized state from ``cursor`` up to ``end`` (the checksum) into
 * ``strings``: 1, or 0 (nothing allocated) when a length runs beyond the bytes or the limit, a
 * string holds a NUL, or the bytes do not end where the strings do; -1 without memory. */
static int take_strings(Cursor *cursor, size_t end, char *strings[MODEL_VARIABLE_COUNT])
{
    uint32_t length;
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        strings[i] = NULL;
    }
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].type != VAR_STRING) {
            continue;
        }
        if (end - cursor->at < sizeof length) {
            free_strings(strings);
            return 0;
        }
        take(cursor, &length, sizeof length);
        if (length > FMU_MAX_STRING_BYTES || length > end - cursor->at ||
            memchr(cursor->read + cursor->at, '\0', length) != NULL ||
            characters(cursor->read + cursor->at, length) > FMU_MAX_STRING) {
            free_strings(strings);
            return 0;
        }
        strings[i] = copy_text(cursor->read + cursor->at, length);
        if (strings[i] == NULL) {
            free_strings(strings);
            return -1;
        }
        cursor->at += length;
    }
    if (cursor->at != end) {
        free_strings(strings);
        return 0;
    }
    return 1;
}

Status state_deserialize(Instance *instance, const char *function, const char *bytes, size_t size, void **state)
{
    Cursor cursor = {NULL, NULL, 0};
    uint32_t words[4], expected[4], slots;
    int32_t mode, initialized;
    uint64_t sum;
    StoredState *target;
    ModelData decoded;
    Mode decoded_mode;
    double decoded_start;
    int taken;
    if (state == NULL || (bytes == NULL && size > 0)) {
        return instance_fail(instance, instance->fmi_prefix, function, ": null argument", (const char *)NULL);
    }
    header(expected);
    cursor.read = bytes;
    if (size < sizeof STATE_MAGIC + sizeof words || memcmp(bytes, STATE_MAGIC, sizeof STATE_MAGIC) != 0) {
        return refuse_bytes(instance, function, "the bytes are not a serialized FMU state of these native FMUs");
    }
    cursor.at = sizeof STATE_MAGIC;
    take(&cursor, words, sizeof words);
    if (words[0] != expected[0] || words[1] != expected[1]) {
        return refuse_bytes(instance, function, "the state was written by another format version or platform");
    }
    if (words[2] != expected[2] || words[3] != expected[3] || size < fixed_serialized_size() ||
        (MODEL_STRING_COUNT == 0 && size != fixed_serialized_size()) ||
        memcmp(bytes + cursor.at, MODEL_TOKEN, token_length()) != 0) {
        return refuse_bytes(instance, function,
                            "the state belongs to another model or build (instantiation token differs)");
    }
    memcpy(&sum, bytes + size - sizeof sum, sizeof sum);
    if (checksum(bytes, size - sizeof sum) != sum) {
        return refuse_bytes(instance, function, "the state is corrupt (checksum mismatch)");
    }
    cursor.at += token_length();
    memset(&decoded, 0, sizeof decoded);
    take(&cursor, &slots, sizeof slots);
    take(&cursor, &mode, sizeof mode);
    take(&cursor, &initialized, sizeof initialized);
    if (slots != FMU_INTERNAL_SLOTS || mode < MODE_INSTANTIATED || mode > MODE_TERMINATED || initialized < 0 ||
        initialized > 1) {
        return refuse_bytes(instance, function, "the state holds impossible values");
    }
    take(&cursor, &decoded_start, sizeof(double));
    take(&cursor, &decoded.time, sizeof(double));
    take(&cursor, decoded.real_value, sizeof decoded.real_value);
    take(&cursor, decoded.int_value, sizeof decoded.int_value);
    take(&cursor, decoded.internal, sizeof decoded.internal);
    taken = take_strings(&cursor, size - sizeof sum, decoded.string_value);
    if (taken < 0) {
        return instance_fail(instance, instance->fmi_prefix, function, ": out of memory", (const char *)NULL);
    }
    if (taken == 0) {
        return refuse_bytes(instance, function, "the state holds impossible values");
    }
    decoded_mode = (Mode)mode;
    decoded.initialized = initialized;
    target = state_slot(instance, function, *state);
    if (target == NULL) {
        free_strings(decoded.string_value);
        return STATUS_ERROR;
    }
    store(target, decoded_mode, decoded_start, &decoded);
    *state = target;
    return STATUS_OK;
}

/* ---- instances ------------------------------------------------------------------------------ */

static int hex_digit(char c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1;
}

char *resource_folder_of_uri(const char *uri)
{
    const char *path;
    char *folder;
    size_t at = 0, length;
    if (uri == NULL || strncmp(uri, "file:", 5) != 0) {
        return NULL;
    }
    path = uri + 5;
    if (strncmp(path, "//", 2) == 0) { /* file://host/path: an empty host or localhost is this machine */
        path += 2;
        if (strncmp(path, "localhost", 9) == 0) {
            path += 9;
        }
        if (*path != '/') {
            return NULL;
        }
    }
    if (path[0] == '/' && path[1] != '\0' && path[2] == ':') { /* file:///C:/...: a drive letter */
        path++;
    }
    length = strlen(path);
    folder = malloc(length + 1);
    if (folder == NULL) {
        return NULL;
    }
    while (*path != '\0') {
        if (path[0] == '%' && hex_digit(path[1]) >= 0 && hex_digit(path[2]) >= 0) {
            folder[at++] = (char)(hex_digit(path[1]) * 16 + hex_digit(path[2]));
            path += 3;
        } else {
            folder[at++] = *path++;
        }
    }
    folder[at] = '\0';
    if (strlen(folder) != at) { /* an escaped NUL: no such folder */
        free(folder);
        return NULL;
    }
    return folder;
}

/* A copy of the folder ``path`` without trailing separators (the root stays "/"); NULL for none. */
static char *resource_folder(const char *path)
{
    size_t length;
    if (path == NULL || *path == '\0') {
        return NULL;
    }
    length = strlen(path);
    while (length > 1 && (path[length - 1] == '/' || path[length - 1] == '\\')) {
        length--;
    }
    return copy_text(path, length);
}

Instance *instance_new(const char *name, const char *token, const char *fmi_prefix, Emit emit,
                       void (*host_logger)(void), void *host_environment, const char *resources)
{
    Instance *instance = calloc(1, sizeof *instance);
    if (instance == NULL) {
        return NULL;
    }
    instance->name = copy_text(name != NULL ? name : "", name != NULL ? strlen(name) : 0);
    instance->resources = resource_folder(resources);
    if (instance->name == NULL || (resources != NULL && *resources != '\0' && instance->resources == NULL)) {
        instance_free(instance);
        return NULL;
    }
    instance->cache.resources = instance->resources;
    instance->emit = emit;
    instance->host_logger = host_logger;
    instance->host_environment = host_environment;
    instance->fmi_prefix = fmi_prefix;
    if (token == NULL || strcmp(token, MODEL_TOKEN) != 0) {
        instance_log(instance, STATUS_ERROR, fmi_prefix, "Instantiate: the token '", token ? token : "(null)",
                     "' is not this FMU's (", MODEL_NAME, ": '", MODEL_TOKEN, "')", (const char *)NULL);
        instance_free(instance);
        return NULL;
    }
    if (instance_reset(instance) != STATUS_OK) {
        instance_free(instance);
        return NULL;
    }
    return instance;
}

void instance_free(Instance *instance)
{
    if (instance != NULL) {
        clear_cache(instance);
        free_strings(instance->data.string_value);
        free(instance->resources);
        free(instance->name);
        free(instance);
    }
}
