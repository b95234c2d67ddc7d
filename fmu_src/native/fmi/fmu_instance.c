/* Shared core of the native co-simulation FMUs: life cycle, stepping, logging, instances; the
 * checks in fmu_checks.c, the values in fmu_values.c, the FMU state in fmu_state.c, the messages in
 * fmu_messages.c.
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

/* ---- stepping (SteppedModel.initialize, step, _undoable) --------------------------------- */

typedef enum { ACTION_START, ACTION_ADVANCE } Action;

void step_undo_keep(const ModelData *data, StepUndo *undo)
{
    int i;
    for (i = 0; i < MODEL_REAL_COMPUTED_COUNT; i++) {
        undo->real[i] = data->real_value[model_real_computed[i]];
    }
    for (i = 0; i < MODEL_INT_COMPUTED_COUNT; i++) {
        undo->integer[i] = data->int_value[model_int_computed[i]];
    }
    memcpy(undo->internal, data->internal, sizeof undo->internal);
}

void step_undo_restore(ModelData *data, const StepUndo *undo)
{
    int i;
    for (i = 0; i < MODEL_REAL_COMPUTED_COUNT; i++) {
        data->real_value[model_real_computed[i]] = undo->real[i];
    }
    for (i = 0; i < MODEL_INT_COMPUTED_COUNT; i++) {
        data->int_value[model_int_computed[i]] = undo->integer[i];
    }
    memcpy(data->internal, undo->internal, sizeof data->internal);
}

/* Runs the action on ``data``; if it fails arithmetically or leaves a non-finite output, undoes it and
 * says why in ``out`` ("the start values ..." or "the step from t = ... s ...", formatted only then). */
static void undoable(ModelData *data, Messages *out, Action action, double time, double step_size)
{
    StepUndo undo;
    int before = out->count;
    char shown[40];
    Failure failure;
    step_undo_keep(data, &undo);
    if (model_hooks.at_time != NULL) {
        failure = model_hooks.at_time(data, action == ACTION_START ? time : time + step_size);
    } else if (action == ACTION_START) {
        failure = model_hooks.start(data, time);
    } else {
        failure = model_hooks.advance(data, time, step_size);
    }
    if (failure.kind == ERROR_NONE) {
        output_errors(data, out, &failure);
    }
    if (failure.kind != ERROR_NONE && action == ACTION_START) {
        messages_add(out, "the start values could not be computed (", ERROR_KIND_NAME(failure.kind), ": ",
                     failure.message, ")", (const char *)NULL);
    } else if (failure.kind != ERROR_NONE) {
        python_float_repr(time, shown, sizeof shown);
        messages_add(out, "the step from t = ", shown, " s could not be computed (", ERROR_KIND_NAME(failure.kind),
                     ": ", failure.message, ")", (const char *)NULL);
    }
    if (out->count != before) {
        step_undo_restore(data, &undo);
    }
}

/* SteppedModel.initialize: the parameters and inputs checked, then the outputs at ``start_time``. */
static void initialize(ModelData *data, Messages *out, double start_time)
{
    parameter_errors(data, out);
    input_errors(data, out);
    if (out->count) {
        return;
    }
    data->time = start_time;
    undoable(data, out, ACTION_START, start_time, 0.0);
    data->initialized = out->count == 0;
}

static void step(Instance *instance, double current_time, double step_size)
{
    Messages *out = &instance->messages;
    char shown[40];
    if (!instance->data.initialized) {
        initialize(&instance->data, out, current_time);
        if (out->count) {
            return;
        }
    }
    if (!(isfinite(step_size) && step_size > 0.0)) {
        python_float_repr(step_size, shown, sizeof shown);
        messages_add(out, "communication step size must be positive and finite, got ", shown, (const char *)NULL);
        return;
    }
    if (!isfinite(current_time + step_size)) {
        char start[40];
        python_float_repr(current_time, start, sizeof start);
        python_float_repr(step_size, shown, sizeof shown);
        messages_add(out, "the communication step from t = ", start, " s by ", shown,
                     " s ends at a time that is not finite", (const char *)NULL);
        return;
    }
    instance_parameter_errors(instance, &instance->data);
    input_errors(&instance->data, out);
    if (out->count == 0 && model_hooks.step_size_errors != NULL) {
        model_hooks.step_size_errors(&instance->data, step_size, out);
    }
    if (out->count) {
        return;
    }
    undoable(&instance->data, out, ACTION_ADVANCE, current_time, step_size);
    if (out->count == 0) {
        instance->data.time = current_time + step_size;
    }
}

