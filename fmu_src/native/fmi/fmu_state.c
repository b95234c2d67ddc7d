/* FMU state of the native FMUs' shared layer: get, set, free, serialize and deserialize. */
#include "fmu_instance.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- FMU state ---------------------------------------------------------------------------- */

#define STATE_TAG 0x4452564C53544154ull /* marks a live StoredState */
#define STATE_FORMAT 6u /* 6: 96 internal slots (5: twelve; 4: eleven; 3: String values; 2: six internal slots; 1 had four) */
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
    instance->stale = 1;
    instance->parameters_checked = 0;
    instance->epoch++;
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
    instance->messages.count = 0;
    restored_errors(&decoded, decoded_start, &instance->messages);
    if (instance->messages.count) { /* a checksum made by hand: the values are checked as the model leaves them */
        free_strings(decoded.string_value);
        return instance_fail(instance, instance->fmi_prefix, function, ": refused: the state holds an impossible "
                             "value (", instance->messages.text[0], ")", (const char *)NULL);
    }
    target = state_slot(instance, function, *state);
    if (target == NULL) {
        free_strings(decoded.string_value);
        return STATUS_ERROR;
    }
    store(target, decoded_mode, decoded_start, &decoded);
    *state = target;
    return STATUS_OK;
}

