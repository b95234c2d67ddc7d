/* The driveline of a layout: the TOML-subset reader and the checks of driveline/rotor/loader.py, the
 * element checks of elements.py and Driveline.__post_init__ (driveline.py), with their messages.
 *
 * The TOML reader (tomllib's grammar for): comments, bare, quoted and dotted keys, [table],
 * [[array.of.tables]], basic, literal and multi-line strings with escapes, integers (decimal with _
 * and sign, 0x, 0o, 0b; beyond 64 bits refused), floats (exponent, inf, nan, _), booleans, arrays
 * and inline tables. Datetimes are refused as malformed. Everything the reader builds lives in one
 * arena, freed at once. */
#include "rotor.h"

#include <errno.h>
#include <limits.h>
#include <locale.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#ifdef _WIN32
#include <direct.h> /* _getcwd */
#else
#include <unistd.h> /* getcwd */
#endif

#define NODE_SNAP 1e-9 /* loader.NODE_SNAP */
/* Tables and arrays nested below the document at the most (deeper is refused as malformed TOML:
 * a bound on a key's parts and on the stack of put_repr). */
#define TREE_DEPTH (4 * LAYOUT_MAX_NESTING)

/* ---- messages ----------------------------------------------------------------------------- */

typedef struct {
    char *out;
    size_t size, used;
} Text;

static void put_bytes(Text *text, const char *bytes, size_t count)
{
    text_append(text->out, text->size, &text->used, bytes, count);
}

static void put(Text *text, const char *piece)
{
    put_bytes(text, piece, strlen(piece));
}

static void put_str_repr(Text *text, const char *bytes, size_t count)
{
    if (text->size > 0 && text->used + 1 < text->size) {
        python_str_repr_n(bytes, count, 0, text->out + text->used, text->size - text->used);
        text->used += strlen(text->out + text->used);
    }
}

static void put_float(Text *text, double value)
{
    char shown[40];
    python_float_repr(value, shown, sizeof shown);
    put(text, shown);
}

/* ---- the arena ---------------------------------------------------------------------------- */

typedef union {
    long double a;
    long long b;
    void *c;
    double d;
} Aligned;

typedef struct Block {
    struct Block *next;
    size_t used, size;
    Aligned data[];
} Block;

typedef struct {
    Block *blocks;
} Arena;

static void *arena_alloc(Arena *arena, size_t count)
{
    Block *block = arena->blocks;
    size_t units = (count + sizeof(Aligned) - 1) / sizeof(Aligned);
    if (units == 0) {
        units = 1;
    }
    if (block == NULL || block->size - block->used < units) {
        size_t size = units > 4096 ? units : 4096;
        block = malloc(sizeof(Block) + size * sizeof(Aligned));
        if (block == NULL) {
            return NULL;
        }
        block->next = arena->blocks;
        block->used = 0;
        block->size = size;
        arena->blocks = block;
    }
    block->used += units;
    return block->data + block->used - units;
}

static void arena_free(Arena *arena)
{
    while (arena->blocks != NULL) {
        Block *next = arena->blocks->next;
        free(arena->blocks);
        arena->blocks = next;
    }
}

/* ---- TOML values -------------------------------------------------------------------------- */

typedef enum { V_STRING, V_INTEGER, V_FLOAT, V_BOOL, V_ARRAY, V_TABLE } Kind;

typedef struct Item Item;

typedef struct {
    Kind kind;
    unsigned char frozen;   /* a literal array or inline table (tomllib Flags.FROZEN) */
    unsigned char declared; /* a table named by a header or a dotted key before (Flags.EXPLICIT_NEST) */
    unsigned char of_tables; /* an array made by [[...]] headers */
    int depth;
    const char *text; /* V_STRING: ``length`` bytes */
    size_t length;
    long long integer; /* V_INTEGER; V_BOOL: 0 or 1 */
    double number;     /* V_FLOAT */
    Item *first, *last; /* V_ARRAY (keys NULL), V_TABLE */
    size_t count;
} Value;

struct Item {
    const char *key;
    size_t key_length;
    Value *value;
    Item *next;
};

/* repr() of a scalar as Python shows the loaded one (str, int, float, bool). */
static void put_scalar_repr(Text *text, const Value *value)
{
    char shown[32];
    if (value->kind == V_STRING) {
        put_str_repr(text, value->text, value->length);
    } else if (value->kind == V_INTEGER) {
        snprintf(shown, sizeof shown, "%lld", value->integer);
        put(text, shown);
    } else if (value->kind == V_FLOAT) {
        put_float(text, value->number);
    } else {
        put(text, value->integer ? "True" : "False");
    }
}

/* repr() of a value as Python shows the loaded one, lists and dicts too: walked with a stack of the
 * open containers (no recursion; the reader makes none deeper than TREE_DEPTH). */
static void put_repr(Text *text, const Value *value)
{
    const Value *open[TREE_DEPTH + 2];
    const Item *next[TREE_DEPTH + 2];
    int top = -1;
    for (;;) {
        if ((value->kind == V_ARRAY || value->kind == V_TABLE) && top + 1 < TREE_DEPTH + 2) {
            put(text, value->kind == V_ARRAY ? "[" : "{");
            open[++top] = value;
            next[top] = value->first;
        } else if (value->kind == V_ARRAY || value->kind == V_TABLE) {
            put(text, "...");
        } else {
            put_scalar_repr(text, value);
        }
        for (;;) { /* the next value to show, after the ends of the containers done */
            const Item *item;
            if (top < 0) {
                return;
            }
            item = next[top];
            if (item == NULL) {
                put(text, open[top]->kind == V_ARRAY ? "]" : "}");
                top--;
                continue;
            }
            if (item != open[top]->first) {
                put(text, ", ");
            }
            if (open[top]->kind == V_TABLE) {
                put_str_repr(text, item->key, item->key_length);
                put(text, ": ");
            }
            next[top] = item->next;
            value = item->value;
            break;
        }
    }
}

/* The message into ``error``: ``format`` with %s (C string), %d (int), %v (a Value's repr), %g (a
 * double's repr), %r (a C string's repr). Returns -1. */
static int fail(char *error, size_t size, const char *format, ...)
{
    Text text = {error, size, 0};
    va_list args;
    const char *c;
    char shown[32];
    if (size > 0) {
        error[0] = '\0';
    }
    va_start(args, format);
    for (c = format; *c != '\0'; c++) {
        const char *s;
        if (*c != '%' || c[1] == '\0') {
            put_bytes(&text, c, 1);
            continue;
        }
        switch (*++c) {
        case 's':
            put(&text, va_arg(args, const char *));
            break;
        case 'd':
            snprintf(shown, sizeof shown, "%d", va_arg(args, int));
            put(&text, shown);
            break;
        case 'v':
            put_repr(&text, va_arg(args, const Value *));
            break;
        case 'g':
            put_float(&text, va_arg(args, double));
            break;
        case 'r':
            s = va_arg(args, const char *);
            put_str_repr(&text, s, strlen(s));
            break;
        default:
            put_bytes(&text, c, 1);
            break;
        }
    }
    va_end(args);
    return -1;
}

