/* The TOML reader of the layouts (tomllib's grammar for): comments, bare, quoted and dotted keys,
 * [table], [[array.of.tables]], basic, literal and multi-line strings with escapes, integers (decimal
 * with _ and sign, 0x, 0o, 0b; beyond 64 bits refused), floats (exponent, inf, nan, _), booleans,
 * arrays and inline tables. Datetimes are refused as malformed. Everything the reader builds lives
 * in one arena, freed at once. */
#include "toml.h"

#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- the reader (tomllib.loads) -----------------------------------------------------------
 * A function of the reader that returns ErrorKind gives ERROR_NONE, or ERROR_VALUE with the message
 * in reader->error (one that returns a Value gives NULL with it): the loader raises tomllib's
 * TOMLDecodeError as a ValueError (and out of memory as one too, as the FMU reports it). */

typedef struct Pending {
    Value *table;
    struct Pending *next;
} Pending;

typedef struct {
    Arena arena;
    const char *src; /* the text with CRLF made LF (tomllib.loads) */
    size_t length, pos;
    const char *source;
    char *error;
    size_t size;
    Pending *pending; /* tables of this section's dotted keys (Flags.add_pending) */
} Reader;

#define MAX_KEY_PARTS TREE_DEPTH

typedef struct {
    int count;
    const char *part[MAX_KEY_PARTS];
    size_t length[MAX_KEY_PARTS];
} Key;

/* suffixed_err: the reason and where the reader stands (line, column in characters). */
static ErrorKind malformed(Reader *reader, const char *reason)
{
    size_t line = 1, column = 1, i;
    if (reader->pos >= reader->length) {
        return layout_error(reader->error, reader->size, "%s: malformed TOML: %s (at end of document)", reader->source,
                    reason);
    }
    for (i = 0; i < reader->pos; i++) {
        if (reader->src[i] == '\n') {
            line++;
            column = 1;
        } else if (((unsigned char)reader->src[i] & 0xC0) != 0x80) {
            column++;
        }
    }
    {
        char where[64];
        snprintf(where, sizeof where, "(at line %lu, column %lu)", (unsigned long)line, (unsigned long)column);
        return layout_error(reader->error, reader->size, "%s: malformed TOML: %s %s", reader->source, reason, where);
    }
}

static ErrorKind out_of_memory(Reader *reader)
{
    return layout_error(reader->error, reader->size, "out of memory");
}

static int peek(const Reader *reader, size_t ahead)
{
    return reader->pos + ahead < reader->length ? (unsigned char)reader->src[reader->pos + ahead] : -1;
}

static int starts(const Reader *reader, const char *word)
{
    size_t n = strlen(word);
    return reader->length - reader->pos >= n && memcmp(reader->src + reader->pos, word, n) == 0;
}

static int control(int c)
{
    return (c >= 0 && c < 0x20) || c == 0x7F;
}

static void skip_blanks(Reader *reader)
{
    while (peek(reader, 0) == ' ' || peek(reader, 0) == '\t') {
        reader->pos++;
    }
}

/* skip_comment */
static ErrorKind skip_comment(Reader *reader)
{
    if (peek(reader, 0) != '#') {
        return ERROR_NONE;
    }
    for (reader->pos++; reader->pos < reader->length && reader->src[reader->pos] != '\n'; reader->pos++) {
        if (control(peek(reader, 0)) && peek(reader, 0) != '\t') {
            return malformed(reader, "invalid character in a comment");
        }
    }
    return ERROR_NONE;
}

/* skip_comments_and_array_ws */
static ErrorKind skip_array_space(Reader *reader)
{
    size_t before;
    ErrorKind failed;
    do {
        before = reader->pos;
        while (peek(reader, 0) == ' ' || peek(reader, 0) == '\t' || peek(reader, 0) == '\n') {
            reader->pos++;
        }
        if ((failed = skip_comment(reader)) != ERROR_NONE) {
            return failed;
        }
    } while (reader->pos != before);
    return ERROR_NONE;
}

static Value *new_value(Reader *reader, Kind kind, int depth)
{
    Value *value = arena_alloc(&reader->arena, sizeof *value);
    if (value != NULL) {
        memset(value, 0, sizeof *value);
        value->kind = kind;
        value->depth = depth;
    }
    return value;
}

