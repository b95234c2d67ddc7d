/* The layouts' TOML-subset reader and the rules every model's layout files share
 * (driveline/layout_files.py), the library of every model that reads layout files (CriticalSpeeds' rotor
 * library, PowertrainMounts), one module per concern:
 *   messages.c     the messages: Python's repr() of the values read, the loader's format (%r, %v, %g)
 *   pyrepr.c       Python's repr() of the values the messages show
 *   arena.c        the memory of one reading, freed at once
 *   toml.c         the TOML-subset reader (tomllib.loads)
 *   layout_file.c  a layout by name or file (layout_files.read_layout, shipped_path), its text parsed
 *                  (layout_files.parse) and the loaders' shared checks (unknown, number, counted) */
#ifndef TOML_H
#define TOML_H

#include <stddef.h>

#include "python_numbers.h"

/* Tables and arrays nested below the document at the most (deeper is refused as malformed TOML:
 * a bound on a key's parts and on the stack of text_put_repr). */
#define TREE_DEPTH (4 * DRIVELINE_LAYOUT_FILES_MAX_NESTING)

/* ---- pyrepr.c -------------------------------------------------------------------------------- */
/* repr() of a Python str holding the UTF-8 ``text`` cut to its first ``max_chars`` code points (0: all). */
void python_str_repr(const char *text, size_t max_chars, char *out, size_t size);
/* The same for ``length`` bytes (the text may hold NUL characters). */
void python_str_repr_n(const char *text, size_t length, size_t max_chars, char *out, size_t size);
/* Appends ``count`` bytes to the text of ``*used`` bytes in ``out`` (``size`` bytes), cut to fit,
 * always terminated; ``*used`` grows by what was written. */
void text_append(char *out, size_t size, size_t *used, const char *bytes, size_t count);

/* ---- messages (messages.c) ----------------------------------------------------------------- */

/* a message being written into ``out`` (``size`` bytes, ``used`` so far, always terminated) */
typedef struct {
    char *out;
    size_t size, used;
} Text;

/* ---- the arena (arena.c) ------------------------------------------------------------------- */

typedef struct ArenaBlock ArenaBlock;

typedef struct {
    ArenaBlock *blocks;
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

/* ---- layout files (layout_file.c) ---------------------------------------------------------- */

/* A reading of one layout: where its messages go, the file's name in them, its memory. */
typedef struct {
    char *error;
    size_t size;
    const char *source;
    Arena *arena;
} Loader;

/* How a model's messages call its layout files: "driveline file" and "example" (read_layout's
 * ``what``, shipped_path's ``what``). */
typedef struct {
    const char *file, *shipped;
} LayoutNames;

/* A model's loads(text, source): the layout of ``length`` bytes of text into ``out``; ERROR_NONE or the
 * failure's kind with the message. */
typedef ErrorKind (*LayoutLoads)(const char *text, size_t length, const char *source, void *out, char *error,
                                 size_t size);

/* A layout: a file path ending in ".toml" (any case; relative to the working directory; messages name it
 * by its absolute path, as pathlib's absolute()), read as layout_files.read_layout does, or the name of a
 * layout shipped in ``resources`` (the FMU's resources folder: layout_files.shipped_path), given to
 * ``loads``. ERROR_NONE, or the failure's kind with the message. */
ErrorKind layout_file_load(const char *layout, const char *resources, const LayoutNames *names, LayoutLoads loads,
                           void *out, char *error, size_t size);
/* layout_files.parse: the nesting check, then toml_read into ``loader->arena``. */
ErrorKind layout_parse(const char *text, size_t length, const Loader *loader, Value **root);
/* Python's order of str: code points, which UTF-8 bytes keep. */
int layout_key_before(const char *a, size_t na, const char *b, size_t nb);
/* the value of ``key`` in ``table``, NULL if absent */
Value *layout_get(const Value *table, const char *key);
/* layout_files.unknown: the first (sorted) key of ``table`` not in ``allowed`` (NULL-terminated). */
ErrorKind layout_unknown(const Loader *loader, const char *where, const Value *table, const char *const *allowed);
/* layout_files.number */
ErrorKind layout_number(const Loader *loader, const char *where, const char *key, const Value *value, int positive,
                        int signed_, double *out);
/* layout_files.table_list and counted: the tables of ``key`` (NULL if absent). */
ErrorKind layout_counted(const Loader *loader, const Value *data, const char *key, int limit, const Value **list);

#endif
