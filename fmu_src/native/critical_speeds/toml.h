/* The layouts' TOML-subset reader and what its messages need, for the modules that read a layout:
 *   messages.c     the messages: Python's repr() of the values read, the loader's format (%r, %v, %g)
 *   arena.c        the memory of one reading, freed at once
 *   toml.c         the TOML-subset reader (tomllib.loads)
 *   layout_file.c  a layout by name or file: the file read as loader._read_regular_file does
 * Internal to the rotor library (rotor.h is its interface). */
#ifndef TOML_H
#define TOML_H

#include <stddef.h>

#include "rotor.h"

/* Tables and arrays nested below the document at the most (deeper is refused as malformed TOML:
 * a bound on a key's parts and on the stack of text_put_repr). */
#define TREE_DEPTH (4 * ROTOR_LOADER_MAX_NESTING)

/* ---- messages (messages.c) ----------------------------------------------------------------- */

/* a message being written into ``out`` (``size`` bytes, ``used`` so far, always terminated) */
typedef struct {
    char *out;
    size_t size, used;
} Text;

/* ---- the arena (arena.c) ------------------------------------------------------------------- */

typedef struct Block Block;

typedef struct {
    Block *blocks;
} Arena;

void *arena_alloc(Arena *arena, size_t count);
void arena_free(Arena *arena);

/* ---- TOML values (toml.c) ------------------------------------------------------------------ */

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

void text_put_bytes(Text *text, const char *bytes, size_t count);
void text_put(Text *text, const char *piece);
void text_put_str_repr(Text *text, const char *bytes, size_t count);
void text_put_float(Text *text, double value);
void text_put_repr(Text *text, const Value *value);
/* The message into ``error``: ``format`` with %s (C string), %d (int), %v (a Value's repr), %g (a
 * double's repr), %r (a C string's repr). Returns ERROR_VALUE: the loader raises ValueError only. */
ErrorKind layout_error(char *error, size_t size, const char *format, ...);

/* tomllib.loads of ``text`` (``length`` bytes of UTF-8): the document's table into *root, built in
 * ``arena`` (which the caller frees, also on failure); ERROR_NONE, or ERROR_VALUE (*root NULL) with the
 * message ``source``: malformed TOML: ... (tomllib's TOMLDecodeError, which the loader raises as a
 * ValueError) or out of memory */
ErrorKind toml_read(const char *text, size_t length, const char *source, Arena *arena, Value **root, char *error,
                    size_t size);
/* the value of ``key`` in ``table``, NULL if absent */
Value *toml_find(const Value *table, const char *key, size_t key_length);
/* The first invalid UTF-8 sequence (CPython's decoder: its reason and start), -1 if none. */
long toml_utf8_error(const unsigned char *bytes, size_t length, const char **reason);
/* a character of a bare key */
int toml_bare_key_char(int c);

#endif