static ErrorKind append(Reader *reader, Value *container, const char *key, size_t key_length, Value *value)
{
    Item *item = arena_alloc(&reader->arena, sizeof *item);
    if (item == NULL) {
        return out_of_memory(reader);
    }
    item->key = key;
    item->key_length = key_length;
    item->value = value;
    item->next = NULL;
    if (container->last != NULL) {
        container->last->next = item;
    } else {
        container->first = item;
    }
    container->last = item;
    container->count++;
    return ERROR_NONE;
}

Value *toml_find(const Value *table, const char *key, size_t key_length)
{
    const Item *item;
    for (item = table->first; item != NULL; item = item->next) {
        if (item->key_length == key_length && memcmp(item->key, key, key_length) == 0) {
            return item->value;
        }
    }
    return NULL;
}

/* A new empty table or array named ``key`` in the table ``parent`` (get_or_create_nest's step), or
 * at the end of the array ``parent`` (key NULL). */
static Value *add_child(Reader *reader, Value *parent, Kind kind, const char *key, size_t key_length)
{
    Value *child;
    if (parent->depth >= TREE_DEPTH) {
        malformed(reader, "tables and arrays nest too deep");
        return NULL;
    }
    child = new_value(reader, kind, parent->depth + 1);
    if (child == NULL) {
        out_of_memory(reader);
        return NULL;
    }
    if (append(reader, parent, key, key_length, child) != 0) {
        return NULL;
    }
    return child;
}