/* ---- the reader (tomllib.loads) ----------------------------------------------------------- */

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
static int malformed(Reader *reader, const char *reason)
{
    size_t line = 1, column = 1, i;
    if (reader->pos >= reader->length) {
        return fail(reader->error, reader->size, "%s: malformed TOML: %s (at end of document)", reader->source,
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
        return fail(reader->error, reader->size, "%s: malformed TOML: %s %s", reader->source, reason, where);
    }
}

static int out_of_memory(Reader *reader)
{
    return fail(reader->error, reader->size, "out of memory");
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
static int skip_comment(Reader *reader)
{
    if (peek(reader, 0) != '#') {
        return 0;
    }
    for (reader->pos++; reader->pos < reader->length && reader->src[reader->pos] != '\n'; reader->pos++) {
        if (control(peek(reader, 0)) && peek(reader, 0) != '\t') {
            return malformed(reader, "invalid character in a comment");
        }
    }
    return 0;
}

/* skip_comments_and_array_ws */
static int skip_array_space(Reader *reader)
{
    size_t before;
    do {
        before = reader->pos;
        while (peek(reader, 0) == ' ' || peek(reader, 0) == '\t' || peek(reader, 0) == '\n') {
            reader->pos++;
        }
        if (skip_comment(reader) != 0) {
            return -1;
        }
    } while (reader->pos != before);
    return 0;
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

static int append(Reader *reader, Value *container, const char *key, size_t key_length, Value *value)
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
    return 0;
}

static Value *find(const Value *table, const char *key, size_t key_length)
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
static int basic_escape(Reader *reader, int multiline, char *out, size_t *count)
{
    int c = peek(reader, 1);
    static const char from[] = "btnfr\"\\", to[] = "\b\t\n\f\r\"\\";
    const char *known;
    if (multiline && (c == ' ' || c == '\t' || c == '\n')) { /* line-ending backslash */
        reader->pos += 2;
        if (c != '\n') {
            skip_blanks(reader);
            if (reader->pos >= reader->length) {
                return 0;
            }
            if (peek(reader, 0) != '\n') {
                return malformed(reader, "unescaped '\\' in a string");
            }
            reader->pos++;
        }
        while (peek(reader, 0) == ' ' || peek(reader, 0) == '\t' || peek(reader, 0) == '\n') {
            reader->pos++;
        }
        return 0;
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
        return 0;
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
    return 0;
}

/* The body of a string opened at pos (parse_one_line_basic_str, parse_literal_str,
 * parse_multiline_str): its characters to ``out`` (NULL: counted only), pos after the closing quotes. */
static int string_body(Reader *reader, char *out, size_t *count)
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
                return 0;
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
                return 0;
            }
        } else if (c == '\\' && quote == '"') {
            if (basic_escape(reader, multiline, out, count) != 0) {
                return -1;
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
static int read_string(Reader *reader, const char **text, size_t *length)
{
    size_t start = reader->pos, count;
    char *out;
    if (string_body(reader, NULL, &count) != 0) {
        return -1;
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
    return 0;
}

static int bare_key_char(int c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

/* parse_key: dotted parts, quoted or bare (one-line strings only). */
static int read_key(Reader *reader, Key *key)
{
    key->count = 0;
    for (;;) {
        int c = peek(reader, 0);
        const char *part;
        size_t length;
        if (key->count == MAX_KEY_PARTS) {
            return malformed(reader, "a key of too many parts");
        }
        if (bare_key_char(c)) {
            size_t start = reader->pos;
            while (bare_key_char(peek(reader, 0))) {
                reader->pos++;
            }
            part = reader->src + start;
            length = reader->pos - start;
        } else if (c == '"' || c == '\'') {
            if (starts(reader, c == '"' ? "\"\"\"" : "\'\'\'")) { /* an empty key, then a quote */
                return malformed(reader, "invalid key");
            }
            if (read_string(reader, &part, &length) != 0) {
                return -1;
            }
        } else {
            return malformed(reader, "invalid initial character for a key part");
        }
        key->part[key->count] = part;
        key->length[key->count] = length;
        key->count++;
        skip_blanks(reader);
        if (peek(reader, 0) != '.') {
            return 0;
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
static int integer_value(Reader *reader, size_t start, size_t end, int base, int minus, long long *out)
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
    return 0;
}

/* float() of the TOML float text [start, end): underscores dropped, the locale's decimal point. */
static int float_value(Reader *reader, size_t start, size_t end, double *out)
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
    return 0;
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
static int read_number(Reader *reader, Value *value)
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
            return 0;
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

static int read_value(Reader *reader, int depth, Value **out);

static int descend_error(Reader *reader)
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
static int read_array(Reader *reader, Value *array)
{
    reader->pos++;
    if (skip_array_space(reader) != 0) {
        return -1;
    }
    if (closes(reader, ']')) {
        return 0;
    }
    for (;;) {
        Value *item;
        if (read_value(reader, array->depth + 1, &item) != 0 || append(reader, array, NULL, 0, item) != 0 ||
            skip_array_space(reader) != 0) {
            return -1;
        }
        if (closes(reader, ']')) {
            return 0;
        }
        if (peek(reader, 0) != ',') {
            return malformed(reader, "unclosed array");
        }
        reader->pos++;
        if (skip_array_space(reader) != 0) {
            return -1;
        }
        if (closes(reader, ']')) {
            return 0;
        }
    }
}

/* parse_key_value_pair: key = value, the value at the depth of its place below ``parent``. */
static int read_pair(Reader *reader, const Value *parent, Key *key, Value **value)
{
    if (read_key(reader, key) != 0) {
        return -1;
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
static int place_pair(Reader *reader, Value *table, const Key *key, Value *value, int section)
{
    Value *nest = table;
    int i;
    for (i = 0; i + 1 < key->count; i++) {
        Value *next = find(nest, key->part[i], key->length[i]);
        if (next == NULL) {
            next = add_child(reader, nest, V_TABLE, key->part[i], key->length[i]);
            if (next == NULL) {
                return -1;
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
    if (find(nest, key->part[key->count - 1], key->length[key->count - 1]) != NULL) {
        return descend_error(reader);
    }
    return append(reader, nest, key->part[key->count - 1], key->length[key->count - 1], value);
}

/* parse_inline_table: { key = value, ... } on one line; dotted keys make tables inside. */
static int read_inline_table(Reader *reader, Value *table)
{
    reader->pos++;
    skip_blanks(reader);
    if (closes(reader, '}')) {
        return 0;
    }
    for (;;) {
        Key key;
        Value *value;
        if (read_pair(reader, table, &key, &value) != 0 || place_pair(reader, table, &key, value, 0) != 0) {
            return -1;
        }
        skip_blanks(reader);
        if (closes(reader, '}')) {
            return 0;
        }
        if (peek(reader, 0) != ',') {
            return malformed(reader, "unclosed inline table");
        }
        reader->pos++;
        skip_blanks(reader);
    }
}

/* parse_value */
static int read_value(Reader *reader, int depth, Value **out)
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
        return 0;
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
        Value *next = find(nest, key->part[i], key->length[i]);
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
    existing = find(parent, stem, stem_length);
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
static int read_statement_pair(Reader *reader, Value *header)
{
    Key key;
    Value *value;
    return read_pair(reader, header, &key, &value) != 0 ? -1 : place_pair(reader, header, &key, value, 1);
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
        if (bare_key_char(c) || c == '"' || c == '\'') {
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

typedef struct {
    char *error;
    size_t size;
    const char *source;
    Arena *arena;
} Loader;

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

static Value *get(const Value *table, const char *key)
{
    return find(table, key, strlen(key));
}

/* Python's order of str: code points, which UTF-8 bytes keep. */
static int key_before(const char *a, size_t na, const char *b, size_t nb)
{
    int order = memcmp(a, b, na < nb ? na : nb);
    return order < 0 || (order == 0 && na < nb);
}

/* loader._unknown: the first (sorted) key not in ``allowed``. */
static int unknown(const Loader *loader, const char *where, const Value *table, const char *const *allowed)
{
    const Item *item, *first = NULL;
    char list[512] = "";
    int i;
    for (item = table->first; item != NULL; item = item->next) {
        int known = 0;
        for (i = 0; allowed[i] != NULL && !known; i++) {
            known = strlen(allowed[i]) == item->key_length && memcmp(allowed[i], item->key, item->key_length) == 0;
        }
        if (!known && (first == NULL || key_before(item->key, item->key_length, first->key, first->key_length))) {
            first = item;
        }
    }
    if (first == NULL) {
        return 0;
    }
    for (i = 0; allowed[i] != NULL; i++) {
        if (i > 0) {
            strcat(list, ", ");
        }
        strcat(list, allowed[i]);
    }
    {
        Value key = {V_STRING, 0, 0, 0, 0, NULL, 0, 0, 0.0, NULL, NULL, 0};
        key.text = first->key;
        key.length = first->key_length;
        return fail(loader->error, loader->size, "%s: unknown key %v (allowed: %s)", where, &key, list);
    }
}

/* loader._number */
static int number(const Loader *loader, const char *where, const char *key, const Value *value, int positive,
                  int signed_, double *out)
{
    double v;
    if (value->kind != V_INTEGER && value->kind != V_FLOAT) {
        return fail(loader->error, loader->size, "%s.%s must be a number, got %v", where, key, value);
    }
    v = value->kind == V_INTEGER ? (double)value->integer : value->number;
    if (!isfinite(v)) {
        return fail(loader->error, loader->size, "%s.%s must be finite, got %v", where, key, value);
    }
    if (positive && v <= 0.0) {
        return fail(loader->error, loader->size, "%s.%s must be > 0, got %v", where, key, value);
    }
    if (v < 0.0 && !signed_) {
        return fail(loader->error, loader->size, "%s.%s must be >= 0, got %v", where, key, value);
    }
    *out = v;
    return 0;
}

/* loader._number of an optional key (``fallback`` when absent, as t.get(key, 0.0)) */
static int number_or(const Loader *loader, const char *where, const Value *table, const char *key, double fallback,
                     int signed_, double *out)
{
    const Value *value = get(table, key);
    if (value == NULL) {
        *out = fallback;
        return 0;
    }
    return number(loader, where, key, value, 0, signed_, out);
}

/* loader._table_list and loader._counted: the tables of ``key`` (NULL with count 0 if absent). */
static int counted(const Loader *loader, const Value *data, const char *key, int limit, const Value **list)
{
    const Value *items = get(data, key);
    const Item *item;
    *list = items;
    if (items == NULL) {
        return 0;
    }
    if (items->kind != V_ARRAY) {
        return fail(loader->error, loader->size, "%s must be an array of tables ([[%s]])", key, key);
    }
    for (item = items->first; item != NULL; item = item->next) {
        if (item->value->kind != V_TABLE) {
            return fail(loader->error, loader->size, "%s must be an array of tables ([[%s]])", key, key);
        }
    }
    if (items->count > (size_t)limit) {
        char count[32];
        snprintf(count, sizeof count, "%lu", (unsigned long)items->count);
        return fail(loader->error, loader->size, "%s [[%s]] tables are more than the %d accepted", count, key,
                    limit);
    }
    return 0;
}

static int list_count(const Value *list)
{
    return list == NULL ? 0 : (int)list->count;
}

/* elements._positive */
static int check_positive(const Loader *loader, const char *name, double value)
{
    if (!isfinite(value) || value <= 0.0) {
        return fail(loader->error, loader->size, "%s must be a finite number > 0, got %g", name, value);
    }
    return 0;
}

/* elements._non_negative */
static int check_non_negative(const Loader *loader, const char *name, double value)
{
    if (!isfinite(value) || value < 0.0) {
        return fail(loader->error, loader->size, "%s must be a finite number >= 0, got %g", name, value);
    }
    return 0;
}

/* ShaftSegment.__post_init__ */
static int check_segment(const Loader *loader, const RotorSegment *s)
{
    if (check_positive(loader, "length", s->length) != 0 ||
        check_positive(loader, "outer_diameter", s->outer_diameter) != 0 ||
        check_non_negative(loader, "inner_diameter", s->inner_diameter) != 0) {
        return -1;
    }
    if (s->inner_diameter >= s->outer_diameter) {
        return fail(loader->error, loader->size, "inner_diameter (%g) must be smaller than outer_diameter (%g)",
                    s->inner_diameter, s->outer_diameter);
    }
    if (check_positive(loader, "youngs_modulus", s->youngs_modulus) != 0 ||
        check_positive(loader, "density", s->density) != 0) {
        return -1;
    }
    if (!(-1.0 < s->poisson_ratio && s->poisson_ratio < 0.5)) {
        return fail(loader->error, loader->size, "poisson_ratio must lie in (-1, 0.5), got %g", s->poisson_ratio);
    }
    return 0;
}

/* ConcentratedMass.__post_init__ */
static int check_mass(const Loader *loader, const RotorMass *m)
{
    return check_non_negative(loader, "mass", m->mass) != 0 ||
                   check_non_negative(loader, "polar_inertia", m->polar_inertia) != 0 ||
                   check_non_negative(loader, "diametral_inertia", m->diametral_inertia) != 0
               ? -1
               : 0;
}

/* Bearing.__post_init__ (kyy and cyy resolved: checked again, as kxx and cxx before) */
static int check_bearing(const Loader *loader, const RotorBearing *b)
{
    static const char *const cross[] = {"kxy", "kyx", "cxy", "cyx"};
    const double values[] = {b->kxy, b->kyx, b->cxy, b->cyx};
    int k;
    if (check_non_negative(loader, "kxx", b->kxx) != 0 || check_non_negative(loader, "kyy", b->kyy) != 0 ||
        check_non_negative(loader, "cxx", b->cxx) != 0 || check_non_negative(loader, "cyy", b->cyy) != 0) {
        return -1;
    }
    for (k = 0; k < 4; k++) {
        if (!isfinite(values[k])) {
            return fail(loader->error, loader->size, "%s must be a finite number, got %g", cross[k], values[k]);
        }
    }
    return 0;
}

/* Unbalance.__post_init__ */
static int check_unbalance(const Loader *loader, const RotorUnbalance *u)
{
    if (check_non_negative(loader, "position", u->position) != 0 ||
        check_non_negative(loader, "amount", u->amount) != 0) {
        return -1;
    }
    if (!isfinite(u->phase)) {
        return fail(loader->error, loader->size, "phase must be a finite angle in rad, got %g", u->phase);
    }
    return 0;
}

/* Driveline.length: math.fsum of the segment lengths; NULL, or the text of Python's exception */
static const char *segments_length(const Driveline *d, double *sum)
{
    return python_fsum_strided(&d->segments[0].length, d->n_segments, sizeof(RotorSegment) / sizeof(double), sum);
}

/* Driveline.__post_init__'s checks on the nodes and the unbalances. */
static int check_driveline(const Loader *loader, const Driveline *d)
{
    int n_nodes = d->n_segments + 1, i;
    double length;
    for (i = 0; i < d->n_masses; i++) {
        if (d->masses[i].node >= n_nodes) {
            return fail(loader->error, loader->size, "masses[%d].node = %d is out of range: nodes are 0..%d", i,
                        d->masses[i].node, n_nodes - 1);
        }
    }
    for (i = 0; i < d->n_bearings; i++) {
        if (d->bearings[i].node >= n_nodes) {
            return fail(loader->error, loader->size, "bearings[%d].node = %d is out of range: nodes are 0..%d", i,
                        d->bearings[i].node, n_nodes - 1);
        }
    }
    for (i = 0; i < d->n_hinges; i++) {
        int node = d->hinges[i].node;
        if (node >= n_nodes) {
            return fail(loader->error, loader->size, "joints[%d].node = %d is out of range: nodes are 0..%d", i,
                        node, n_nodes - 1);
        }
        if (node == 0 || node == n_nodes - 1) {
            return fail(loader->error, loader->size,
                        "joints[%d].node = %d: a hinge must sit at an inner node (1..%d), not at an end", i, node,
                        n_nodes - 2);
        }
    }
    const char *failure = segments_length(d, &length);
    if (failure != NULL) {
        return fail(loader->error, loader->size, "%s", failure);
    }
    for (i = 0; i < d->n_unbalances; i++) {
        if (d->unbalances[i].position > length) {
            char position[32], end[32];
            python_float_repr(d->unbalances[i].position, position, sizeof position);
            python_float_repr(length, end, sizeof end);
            return fail(loader->error, loader->size, "unbalances[%d].position = %s m lies beyond the right end (%s m)",
                        i, position, end);
        }
    }
    return 0;
}

/* loader._materials */
static int materials(const Loader *loader, const Value *data, Material **out, int *count)
{
    const Value *table = get(data, "materials");
    const Item *item;
    int n = 0;
    *out = NULL;
    *count = 0;
    if (table == NULL) {
        return 0;
    }
    if (table->kind != V_TABLE) {
        return fail(loader->error, loader->size, "materials must be a table of named materials ([materials.NAME])");
    }
    *out = arena_alloc(loader->arena, (table->count + 1) * sizeof **out);
    if (*out == NULL) {
        return fail(loader->error, loader->size, "out of memory");
    }
    for (item = table->first; item != NULL; item = item->next, n++) {
        const Value *t = item->value, *E, *rho;
        char *where = arena_alloc(loader->arena, item->key_length + 16);
        Material *m = &(*out)[n];
        if (where == NULL) {
            return fail(loader->error, loader->size, "out of memory");
        }
        memcpy(where, "materials.", 10);
        memcpy(where + 10, item->key, item->key_length);
        where[10 + item->key_length] = '\0';
        if (t->kind != V_TABLE) {
            return fail(loader->error, loader->size, "%s must be a table", where);
        }
        if (unknown(loader, where, t, MATERIAL_KEYS) != 0) {
            return -1;
        }
        E = get(t, "youngs_modulus");
        rho = get(t, "density");
        if (rho == NULL || E == NULL) {
            return fail(loader->error, loader->size, "%s: missing key %r", where,
                        rho == NULL ? "density" : "youngs_modulus");
        }
        m->name = item->key;
        m->length = item->key_length;
        if (number(loader, where, "youngs_modulus", E, 1, 0, &m->E) != 0 ||
            number(loader, where, "density", rho, 1, 0, &m->rho) != 0) {
            return -1;
        }
        *count = n + 1;
    }
    return 0;
}

/* loader._flag */
static int flag(const Loader *loader, const char *where, const Value *t, const char *key, int *out)
{
    const Value *value = get(t, key);
    if (value == NULL) {
        return 0;
    }
    if (value->kind != V_BOOL) {
        return fail(loader->error, loader->size, "%s.%s must be true or false, got %v", where, key, value);
    }
    *out = (int)value->integer;
    return 0;
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
        for (j = i; j > 0 && key_before(mats[i].name, mats[i].length, mats[order[j - 1]].name,
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
static int segment(const Loader *loader, int i, const Value *t, const Material *mats, int n_mats, RotorSegment *s)
{
    static const char *const inner_keys[] = {"inner_diameter", "inner_radius", "wall_thickness"};
    char where[40];
    const char *outer_key = NULL, *inner_key = NULL;
    const Value *value, *nu;
    double d_out, d_in = 0.0, v;
    int have_E = 0, have_rho = 0, k;
    snprintf(where, sizeof where, "segments[%d]", i);
    if (unknown(loader, where, t, SEGMENT_KEYS) != 0) {
        return -1;
    }
    if (get(t, "length") == NULL) {
        return fail(loader->error, loader->size, "%s: missing key 'length'", where);
    }
    if (number(loader, where, "length", get(t, "length"), 1, 0, &s->length) != 0) {
        return -1;
    }
    if ((get(t, "outer_diameter") == NULL) == (get(t, "outer_radius") == NULL)) {
        return fail(loader->error, loader->size, "%s: give exactly one of 'outer_diameter' or 'outer_radius'", where);
    }
    outer_key = get(t, "outer_diameter") != NULL ? "outer_diameter" : "outer_radius";
    if (number(loader, where, outer_key, get(t, outer_key), 1, 0, &d_out) != 0) {
        return -1;
    }
    d_out *= outer_key[6] == 'r' ? 2.0 : 1.0;
    for (k = 0; k < 3; k++) {
        if (get(t, inner_keys[k]) != NULL) {
            if (inner_key != NULL) {
                return fail(loader->error, loader->size,
                            "%s: give at most one of 'inner_diameter', 'inner_radius', 'wall_thickness'", where);
            }
            inner_key = inner_keys[k];
        }
    }
    if (inner_key != NULL) {
        value = get(t, inner_key);
        if (number(loader, where, inner_key, value, 0, 0, &v) != 0) {
            return -1;
        }
        if (inner_key[0] == 'w') {
            if (v <= 0.0) {
                return fail(loader->error, loader->size, "%s.wall_thickness must be > 0, got %v", where, value);
            }
            if (2.0 * v > d_out) {
                return fail(loader->error, loader->size,
                            "%s.wall_thickness = %v exceeds half the outer diameter (%g)", where, value, d_out / 2);
            }
            d_in = d_out - 2.0 * v;
            d_in = 0.0 > d_in ? 0.0 : d_in;
        } else {
            d_in = v * (inner_key[6] == 'r' ? 2.0 : 1.0);
            if (d_in >= d_out) {
                return fail(loader->error, loader->size,
                            "%s.%s = %v must be smaller than the outer size (%s = %v)", where, inner_key, value,
                            outer_key, get(t, outer_key));
            }
        }
    }
    s->outer_diameter = d_out;
    s->inner_diameter = d_in;
    if ((value = get(t, "material")) != NULL) {
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
                return fail(loader->error, loader->size, "out of memory");
            }
            return fail(loader->error, loader->size, "%s.material %v is not a defined material (%s)", where, value,
                        known);
        }
        s->youngs_modulus = mats[m].E;
        s->density = mats[m].rho;
        have_E = have_rho = 1;
    }
    if ((value = get(t, "youngs_modulus")) != NULL) {
        if (number(loader, where, "youngs_modulus", value, 1, 0, &s->youngs_modulus) != 0) {
            return -1;
        }
        have_E = 1;
    }
    if ((value = get(t, "density")) != NULL) {
        if (number(loader, where, "density", value, 1, 0, &s->density) != 0) {
            return -1;
        }
        have_rho = 1;
    }
    if (!have_E || !have_rho) {
        return fail(loader->error, loader->size, "%s: missing key %r (or a 'material')", where,
                    !have_E ? "youngs_modulus" : "density");
    }
    s->rotary_inertia = s->gyroscopic = s->shear = 1;
    if (flag(loader, where, t, "rotary_inertia", &s->rotary_inertia) != 0 ||
        flag(loader, where, t, "gyroscopic", &s->gyroscopic) != 0 || flag(loader, where, t, "shear", &s->shear) != 0) {
        return -1;
    }
    s->poisson_ratio = 0.3;
    if ((nu = get(t, "poisson_ratio")) != NULL) {
        double x = nu->kind == V_INTEGER ? (double)nu->integer : nu->kind == V_FLOAT ? nu->number : NAN;
        /* an integer is in (-1, 0.5) just when it is 0, its double too */
        if (!(-1.0 < x && x < 0.5)) {
            return fail(loader->error, loader->size, "%s.poisson_ratio must be a number in (-1, 0.5), got %v", where,
                        nu);
        }
        s->poisson_ratio = x;
    }
    return check_segment(loader, s);
}

/* loader._station */
static int station(const Loader *loader, const char *where, const Value *t, int n_nodes, Station *out)
{
    const Value *node = get(t, "node"), *position = get(t, "position");
    if ((node != NULL) == (position != NULL)) {
        return fail(loader->error, loader->size, "%s: give exactly one of 'node' or 'position'", where);
    }
    out->is_node = node != NULL;
    if (node != NULL) {
        if (node->kind != V_INTEGER || node->integer < 0) {
            return fail(loader->error, loader->size, "%s.node must be an integer >= 0, got %v", where, node);
        }
        if (node->integer >= n_nodes) {
            char shown[32];
            snprintf(shown, sizeof shown, "%lld", node->integer);
            return fail(loader->error, loader->size, "%s.node = %s is out of range: nodes are 0..%d", where, shown,
                        n_nodes - 1);
        }
        out->node = (int)node->integer;
        out->value = out->node;
        return 0;
    }
    return number(loader, where, "position", position, 0, 0, &out->value);
}

/* loader._unbalance */
static int unbalance(const Loader *loader, int i, const Value *t, const double *ends, int n_ends, RotorUnbalance *u)
{
    char where[40];
    Station at;
    double position, right = ends[n_ends - 1];
    snprintf(where, sizeof where, "unbalances[%d]", i);
    if (unknown(loader, where, t, UNBALANCE_KEYS) != 0 || station(loader, where, t, n_ends, &at) != 0) {
        return -1;
    }
    position = at.is_node ? ends[at.node] : at.value;
    if (position > right + NODE_SNAP) {
        return fail(loader->error, loader->size, "%s.position = %g m lies beyond the right end (%g m)", where,
                    at.value, right);
    }
    if (get(t, "amount") == NULL) {
        return fail(loader->error, loader->size, "%s: missing key 'amount'", where);
    }
    u->position = right < position ? right : position;
    return number(loader, where, "amount", get(t, "amount"), 0, 0, &u->amount) != 0 ||
                   number_or(loader, where, t, "phase", 0.0, 1, &u->phase) != 0
               ? -1
               : check_unbalance(loader, u);
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* loader._cut: the segments split at every position that is no node (into ``d``), and every
 * station's node (``nodes[kind][i]``). */
static int cut(const Loader *loader, const RotorSegment *old, int n_old, Station *const stations[3],
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
        return fail(loader->error, loader->size, "out of memory");
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
            if (value > ends[n_old] + NODE_SNAP) {
                return fail(loader->error, loader->size, "%s[%d].position = %g m lies beyond the right end (%g m)",
                            kinds[kind], i, value, ends[n_old]);
            }
            for (k = 0; k < n_old && !(ends[k] <= value && value <= ends[k + 1]); k++) {
            }
            k = k == n_old ? 0 : k;
            if ((value - ends[k] < ends[k + 1] - value ? value - ends[k] : ends[k + 1] - value) > NODE_SNAP) {
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
                return fail(loader->error, loader->size, "out of memory");
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
    return 0;
}

/* loader._pair: (xx, yy) of a bearing from the isotropic ``key`` or from ``xx`` [+ ``yy``]. */
static int pair(const Loader *loader, const char *where, const Value *t, const char *key, const char *xx,
                const char *yy, int positive, double *x, double *y)
{
    const Value *iso = get(t, key), *vx = get(t, xx), *vy = get(t, yy);
    if (iso != NULL) {
        if (vx != NULL || vy != NULL) {
            return fail(loader->error, loader->size, "%s: give either %r or %r/%r, not both", where, key, xx, yy);
        }
        if (number(loader, where, key, iso, positive, 0, x) != 0) {
            return -1;
        }
        *y = *x;
        return 0;
    }
    if (vx == NULL) {
        if (positive) {
            return fail(loader->error, loader->size, "%s: missing key %r (or %r)", where, key, xx);
        }
        if (vy != NULL) {
            return fail(loader->error, loader->size, "%s: %r needs %r", where, yy, xx);
        }
        *x = *y = 0.0;
        return 0;
    }
    if (number(loader, where, xx, vx, positive, 0, x) != 0) {
        return -1;
    }
    if (vy == NULL) {
        *y = *x;
        return 0;
    }
    return number(loader, where, yy, vy, positive, 0, y);
}

/* loader._mass, _bearing, _hinge of entry ``i`` of ``kind`` (0, 1, 2) at ``node`` */
static int point_element(const Loader *loader, Driveline *d, int kind, int i, const Value *t, int node)
{
    char where[40];
    snprintf(where, sizeof where, "%s[%d]", kind == 0 ? "masses" : kind == 1 ? "bearings" : "hinges", i);
    if (unknown(loader, where, t, kind == 0 ? MASS_KEYS : kind == 1 ? BEARING_KEYS : HINGE_KEYS) != 0) {
        return -1;
    }
    if (kind == 0) {
        RotorMass *m = &d->masses[d->n_masses];
        m->node = node;
        if (get(t, "mass") == NULL) {
            return fail(loader->error, loader->size, "%s: missing key 'mass'", where);
        }
        if (number(loader, where, "mass", get(t, "mass"), 0, 0, &m->mass) != 0 ||
            number_or(loader, where, t, "polar_inertia", 0.0, 0, &m->polar_inertia) != 0 ||
            number_or(loader, where, t, "diametral_inertia", 0.0, 0, &m->diametral_inertia) != 0) {
            return -1;
        }
        d->n_masses++;
        return check_mass(loader, m);
    } else if (kind == 1) {
        RotorBearing *b = &d->bearings[d->n_bearings];
        b->node = node;
        if (pair(loader, where, t, "stiffness", "kxx", "kyy", 1, &b->kxx, &b->kyy) != 0 ||
            pair(loader, where, t, "damping", "cxx", "cyy", 0, &b->cxx, &b->cyy) != 0 ||
            number_or(loader, where, t, "kxy", 0.0, 1, &b->kxy) != 0 ||
            number_or(loader, where, t, "kyx", 0.0, 1, &b->kyx) != 0 ||
            number_or(loader, where, t, "cxy", 0.0, 1, &b->cxy) != 0 ||
            number_or(loader, where, t, "cyx", 0.0, 1, &b->cyx) != 0) {
            return -1;
        }
        d->n_bearings++;
        return check_bearing(loader, b);
    } else {
        RotorHinge *h = &d->hinges[d->n_hinges];
        int n_nodes = d->n_segments + 1;
        if (!(0 < node && node < n_nodes - 1)) {
            const Value *at = get(t, "node");
            if (at != NULL) {
                char shown[32];
                snprintf(shown, sizeof shown, "%lld", at->integer);
                return fail(loader->error, loader->size, "%s.node = %s must be an inner node (1..%d), not an end",
                            where, shown, n_nodes - 2);
            }
            return fail(loader->error, loader->size, "%s.position = %v m must be an inner node (1..%d), not an end",
                        where, get(t, "position"), n_nodes - 2);
        }
        h->node = node;
        if (number_or(loader, where, t, "bending_stiffness", 0.0, 0, &h->bending_stiffness) != 0) {
            return -1;
        }
        d->n_hinges++;
        return check_non_negative(loader, "bending_stiffness", h->bending_stiffness);
    }
    return 0;
}

static int end_condition(const Loader *loader, const Value *data, const char *key, EndCondition *out)
{
    const Value *v = get(data, key);
    int i;
    *out = END_FREE;
    if (v == NULL) {
        return 0;
    }
    for (i = 0; i < 3 && v->kind == V_STRING; i++) {
        if (v->length == strlen(END_NAMES[i]) && memcmp(v->text, END_NAMES[i], v->length) == 0) {
            *out = (EndCondition)i;
            return 0;
        }
    }
    return fail(loader->error, loader->size, "%s = %v is not one of: free, pinned, clamped", key, v);
}

/* loader.loads_driveline after the parse: the driveline of the document ``data``. */
static int load(const Loader *loader, const Value *data, Driveline *d)
{
    static const char *const kinds[] = {"masses", "bearings", "hinges"};
    static const int limits[] = {LAYOUT_MAX_POINT_ELEMENTS, LAYOUT_MAX_POINT_ELEMENTS, LAYOUT_MAX_POINT_ELEMENTS};
    const Value *name = get(data, "name"), *segs, *unbs, *tables[3];
    const Item *item;
    Material *mats;
    RotorSegment *old;
    Station *stations[3];
    int *nodes[3], counts[3], n_mats, n_old, n_unb, i, kind;
    double *ends;
    if (unknown(loader, loader->source, data, TOP_KEYS) != 0) {
        return -1;
    }
    if (name != NULL && name->kind != V_STRING) {
        return fail(loader->error, loader->size, "%s: name must be a string, got %v", loader->source, name);
    }
    if (end_condition(loader, data, "left_end", &d->left) != 0 ||
        end_condition(loader, data, "right_end", &d->right) != 0 || materials(loader, data, &mats, &n_mats) != 0 ||
        counted(loader, data, "segments", LAYOUT_MAX_SEGMENTS, &segs) != 0) {
        return -1;
    }
    n_old = list_count(segs);
    if (n_old == 0) {
        return fail(loader->error, loader->size, "%s: at least one [[segments]] table is required", loader->source);
    }
    old = arena_alloc(loader->arena, (size_t)n_old * sizeof *old);
    ends = arena_alloc(loader->arena, ((size_t)n_old + 1) * sizeof *ends);
    if (old == NULL || ends == NULL) {
        return fail(loader->error, loader->size, "out of memory");
    }
    ends[0] = 0.0;
    for (i = 0, item = segs->first; item != NULL; item = item->next, i++) {
        if (segment(loader, i, item->value, mats, n_mats, &old[i]) != 0) {
            return -1;
        }
        ends[i + 1] = ends[i] + old[i].length;
    }
    if (counted(loader, data, "unbalances", LAYOUT_MAX_POINT_ELEMENTS, &unbs) != 0) {
        return -1;
    }
    n_unb = list_count(unbs);
    d->unbalances = malloc(((size_t)n_unb + 1) * sizeof *d->unbalances);
    if (d->unbalances == NULL) {
        return fail(loader->error, loader->size, "out of memory");
    }
    for (i = 0, item = unbs != NULL ? unbs->first : NULL; item != NULL; item = item->next, i++) {
        if (unbalance(loader, i, item->value, ends, n_old + 1, &d->unbalances[i]) != 0) {
            return -1;
        }
        d->n_unbalances = i + 1;
    }
    for (kind = 0; kind < 3; kind++) {
        if (counted(loader, data, kinds[kind], limits[kind], &tables[kind]) != 0) {
            return -1;
        }
        counts[kind] = list_count(tables[kind]);
        stations[kind] = arena_alloc(loader->arena, ((size_t)counts[kind] + 1) * sizeof *stations[kind]);
        nodes[kind] = arena_alloc(loader->arena, ((size_t)counts[kind] + 1) * sizeof *nodes[kind]);
        if (stations[kind] == NULL || nodes[kind] == NULL) {
            return fail(loader->error, loader->size, "out of memory");
        }
    }
    for (kind = 0; kind < 3; kind++) {
        for (i = 0, item = tables[kind] != NULL ? tables[kind]->first : NULL; item != NULL; item = item->next, i++) {
            char where[40];
            snprintf(where, sizeof where, "%s[%d]", kinds[kind], i);
            if (station(loader, where, item->value, n_old + 1, &stations[kind][i]) != 0) {
                return -1;
            }
        }
    }
    if (cut(loader, old, n_old, stations, counts, d, nodes) != 0) {
        return -1;
    }
    d->masses = malloc(((size_t)counts[0] + 1) * sizeof *d->masses);
    d->bearings = malloc(((size_t)counts[1] + 1) * sizeof *d->bearings);
    d->hinges = malloc(((size_t)counts[2] + 1) * sizeof *d->hinges);
    if (d->masses == NULL || d->bearings == NULL || d->hinges == NULL) {
        return fail(loader->error, loader->size, "out of memory");
    }
    for (kind = 0; kind < 3; kind++) {
        for (i = 0, item = tables[kind] != NULL ? tables[kind]->first : NULL; item != NULL; item = item->next, i++) {
            if (point_element(loader, d, kind, i, item->value, nodes[kind][i]) != 0) {
                return -1;
            }
        }
    }
    return check_driveline(loader, d);
}

/* loader._nesting_errors: brackets anywhere (strings too) nest at most MAX_NESTING deep. */
static int nesting_errors(const char *text, size_t length, const char *source, char *error, size_t size)
{
    size_t i;
    int depth = 0;
    for (i = 0; i < length; i++) {
        if (text[i] == '[' || text[i] == '{') {
            if (++depth > LAYOUT_MAX_NESTING) {
                return fail(error, size, "%s: brackets nest deeper than %d levels", source, LAYOUT_MAX_NESTING);
            }
        } else if ((text[i] == ']' || text[i] == '}') && depth > 0) {
            depth--;
        }
    }
    return 0;
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

/* The first invalid UTF-8 sequence (CPython's decoder: its reason and start), -1 if none. */
static long utf8_error(const unsigned char *bytes, size_t length, const char **reason)
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

int driveline_from_text(const char *text, size_t length, const char *source, Driveline *out, char *error,
                        size_t size)
{
    Reader reader;
    Arena arena = {NULL};
    Loader loader;
    Value *root;
    const char *reason;
    int status;
    memset(out, 0, sizeof *out);
    if (size > 0) {
        error[0] = '\0';
    }
    if (nesting_errors(text, length, source, error, size) != 0) {
        return -1;
    }
    memset(&reader, 0, sizeof reader);
    reader.source = source;
    reader.error = error;
    reader.size = size;
    if (utf8_error((const unsigned char *)text, length, &reason) >= 0) {
        return fail(error, size, "%s: malformed TOML: the text is not UTF-8 (%s)", source, reason);
    }
    root = read_document(&reader, text, length);
    if (root == NULL) {
        arena_free(&reader.arena);
        return -1;
    }
    arena = reader.arena;
    loader.error = error;
    loader.size = size;
    loader.source = source;
    loader.arena = &arena;
    status = load(&loader, root, out);
    arena_free(&arena);
    if (status != 0) {
        driveline_free(out);
    }
    return status;
}

/* ---- what ISO C cannot ask the operating system ------------------------------------------ */
/* Standard C has neither the working directory nor a file's type, and opening a FIFO with fopen
 * blocks until a writer comes: these two calls, with the C library each platform has, are all the
 * loader asks of the system beyond stdio. */

/* The working directory into ``out`` (``room`` bytes); NULL with errno (ERANGE: too small). */
static char *working_directory(char *out, size_t room)
{
#ifdef _WIN32
    return _getcwd(out, room > INT_MAX ? INT_MAX : (int)room);
#else
    return getcwd(out, room);
#endif
}

/* 1 when ``path`` names a regular file, 0 when it names something else (a directory, a FIFO, a
 * device), -1 with errno when it names nothing that can be looked at. */
static int regular_file(const char *path)
{
#ifdef _WIN32
    struct _stat64 info;
    if (_stat64(path, &info) != 0) {
        return -1;
    }
    return (info.st_mode & _S_IFMT) == _S_IFREG;
#else
    struct stat info;
    if (stat(path, &info) != 0) {
        return -1;
    }
    return S_ISREG(info.st_mode) != 0;
#endif
}

/* os.strerror */
static void error_text(int err, char *out, size_t size)
{
    const char *text = strerror(err);
    if (text != NULL) {
        snprintf(out, size, "%s", text);
    } else {
        snprintf(out, size, "error %d", err);
    }
}

#ifdef _WIN32
#define SEPARATOR "\\"
#define IS_ABSOLUTE(path) ((path)[0] == '/' || (path)[0] == '\\' || ((path)[0] != '\0' && (path)[1] == ':'))
#else
#define SEPARATOR "/"
#define IS_ABSOLUTE(path) ((path)[0] == '/')
#endif

/* pathlib's Path(path).absolute(): the working directory before a relative path, "//" and "."
 * parts dropped (a leading "//" kept), ".." kept (on Windows only the working directory put
 * before a relative path). Owned (free()); NULL with errno. */
static char *absolute_path(const char *path)
{
    char *joined, *out, *cwd = NULL;
    size_t n, used = 0, at, root;
    if (!IS_ABSOLUTE(path)) {
        size_t room = 256;
        for (;;) {
            char *grown = realloc(cwd, room);
            if (grown == NULL) {
                free(cwd);
                errno = ENOMEM;
                return NULL;
            }
            cwd = grown;
            if (working_directory(cwd, room) != NULL) {
                break;
            }
            if (errno != ERANGE) {
                free(cwd);
                return NULL;
            }
            room *= 2;
        }
    }
    n = (cwd != NULL ? strlen(cwd) + 1 : 0) + strlen(path) + 1;
    joined = malloc(n);
    out = malloc(n + 1);
    if (joined == NULL || out == NULL) {
        free(cwd);
        free(joined);
        free(out);
        errno = ENOMEM;
        return NULL;
    }
    snprintf(joined, n, "%s%s%s", cwd != NULL ? cwd : "", cwd != NULL ? SEPARATOR : "", path);
    free(cwd);
#ifdef _WIN32
    free(out);
    return joined;
#endif
    out[used++] = '/';
    if (joined[0] == '/' && joined[1] == '/' && joined[2] != '/') {
        out[used++] = '/';
    }
    root = used;
    for (at = 0; joined[at] != '\0';) {
        size_t start, part;
        while (joined[at] == '/') {
            at++;
        }
        start = at;
        while (joined[at] != '\0' && joined[at] != '/') {
            at++;
        }
        part = at - start;
        if (part == 0 || (part == 1 && joined[start] == '.')) {
            continue;
        }
        if (used > root) {
            out[used++] = '/';
        }
        memcpy(out + used, joined + start, part);
        used += part;
    }
    out[used] = '\0';
    free(joined);
    return out;
}

/* loader._read_regular_file: refuse what is not a regular file before opening it (a FIFO would block
 * fopen), read at most MAX_FILE_BYTES + 1 bytes. ``*data`` owned (free()). */
static int read_regular_file(const char *path, char **data, size_t *length, char *error, size_t size)
{
    char reason[128];
    size_t used = 0;
    int err = 0, regular;
    FILE *file = NULL;
    *data = NULL;
    errno = 0;
    regular = regular_file(path);
    if (regular == 0) {
        return fail(error, size, "driveline file %r is not a regular file", path);
    }
    if (regular < 0 || (file = fopen(path, "rb")) == NULL) {
        err = errno != 0 ? errno : EINVAL;
    } else if ((*data = malloc(LAYOUT_MAX_FILE_BYTES + 1)) == NULL) {
        fclose(file);
        return fail(error, size, "out of memory");
    } else {
        while (used <= LAYOUT_MAX_FILE_BYTES) {
            size_t got = fread(*data + used, 1, LAYOUT_MAX_FILE_BYTES + 1 - used, file);
            if (got == 0) {
                break;
            }
            used += got;
        }
        if (ferror(file)) {
            err = errno != 0 ? errno : EIO;
        }
        fclose(file);
    }
    if (err != 0) {
        free(*data);
        *data = NULL;
        error_text(err, reason, sizeof reason);
        return fail(error, size, "cannot read driveline file %r: %s", path, reason);
    }
    if (used > LAYOUT_MAX_FILE_BYTES) {
        free(*data);
        *data = NULL;
        return fail(error, size, "driveline file %r is larger than %d bytes", path, LAYOUT_MAX_FILE_BYTES);
    }
    *length = used;
    return 0;
}

/* loader.load_driveline */
static int load_driveline(const char *path, Driveline *out, char *error, size_t size)
{
    char *p = absolute_path(path), *data, *message;
    size_t length = 0, p_length;
    const char *reason;
    long bad;
    int status;
    memset(out, 0, sizeof *out);
    if (p == NULL && errno == ENOMEM) {
        return fail(error, size, "out of memory");
    }
    if (p == NULL) { /* the working directory is gone (os.getcwd's OSError) */
        char reason_text[128];
        error_text(errno, reason_text, sizeof reason_text);
        return fail(error, size, "cannot read driveline file %r: %s", path, reason_text);
    }
    if (read_regular_file(p, &data, &length, error, size) != 0) {
        free(p);
        return -1;
    }
    bad = utf8_error((const unsigned char *)data, length, &reason);
    if (bad >= 0) {
        char at[32];
        snprintf(at, sizeof at, "%ld", bad);
        fail(error, size, "driveline file %r is not UTF-8 text (%s at byte %s)", p, reason, at);
        free(data);
        free(p);
        return -1;
    }
    status = driveline_from_text(data, length, p, out, error, size);
    free(data);
    p_length = strlen(p);
    if (status != 0 && size > 0 && strncmp(error, p, p_length) != 0) {
        message = malloc(size);
        if (message == NULL) {
            fail(error, size, "out of memory");
        } else {
            memcpy(message, error, size);
            message[size - 1] = '\0';
            fail(error, size, "%s: %s", p, message);
            free(message);
        }
    }
    free(p);
    return status;
}

/* model.build_driveline for a layout: a ".toml" file or a shipped name (loader.example_path). */
int driveline_from_layout(const char *layout, const char *resources, Driveline *out, char *error, size_t size)
{
    size_t n = strlen(layout), i;
    char *path;
    int status;
    memset(out, 0, sizeof *out);
    if (size > 0) {
        error[0] = '\0';
    }
    if (n >= 5 && layout[n - 5] == '.' && (layout[n - 4] | 0x20) == 't' && (layout[n - 3] | 0x20) == 'o' &&
        (layout[n - 2] | 0x20) == 'm' && (layout[n - 1] | 0x20) == 'l') {
        return load_driveline(layout, out, error, size);
    }
    for (i = 0; i < n; i++) {
        if (!(bare_key_char((unsigned char)layout[i]) && layout[i] != '-')) {
            break;
        }
    }
    if (n == 0 || n > 64 || i < n) {
        Text text = {error, size, 0};
        put(&text, "no shipped example named ");
        if (text.used + 1 < size) {
            python_str_repr_n(layout, n, 80, error + text.used, size - text.used);
            text.used += strlen(error + text.used);
        }
        put(&text, " (names are letters, digits and '_')");
        return -1;
    }
    if (resources == NULL) {
        return fail(error, size, "no shipped example named %r", layout);
    }
    path = malloc(strlen(resources) + n + 8);
    if (path == NULL) {
        return fail(error, size, "out of memory");
    }
    sprintf(path, "%s/%s.toml", resources, layout);
    if (regular_file(path) != 1) {
        free(path);
        return fail(error, size, "no shipped example named %r", layout);
    }
    status = load_driveline(path, out, error, size);
    free(path);
    return status;
}

/* loader.one_piece_shaft */
int driveline_one_piece(const OnePieceShaft *shaft, Driveline *out, char *error, size_t size)
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
            return fail(error, size, "%s must be a finite number, got %g", names[i], values[i]);
        }
    }
    for (pass = 1; pass >= 0; pass--) {
        for (i = 0; i < 10; i++) {
            if (positive[i] == pass && (pass ? values[i] <= 0.0 : values[i] < 0.0)) {
                return fail(error, size, pass ? "%s must be > 0, got %g" : "%s must be >= 0, got %g", names[i],
                            values[i]);
            }
        }
    }
    if (shaft->D_inner >= shaft->D_outer) {
        return fail(error, size, "D_inner (%g) must be smaller than D_outer (%g)", shaft->D_inner, shaft->D_outer);
    }
    out->segments = malloc(sizeof *out->segments);
    out->masses = malloc(2 * sizeof *out->masses);
    out->bearings = malloc(2 * sizeof *out->bearings);
    if (out->segments == NULL || out->masses == NULL || out->bearings == NULL) {
        driveline_free(out);
        return fail(error, size, "out of memory");
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
    return 0;
}

/* Driveline.length */
double driveline_length(const Driveline *driveline)
{
    double sum;
    return segments_length(driveline, &sum) == NULL ? sum : HUGE_VAL;
}

/* Driveline.is_isotropic (the chain's: every bearing with kxx == kyy) */
int driveline_isotropic(const Driveline *driveline)
{
    int i;
    for (i = 0; i < driveline->n_bearings; i++) {
        if (driveline->bearings[i].kxx != driveline->bearings[i].kyy) {
            return 0;
        }
    }
    return 1;
}