/* The model's notice of a step it took, logged as a warning when it differs from the last one. */
static void step_notice(Instance *instance, double step_size)
{
    Messages *out = &instance->messages;
    if (model_hooks.step_notice == NULL || out->count) {
        return;
    }
    model_hooks.step_notice(&instance->data, step_size, out);
    if (out->count && strcmp(instance->notice, out->text[0]) != 0) {
        instance_log(instance, STATUS_WARNING, out->text[0], (const char *)NULL);
        strcpy(instance->notice, out->text[0]);
    }
    out->count = 0;
}

/* ---- logging ------------------------------------------------------------------------------ */

static const char *category_of(Status status)
{
    return status == STATUS_ERROR     ? "logStatusError"
           : status == STATUS_DISCARD ? "logStatusDiscard"
           : status == STATUS_WARNING ? "logStatusWarning"
                                      : "logAll";
}

void instance_log(Instance *instance, Status status, const char *first, ...)
{
    char message[FMU_MESSAGE_SIZE] = "";
    va_list pieces;
    va_start(pieces, first);
    append_pieces(message, sizeof message, first, pieces);
    va_end(pieces);
    if (status != STATUS_OK || instance->logging_on) { /* information only when the host asked for logging */
        instance->emit(instance, status, category_of(status), message);
    }
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
char *copy_text(const char *text, size_t length)
{
    char *copy = malloc(length + 1);
    if (copy != NULL) {
        memcpy(copy, text, length);
        copy[length] = '\0';
    }
    return copy;
}

void free_strings(char *strings[MODEL_VARIABLE_COUNT])
{
    int i;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        free(strings[i]);
        strings[i] = NULL;
    }
}

/* Copies of the String variables of ``from`` (their start values where ``from`` is NULL) into
 * ``to``; 0 (nothing allocated) without memory. */
int copy_strings(char *const from[MODEL_VARIABLE_COUNT], char *to[MODEL_VARIABLE_COUNT])
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
        if (model_variables[i].type == VAR_INTEGER || model_variables[i].type == VAR_BOOLEAN) {
            instance->data.int_value[i] = (int32_t)model_variables[i].start; /* an int32 or 0 and 1: exact */
        }
        instance->data.string_value[i] = strings[i];
    }
    instance->data.cache = &instance->cache;
    if (model_hooks.reset_internal != NULL) {
        model_hooks.reset_internal(&instance->data);
    }
    instance->epoch++;
    instance->stale = 1;
    instance->parameters_checked = 0;
    instance->start_time = 0.0;
    instance->terminated = 0;
    instance->refusal[0] = '\0';
    instance->notice[0] = '\0';
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
    instance->stale = 1;
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
    initialize(&instance->data, &instance->messages, instance->start_time);
    if (instance->messages.count) { /* start values the model refuses (an input beyond its bounds): Error */
        instance_log_messages(instance, STATUS_ERROR);
        instance->mode = MODE_ERROR;
        return STATUS_ERROR;
    }
    if (model_hooks.start_notice != NULL) {
        const char *notice = model_hooks.start_notice(&instance->data);
        if (notice != NULL) { /* a default in use: an information line (status OK, category logAll) */
            instance_log(instance, STATUS_OK, notice, (const char *)NULL);
        }
    }
    instance->mode = MODE_STEP;
    instance->event_mode = instance->model_exchange;
    instance->stale = instance->messages.count > 0;
    return STATUS_OK;
}

const ModelData *instance_readable(Instance *instance, Status *status)
{
    *status = STATUS_OK;
    if (instance->mode != MODE_INITIALIZATION) {
        return &instance->data;
    }
    if (instance->stale) {
        int i;
        instance->initial = instance->data;
        instance->messages.count = 0;
        initialize(&instance->initial, &instance->messages, instance->start_time);
        instance->initial_refused = instance->messages.count > 0;
        instance->stale = 0;
        for (i = 0; i < instance->messages.count; i++) {
            instance_log(instance, STATUS_WARNING, "values read in initialization mode are the start values: ",
                         instance->messages.text[i], (const char *)NULL);
        }
        instance->messages.count = 0;
    }
    if (instance->initial_refused) {
        *status = STATUS_WARNING;
        return &instance->data;
    }
    return &instance->initial;
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
    step_notice(instance, step_size);
    return instance_refusal(instance);
}

Status instance_refusal(Instance *instance)
{
    if (instance->messages.count) { /* the same call would be refused again: its reasons are logged once */
        if (strcmp(instance->refusal, instance->messages.text[0]) != 0) {
            instance_log_messages(instance, STATUS_ERROR);
            strcpy(instance->refusal, instance->messages.text[0]);
        }
        return STATUS_DISCARD;
    }
    instance->refusal[0] = '\0';
    return STATUS_OK;
}

/* ---- instances ------------------------------------------------------------------------------ */

static int hex_digit(char c)
{
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                  : -1;
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
        free(instance->jacobian);
        free(instance->resources);
        free(instance->name);
        free(instance);
    }
}