static int hex_digit(int c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

static size_t put_utf8(char *out, unsigned long code)
{
    if (code < 0x80) {
        if (out != NULL) {
            out[0] = (char)code;
        }
        return 1;
    }
    if (code < 0x800) {
        if (out != NULL) {
            out[0] = (char)(0xC0 | (code >> 6));
            out[1] = (char)(0x80 | (code & 0x3F));
        }
        return 2;
    }
    if (code < 0x10000) {
        if (out != NULL) {
            out[0] = (char)(0xE0 | (code >> 12));
            out[1] = (char)(0x80 | ((code >> 6) & 0x3F));
            out[2] = (char)(0x80 | (code & 0x3F));
        }
        return 3;
    }
    if (out != NULL) {
        out[0] = (char)(0xF0 | (code >> 18));
        out[1] = (char)(0x80 | ((code >> 12) & 0x3F));
        out[2] = (char)(0x80 | ((code >> 6) & 0x3F));
        out[3] = (char)(0x80 | (code & 0x3F));
    }
    return 4;
}

/* parse_basic_str_escape: one escape at pos (a backslash); its characters go to ``out`` (NULL: only
 * counted in ``*count``). */
static ErrorKind basic_escape(Reader *reader, int multiline, char *out, size_t *count)
{
    int c = peek(reader, 1);
    static const char from[] = "btnfr\"\\", to[] = "\b\t\n\f\r\"\\";
    const char *known;
    if (multiline && (c == ' ' || c == '\t' || c == '\n')) { /* line-ending backslash */
        reader->pos += 2;
        if (c != '\n') {
            skip_blanks(reader);
            if (reader->pos >= reader->length) {
                return ERROR_NONE;
            }
            if (peek(reader, 0) != '\n') {
                return malformed(reader, "unescaped '\\' in a string");
            }
            reader->pos++;
        }
        while (peek(reader, 0) == ' ' || peek(reader, 0) == '\t' || peek(reader, 0) == '\n') {
            reader->pos++;
        }
        return ERROR_NONE;
    }
    if (c == 'u' || c == 'U') {
        size_t digits = c == 'u' ? 4 : 8, i;
        unsigned long code = 0;
        reader->pos += 2;
        for (i = 0; i < digits; i++) {
            int d = peek(reader, i);
            if (!hex_digit(d)) {
                return malformed(reader, "invalid hex value");
            }
            code = code * 16 + (unsigned long)(d <= '9' ? d - '0' : (d | 0x20) - 'a' + 10);
        }
        reader->pos += digits;
        if (code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) {
            return malformed(reader, "escaped character is not a Unicode scalar value");
        }
        *count += put_utf8(out != NULL ? out + *count : NULL, code);
        return ERROR_NONE;
    }
    known = c > 0 ? strchr(from, c) : NULL;
    if (known == NULL) {
        reader->pos += c >= 0 ? 2 : 1;
        return malformed(reader, "unescaped '\\' in a string");
    }
    if (out != NULL) {
        out[*count] = to[known - from];
    }
    (*count)++;
    reader->pos += 2;
    return ERROR_NONE;
}

/* The body of a string opened at pos (parse_one_line_basic_str, parse_literal_str,
 * parse_multiline_str): its characters to ``out`` (NULL: counted only), pos after the closing quotes. */
static ErrorKind string_body(Reader *reader, char *out, size_t *count)
{
    char quote = reader->src[reader->pos];
    int multiline = starts(reader, quote == '"' ? "\"\"\"" : "'''");
    *count = 0;
    reader->pos += multiline ? 3 : 1;
    if (multiline && peek(reader, 0) == '\n') {
        reader->pos++;
    }
    for (;;) {
        int c = peek(reader, 0);
        if (c < 0) {
            return malformed(reader, "unterminated string");
        }
        if (c == quote) {
            int extra;
            if (!multiline) {
                reader->pos++;
                return ERROR_NONE;
            }
            if (peek(reader, 1) == quote && peek(reader, 2) == quote) {
                reader->pos += 3;
                for (extra = 0; extra < 2 && peek(reader, 0) == quote; extra++) { /* """"" ends with quotes */
                    if (out != NULL) {
                        out[*count] = quote;
                    }
                    (*count)++;
                    reader->pos++;
                }
                return ERROR_NONE;
            }
        } else if (c == '\\' && quote == '"') {
            ErrorKind failed = basic_escape(reader, multiline, out, count);
            if (failed != ERROR_NONE) {
                return failed;
            }
            continue;
        } else if (control(c) && c != '\t' && !(multiline && c == '\n')) {
            return malformed(reader, "illegal character in a string");
        }
        if (out != NULL) {
            out[*count] = (char)c;
        }
        (*count)++;
        reader->pos++;
    }
}

/* A string at pos into the arena. */
static ErrorKind read_string(Reader *reader, const char **text, size_t *length)
{
    size_t start = reader->pos, count;
    char *out;
    ErrorKind failed = string_body(reader, NULL, &count);
    if (failed != ERROR_NONE) {
        return failed;
    }
    out = arena_alloc(&reader->arena, count + 1);
    if (out == NULL) {
        return out_of_memory(reader);
    }
    reader->pos = start;
    string_body(reader, out, &count);
    out[count] = '\0';
    *text = out;
    *length = count;
    return ERROR_NONE;
}

int toml_bare_key_char(int c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

/* parse_key: dotted parts, quoted or bare (one-line strings only). */
static ErrorKind read_key(Reader *reader, Key *key)
{
    key->count = 0;
    for (;;) {
        int c = peek(reader, 0);
        const char *part;
        size_t length;
        if (key->count == MAX_KEY_PARTS) {
            return malformed(reader, "a key of too many parts");
        }
        if (toml_bare_key_char(c)) {
            size_t start = reader->pos;
            while (toml_bare_key_char(peek(reader, 0))) {
                reader->pos++;
            }
            part = reader->src + start;
            length = reader->pos - start;
        } else if (c == '"' || c == '\'') {
            if (starts(reader, c == '"' ? "\"\"\"" : "\'\'\'")) { /* an empty key, then a quote */
                return malformed(reader, "invalid key");
            }
            ErrorKind failed = read_string(reader, &part, &length);
            if (failed != ERROR_NONE) {
                return failed;
            }
        } else {
            return malformed(reader, "invalid initial character for a key part");
        }
        key->part[key->count] = part;
        key->length[key->count] = length;
        key->count++;
        skip_blanks(reader);
        if (peek(reader, 0) != '.') {
            return ERROR_NONE;
        }
        reader->pos++;
        skip_blanks(reader);
    }
}

static int digit_in(int c, int base)
{
    if (base == 16) {
        return hex_digit(c);
    }
    return c >= '0' && c < '0' + base;
}

/* Digits of ``base`` with single underscores between them ([0-9](?:_?[0-9])*); 0 if none. */
static size_t digit_run(const Reader *reader, size_t at, int base)
{
    size_t end = at;
    if (end >= reader->length || !digit_in((unsigned char)reader->src[end], base)) {
        return 0;
    }
    end++;
    while (end < reader->length) {
        if (digit_in((unsigned char)reader->src[end], base)) {
            end++;
        } else if (reader->src[end] == '_' && end + 1 < reader->length &&
                   digit_in((unsigned char)reader->src[end + 1], base)) {
            end += 2;
        } else {
            break;
        }
    }
    return end - at;
}

/* The integer of [start, end) in ``base`` (underscores skipped), negative if ``minus``. */
static ErrorKind integer_value(Reader *reader, size_t start, size_t end, int base, int minus, long long *out)
{
    unsigned long long magnitude = 0, limit = minus ? (unsigned long long)LLONG_MAX + 1u : LLONG_MAX;
    size_t i;
    for (i = start; i < end; i++) {
        int c = (unsigned char)reader->src[i], d;
        if (c == '_') {
            continue;
        }
        d = c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10;
        if (magnitude > (limit - (unsigned long long)d) / (unsigned long long)base) {
            return malformed(reader, "integer beyond 64 bits");
        }
        magnitude = magnitude * (unsigned long long)base + (unsigned long long)d;
    }
    if (minus) {
        *out = magnitude == (unsigned long long)LLONG_MAX + 1u ? LLONG_MIN : -(long long)magnitude;
    } else {
        *out = (long long)magnitude;
    }
    return ERROR_NONE;
}

/* float() of the TOML float text [start, end): underscores dropped, the locale's decimal point. */
static ErrorKind float_value(Reader *reader, size_t start, size_t end, double *out)
{
    char *copy = arena_alloc(&reader->arena, end - start + 8), point = *localeconv()->decimal_point;
    size_t i, n = 0;
    if (copy == NULL) {
        return out_of_memory(reader);
    }
    for (i = start; i < end; i++) {
        char c = reader->src[i];
        if (c != '_') {
            copy[n++] = c == '.' ? point : c;
        }
    }
    copy[n] = '\0';
    *out = strtod(copy, NULL);
    return ERROR_NONE;
}

/* Whether ``count`` decimal digits and ``c`` follow (the start of a date or a time). */
static int digits_then(const Reader *reader, size_t count, int c)
{
    size_t i;
    for (i = 0; i < count; i++) {
        if (!digit_in(peek(reader, i), 10)) {
            return 0;
        }
    }
    return peek(reader, count) == c;
}

/* A number, inf or nan at pos (RE_NUMBER, match_to_number); datetimes are refused. */
static ErrorKind read_number(Reader *reader, Value *value)
{
    size_t start = reader->pos, at = start, run;
    int c = peek(reader, 0), base = 0, minus = c == '-';
    if (c == '0' && (peek(reader, 1) == 'x' || peek(reader, 1) == 'o' || peek(reader, 1) == 'b')) {
        base = peek(reader, 1) == 'x' ? 16 : peek(reader, 1) == 'o' ? 8 : 2;
        run = digit_run(reader, start + 2, base);
        if (run > 0) {
            value->kind = V_INTEGER;
            reader->pos = start + 2 + run;
            return integer_value(reader, start + 2, reader->pos, base, 0, &value->integer);
        }
    }
    if (digits_then(reader, 4, '-') || digits_then(reader, 2, ':')) {
        return malformed(reader, "dates and times are not supported");
    }
    if (c == '+' || c == '-') {
        at++;
    }
    if (at < reader->length && reader->src[at] == '0') {
        run = 1;
    } else if (at < reader->length && reader->src[at] >= '1' && reader->src[at] <= '9') {
        run = digit_run(reader, at, 10);
    } else {
        run = 0;
    }
    if (run == 0) {
        const char *word = reader->src + at;
        if (reader->length - at >= 3 && (memcmp(word, "inf", 3) == 0 || memcmp(word, "nan", 3) == 0)) {
            value->kind = V_FLOAT;
            value->number = word[0] == 'n' ? NAN : minus ? -INFINITY : INFINITY;
            reader->pos = at + 3;
            return ERROR_NONE;
        }
        return malformed(reader, "invalid value");
    }
    at += run;
    {
        size_t int_end = at;
        int fraction = 0, exponent = 0;
        if (at < reader->length && reader->src[at] == '.' && (run = digit_run(reader, at + 1, 10)) > 0) {
            at += 1 + run;
            fraction = 1;
        }
        if (at < reader->length && (reader->src[at] == 'e' || reader->src[at] == 'E')) {
            size_t sign = at + 1 < reader->length && (reader->src[at + 1] == '+' || reader->src[at + 1] == '-');
            if ((run = digit_run(reader, at + 1 + sign, 10)) > 0) {
                at += 1 + sign + run;
                exponent = 1;
            }
        }
        reader->pos = at;
        if (fraction || exponent) {
            value->kind = V_FLOAT;
            return float_value(reader, start, at, &value->number);
        }
        value->kind = V_INTEGER;
        return integer_value(reader, start + (c == '+' || c == '-'), int_end, 10, minus, &value->integer);
    }
}

static ErrorKind read_value(Reader *reader, int depth, Value **out);

static ErrorKind descend_error(Reader *reader)
{
    return malformed(reader, "cannot overwrite a value");
}

/* Whether ``c`` stands at pos (then passed). */
static int closes(Reader *reader, int c)
{
    if (peek(reader, 0) != c) {
        return 0;
    }
    reader->pos++;
    return 1;
}

/* parse_array: [ values, ... ] over lines, with comments and a trailing comma. */
static ErrorKind read_array(Reader *reader, Value *array)
{
    ErrorKind failed;
    reader->pos++;
    if ((failed = skip_array_space(reader)) != ERROR_NONE) {
        return failed;
    }
    if (closes(reader, ']')) {
        return ERROR_NONE;
    }
    for (;;) {
        Value *item;
        if ((failed = read_value(reader, array->depth + 1, &item)) != ERROR_NONE ||
            (failed = append(reader, array, NULL, 0, item)) != ERROR_NONE ||
            (failed = skip_array_space(reader)) != ERROR_NONE) {
            return failed;
        }
        if (closes(reader, ']')) {
            return ERROR_NONE;
        }
        if (peek(reader, 0) != ',') {
            return malformed(reader, "unclosed array");
        }
        reader->pos++;
        if ((failed = skip_array_space(reader)) != ERROR_NONE) {
            return failed;
        }
        if (closes(reader, ']')) {
            return ERROR_NONE;
        }
    }
}

/* parse_key_value_pair: key = value, the value at the depth of its place below ``parent``. */
static ErrorKind read_pair(Reader *reader, const Value *parent, Key *key, Value **value)
{
    ErrorKind failed = read_key(reader, key);
    if (failed != ERROR_NONE) {
        return failed;
    }
    if (peek(reader, 0) != '=') {
        return malformed(reader, "expected '=' after a key in a key/value pair");
    }
    reader->pos++;
    skip_blanks(reader);
    if (parent->depth + key->count > TREE_DEPTH) {
        return malformed(reader, "tables and arrays nest too deep");
    }
    return read_value(reader, parent->depth + key->count, value);
}

/* The pair's place below ``table``: the tables of the dotted key's parts (made where missing), then the
 * value under its last part. ``section``: a statement of a section (key_value_rule: a table declared
 * before is closed to dotted keys; the ones passed count as declared from the next header on); else
 * a pair of an inline table (parse_inline_table). Literal arrays and inline tables stay closed. */
static ErrorKind place_pair(Reader *reader, Value *table, const Key *key, Value *value, int section)
{
    Value *nest = table;
    int i;
    for (i = 0; i + 1 < key->count; i++) {
        Value *next = toml_find(nest, key->part[i], key->length[i]);
        if (next == NULL) {
            next = add_child(reader, nest, V_TABLE, key->part[i], key->length[i]);
            if (next == NULL) { /* malformed or out of memory, its message written */
                return ERROR_VALUE;
            }
        } else if (section && next->declared) {
            return malformed(reader, "cannot redefine a namespace");
        } else if (next->kind != V_TABLE || next->frozen) {
            return descend_error(reader);
        }
        if (section) {
            Pending *pending = arena_alloc(&reader->arena, sizeof *pending);
            if (pending == NULL) {
                return out_of_memory(reader);
            }
            pending->table = next;
            pending->next = reader->pending;
            reader->pending = pending;
        }
        nest = next;
    }
    if (toml_find(nest, key->part[key->count - 1], key->length[key->count - 1]) != NULL) {
        return descend_error(reader);
    }
    return append(reader, nest, key->part[key->count - 1], key->length[key->count - 1], value);
}

/* parse_inline_table: { key = value, ... } on one line; dotted keys make tables inside. */
static ErrorKind read_inline_table(Reader *reader, Value *table)
{
    reader->pos++;
    skip_blanks(reader);
    if (closes(reader, '}')) {
        return ERROR_NONE;
    }
    for (;;) {
        Key key;
        Value *value;
        ErrorKind failed;
        if ((failed = read_pair(reader, table, &key, &value)) != ERROR_NONE ||
            (failed = place_pair(reader, table, &key, value, 0)) != ERROR_NONE) {
            return failed;
        }
        skip_blanks(reader);
        if (closes(reader, '}')) {
            return ERROR_NONE;
        }
        if (peek(reader, 0) != ',') {
            return malformed(reader, "unclosed inline table");
        }
        reader->pos++;
        skip_blanks(reader);
    }
}

/* parse_value */
static ErrorKind read_value(Reader *reader, int depth, Value **out)
{
    int c = peek(reader, 0);
    Value *value = new_value(reader, V_BOOL, depth);
    if (value == NULL) {
        return out_of_memory(reader);
    }
    *out = value;
    if (c == '"' || c == '\'') {
        value->kind = V_STRING;
        return read_string(reader, &value->text, &value->length);
    }
    if (starts(reader, "true") || starts(reader, "false")) {
        value->integer = c == 't';
        reader->pos += c == 't' ? 4 : 5;
        return ERROR_NONE;
    }
    if (c == '[' || c == '{') {
        if (depth > TREE_DEPTH) {
            return malformed(reader, "tables and arrays nest too deep");
        }
        value->kind = c == '[' ? V_ARRAY : V_TABLE;
        value->frozen = 1;
        return c == '[' ? read_array(reader, value) : read_inline_table(reader, value);
    }
    return read_number(reader, value);
}

/* Flags.finalize_pending: the tables of the section's dotted keys count as declared from now on. */
static void finalize_pending(Reader *reader)
{
    for (; reader->pending != NULL; reader->pending = reader->pending->next) {
        reader->pending->table->declared = 1;
    }
}

/* The table of a header's key up to ``parts``: get_or_create_nest with access to the last table of
 * an array of tables; literal arrays and inline tables are closed (Flags.FROZEN). */
static Value *header_nest(Reader *reader, Value *root, const Key *key, int parts)
{
    Value *nest = root;
    int i;
    for (i = 0; i < parts; i++) {
        Value *next = toml_find(nest, key->part[i], key->length[i]);
        if (next == NULL) {
            next = add_child(reader, nest, V_TABLE, key->part[i], key->length[i]);
            if (next == NULL) {
                return NULL;
            }
        } else if (next->frozen) {
            malformed(reader, "cannot mutate an immutable namespace");
            return NULL;
        } else if (next->kind == V_ARRAY && next->of_tables) {
            next = next->last->value;
        } else if (next->kind != V_TABLE) {
            descend_error(reader);
            return NULL;
        }
        nest = next;
    }
    return nest;
}

/* create_dict_rule ([key]) and create_list_rule ([[key]]): the table the section fills. */
static Value *read_header(Reader *reader, Value *root)
{
    int list = peek(reader, 1) == '[';
    Key key;
    Value *parent, *table, *existing;
    const char *stem;
    size_t stem_length;
    reader->pos += list ? 2 : 1;
    skip_blanks(reader);
    if (read_key(reader, &key) != 0) {
        return NULL;
    }
    if (!starts(reader, list ? "]]" : "]")) {
        malformed(reader, list ? "expected ']]' at the end of an array declaration"
                               : "expected ']' at the end of a table declaration");
        return NULL;
    }
    parent = header_nest(reader, root, &key, key.count - 1);
    if (parent == NULL) {
        return NULL;
    }
    stem = key.part[key.count - 1];
    stem_length = key.length[key.count - 1];
    existing = toml_find(parent, stem, stem_length);
    if (existing != NULL && existing->frozen) {
        malformed(reader, "cannot mutate an immutable namespace");
        return NULL;
    }
    if (!list) {
        if (existing != NULL && (existing->declared || existing->kind != V_TABLE)) {
            malformed(reader, existing->declared ? "cannot declare a table twice" : "cannot overwrite a value");
            return NULL;
        }
        table = existing != NULL ? existing : add_child(reader, parent, V_TABLE, stem, stem_length);
        if (table != NULL) {
            table->declared = 1;
            reader->pos += 1;
        }
        return table;
    }
    if (existing != NULL && !(existing->kind == V_ARRAY && existing->of_tables)) {
        descend_error(reader);
        return NULL;
    }
    if (existing == NULL) {
        existing = add_child(reader, parent, V_ARRAY, stem, stem_length);
        if (existing == NULL) {
            return NULL;
        }
        existing->of_tables = 1;
        existing->declared = 1;
    }
    table = add_child(reader, existing, V_TABLE, NULL, 0);
    if (table != NULL) {
        reader->pos += 2;
    }
    return table;
}

/* key_value_rule: a pair in the section's table ``header``. */
static ErrorKind read_statement_pair(Reader *reader, Value *header)
{
    Key key;
    Value *value;
    ErrorKind failed = read_pair(reader, header, &key, &value);
    return failed != ERROR_NONE ? failed : place_pair(reader, header, &key, value, 1);
}

/* tomllib.loads: the document's table (in the reader's arena), NULL with the message. */
static Value *read_document(Reader *reader, const char *text, size_t length)
{
    char *src = arena_alloc(&reader->arena, length + 1);
    Value *root, *header;
    size_t i, n = 0;
    if (src == NULL) {
        out_of_memory(reader);
        return NULL;
    }
    for (i = 0; i < length; i++) {
        if (!(text[i] == '\r' && i + 1 < length && text[i + 1] == '\n')) {
            src[n++] = text[i];
        }
    }
    src[n] = '\0';
    reader->src = src;
    reader->length = n;
    reader->pos = 0;
    root = header = new_value(reader, V_TABLE, 0);
    if (root == NULL) {
        out_of_memory(reader);
        return NULL;
    }
    for (;;) {
        int c;
        skip_blanks(reader);
        c = peek(reader, 0);
        if (c < 0) {
            break;
        }
        if (c == '\n') {
            reader->pos++;
            continue;
        }
        if (toml_bare_key_char(c) || c == '"' || c == '\'') {
            if (read_statement_pair(reader, header) != 0) {
                return NULL;
            }
            skip_blanks(reader);
        } else if (c == '[') {
            finalize_pending(reader);
            header = read_header(reader, root);
            if (header == NULL) {
                return NULL;
            }
            skip_blanks(reader);
        } else if (c != '#') {
            malformed(reader, "invalid statement");
            return NULL;
        }
        if (skip_comment(reader) != 0) {
            return NULL;
        }
        c = peek(reader, 0);
        if (c < 0) {
            break;
        }
        if (c != '\n') {
            malformed(reader, "expected newline or end of document after a statement");
            return NULL;
        }
        reader->pos++;
    }
    return root;
}

ErrorKind toml_read(const char *text, size_t length, const char *source, Arena *arena, Value **root, char *error,
                    size_t size)
{
    Reader reader;
    memset(&reader, 0, sizeof reader);
    reader.source = source;
    reader.error = error;
    reader.size = size;
    *root = read_document(&reader, text, length);
    *arena = reader.arena;
    return *root != NULL ? ERROR_NONE : ERROR_VALUE;
}

/* The first invalid UTF-8 sequence (CPython's decoder: its reason and start), -1 if none. */
long toml_utf8_error(const unsigned char *bytes, size_t length, const char **reason)
{
    size_t i = 0, k, follow;
    while (i < length) {
        unsigned char lead = bytes[i];
        unsigned char low = 0x80, high = 0xBF;
        if (lead < 0x80) {
            i++;
            continue;
        }
        if (lead < 0xC2 || lead > 0xF4) {
            *reason = "invalid start byte";
            return (long)i;
        }
        follow = lead < 0xE0 ? 1 : lead < 0xF0 ? 2 : 3;
        low = lead == 0xE0 ? 0xA0 : lead == 0xF0 ? 0x90 : 0x80;
        high = lead == 0xED ? 0x9F : lead == 0xF4 ? 0x8F : 0xBF;
        for (k = 1; k <= follow; k++) {
            if (i + k >= length) {
                *reason = "unexpected end of data";
                return (long)i;
            }
            if (bytes[i + k] < (k == 1 ? low : 0x80) || bytes[i + k] > (k == 1 ? high : 0xBF)) {
                *reason = "invalid continuation byte";
                return (long)i;
            }
        }
        i += follow + 1;
    }
    return -1;
}
