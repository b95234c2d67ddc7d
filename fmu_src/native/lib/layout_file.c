/* A layout by file or shipped name (layout_files.read_layout, shipped_path): the path made absolute as
 * pathlib does, the file read with stdio, at most MAX_FILE_BYTES, only a regular file; its text parsed
 * (layout_files.parse) and the checks every loader shares (unknown, number, counted). */
#if !defined(_WIN32) && !defined(_POSIX_C_SOURCE)
#define _POSIX_C_SOURCE 200809L /* fdopen and O_CLOEXEC besides ISO C */
#endif
#include "toml.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#ifdef _WIN32
#include <direct.h> /* _getcwd */
#include <io.h>     /* _open, _close */
#else
#include <unistd.h> /* getcwd, close */
#endif

/* ---- what ISO C cannot ask the operating system ------------------------------------------ */
/* Standard C has neither the working directory nor a file's type, and opening a FIFO with fopen
 * blocks until a writer comes: the working directory, a path's type, and a file opened without
 * blocking whose type is then asked of the open file (so that nothing can swap a FIFO in between),
 * with the C library each platform has, are all the loader asks of the system beyond stdio. */
#ifdef _WIN32
typedef struct _stat64 FileInfo;
#define info_of_path _stat64
#define open_without_blocking(path) _open((path), _O_RDONLY | _O_BINARY) /* no FIFOs among Windows' files */
#define info_of_open_file _fstat64
#define close_file _close
#define stream_of_open_file _fdopen
#define IS_REGULAR(mode) (((mode) & _S_IFMT) == _S_IFREG)
#else
typedef struct stat FileInfo;
#define info_of_path stat
#ifndef O_CLOEXEC
#define O_CLOEXEC 0
#endif
#define open_without_blocking(path) open((path), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC)
#define info_of_open_file fstat
#define close_file close
#define stream_of_open_file fdopen
#define IS_REGULAR(mode) S_ISREG(mode)
#endif

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
    FileInfo info;
    if (info_of_path(path, &info) != 0) {
        return -1;
    }
    return IS_REGULAR(info.st_mode) != 0;
}

/* loader._read_regular_file's opening: ``path`` opened for reading without blocking (a FIFO opens at
 * once), its type asked of the open file. 1 with ``*file`` open for a regular file, 0 for something
 * else (closed again), -1 with errno when it cannot be opened or looked at. */
static int open_regular_file(const char *path, FILE **file)
{
    FileInfo info;
    int descriptor = open_without_blocking(path), err;
    *file = NULL;
    if (descriptor < 0) {
        return -1;
    }
    if (info_of_open_file(descriptor, &info) != 0) {
        err = errno;
        close_file(descriptor);
        errno = err;
        return -1;
    }
    if (!IS_REGULAR(info.st_mode)) {
        close_file(descriptor);
        return 0;
    }
    if ((*file = stream_of_open_file(descriptor, "rb")) == NULL) {
        err = errno;
        close_file(descriptor);
        errno = err;
        return -1;
    }
    return 1;
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

/* layout_files.read_regular_file: refuse what is not a regular file (opened without blocking), read at
 * most MAX_FILE_BYTES + 1 bytes. ``*data`` owned (free()). ERROR_NONE, or ERROR_VALUE with the
 * message (the loader raises the OSError as a ValueError). */
static ErrorKind read_regular_file(const char *path, const char *what, char **data, size_t *length, char *error,
                                   size_t size)
{
    char reason[128];
    size_t used = 0;
    int err = 0, regular;
    FILE *file = NULL;
    *data = NULL;
    errno = 0;
    regular = open_regular_file(path, &file);
    if (regular == 0) {
        return layout_error(error, size, "%s %r is not a regular file", what, path);
    }
    if (regular < 0) {
        err = errno != 0 ? errno : EINVAL;
    } else if ((*data = malloc(DRIVELINE_LAYOUT_FILES_MAX_FILE_BYTES + 1)) == NULL) {
        fclose(file);
        return layout_error(error, size, "out of memory");
    } else {
        while (used <= DRIVELINE_LAYOUT_FILES_MAX_FILE_BYTES) {
            size_t got = fread(*data + used, 1, DRIVELINE_LAYOUT_FILES_MAX_FILE_BYTES + 1 - used, file);
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
        return layout_error(error, size, "cannot read %s %r: %s", what, path, reason);
    }
    if (used > DRIVELINE_LAYOUT_FILES_MAX_FILE_BYTES) {
        free(*data);
        *data = NULL;
        return layout_error(error, size, "%s %r is larger than %d bytes", what, path,
                            DRIVELINE_LAYOUT_FILES_MAX_FILE_BYTES);
    }
    *length = used;
    return ERROR_NONE;
}

Value *layout_get(const Value *table, const char *key)
{
    return toml_find(table, key, strlen(key));
}

/* Python's order of str: code points, which UTF-8 bytes keep. */
int layout_key_before(const char *a, size_t na, const char *b, size_t nb)
{
    int order = memcmp(a, b, na < nb ? na : nb);
    return order < 0 || (order == 0 && na < nb);
}

/* layout_files.unknown */
ErrorKind layout_unknown(const Loader *loader, const char *where, const Value *table, const char *const *allowed)
{
    const Item *item, *first = NULL;
    char list[512] = "";
    int i;
    for (item = table->first; item != NULL; item = item->next) {
        int known = 0;
        for (i = 0; allowed[i] != NULL && !known; i++) {
            known = strlen(allowed[i]) == item->key_length && memcmp(allowed[i], item->key, item->key_length) == 0;
        }
        if (!known &&
            (first == NULL || layout_key_before(item->key, item->key_length, first->key, first->key_length))) {
            first = item;
        }
    }
    if (first == NULL) {
        return ERROR_NONE;
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
        return layout_error(loader->error, loader->size, "%s: unknown key %v (allowed: %s)", where, &key, list);
    }
}

/* layout_files.number */
ErrorKind layout_number(const Loader *loader, const char *where, const char *key, const Value *value, int positive,
                        int signed_, double *out)
{
    double v;
    if (value->kind != V_INTEGER && value->kind != V_FLOAT) {
        return layout_error(loader->error, loader->size, "%s.%s must be a number, got %v", where, key, value);
    }
    v = value->kind == V_INTEGER ? (double)value->integer : value->number;
    if (!isfinite(v)) {
        return layout_error(loader->error, loader->size, "%s.%s must be finite, got %v", where, key, value);
    }
    if (positive && v <= 0.0) {
        return layout_error(loader->error, loader->size, "%s.%s must be > 0, got %v", where, key, value);
    }
    if (v < 0.0 && !signed_) {
        return layout_error(loader->error, loader->size, "%s.%s must be >= 0, got %v", where, key, value);
    }
    *out = v;
    return ERROR_NONE;
}

/* layout_files.table_list and counted */
ErrorKind layout_counted(const Loader *loader, const Value *data, const char *key, int limit, const Value **list)
{
    const Value *items = layout_get(data, key);
    const Item *item;
    *list = items;
    if (items == NULL) {
        return ERROR_NONE;
    }
    if (items->kind != V_ARRAY) {
        return layout_error(loader->error, loader->size, "%s must be an array of tables ([[%s]])", key, key);
    }
    for (item = items->first; item != NULL; item = item->next) {
        if (item->value->kind != V_TABLE) {
            return layout_error(loader->error, loader->size, "%s must be an array of tables ([[%s]])", key, key);
        }
    }
    if (items->count > (size_t)limit) {
        char count[32];
        snprintf(count, sizeof count, "%lu", (unsigned long)items->count);
        return layout_error(loader->error, loader->size, "%s [[%s]] tables are more than the %d accepted", count, key,
                    limit);
    }
    return ERROR_NONE;
}


/* layout_files.nesting_errors: brackets anywhere (strings too) nest at most MAX_NESTING deep. */
static ErrorKind nesting_errors(const char *text, size_t length, const char *source, char *error, size_t size)
{
    size_t i;
    int depth = 0;
    for (i = 0; i < length; i++) {
        if (text[i] == '[' || text[i] == '{') {
            if (++depth > DRIVELINE_LAYOUT_FILES_MAX_NESTING) {
                return layout_error(error, size, "%s: brackets nest deeper than %d levels", source,
                                    DRIVELINE_LAYOUT_FILES_MAX_NESTING);
            }
        } else if ((text[i] == ']' || text[i] == '}') && depth > 0) {
            depth--;
        }
    }
    return ERROR_NONE;
}

ErrorKind layout_parse(const char *text, size_t length, const Loader *loader, Value **root)
{
    const char *reason;
    ErrorKind status = nesting_errors(text, length, loader->source, loader->error, loader->size);
    *root = NULL;
    if (status != ERROR_NONE) {
        return status;
    }
    if (toml_utf8_error((const unsigned char *)text, length, &reason) >= 0) {
        return layout_error(loader->error, loader->size, "%s: malformed TOML: the text is not UTF-8 (%s)",
                            loader->source, reason);
    }
    return toml_read(text, length, loader->source, loader->arena, root, loader->error, loader->size);
}

/* layout_files.read_layout; returns as ``loads`` */
static ErrorKind load_file(const char *path, const LayoutNames *names, LayoutLoads loads, void *out, char *error,
                           size_t size)
{
    char *p = absolute_path(path), *data, *message;
    size_t length = 0, p_length;
    const char *reason;
    long bad;
    ErrorKind status;
    if (p == NULL && errno == ENOMEM) {
        return layout_error(error, size, "out of memory");
    }
    if (p == NULL) { /* the working directory is gone (os.getcwd's OSError) */
        char reason_text[128];
        error_text(errno, reason_text, sizeof reason_text);
        return layout_error(error, size, "cannot read %s %r: %s", names->file, path, reason_text);
    }
    if ((status = read_regular_file(p, names->file, &data, &length, error, size)) != ERROR_NONE) {
        free(p);
        return status;
    }
    bad = toml_utf8_error((const unsigned char *)data, length, &reason);
    if (bad >= 0) {
        char at[32];
        snprintf(at, sizeof at, "%ld", bad);
        status = layout_error(error, size, "%s %r is not UTF-8 text (%s at byte %s)", names->file, p, reason, at);
        free(data);
        free(p);
        return status;
    }
    status = loads(data, length, p, out, error, size);
    free(data);
    p_length = strlen(p);
    if (status != ERROR_NONE && size > 0 && strncmp(error, p, p_length) != 0) {
        message = malloc(size);
        if (message == NULL) {
            layout_error(error, size, "out of memory");
        } else {
            memcpy(message, error, size);
            message[size - 1] = '\0';
            layout_error(error, size, "%s: %s", p, message);
            free(message);
        }
    }
    free(p);
    return status;
}

ErrorKind layout_file_load(const char *layout, const char *resources, const LayoutNames *names, LayoutLoads loads,
                           void *out, char *error, size_t size)
{
    size_t n = strlen(layout), i;
    char *path;
    ErrorKind status;
    if (size > 0) {
        error[0] = '\0';
    }
    if (n >= 5 && layout[n - 5] == '.' && (layout[n - 4] | 0x20) == 't' && (layout[n - 3] | 0x20) == 'o' &&
        (layout[n - 2] | 0x20) == 'm' && (layout[n - 1] | 0x20) == 'l') {
        return load_file(layout, names, loads, out, error, size);
    }
    for (i = 0; i < n; i++) {
        if (!(toml_bare_key_char((unsigned char)layout[i]) && layout[i] != '-')) {
            break;
        }
    }
    if (n == 0 || n > 64 || i < n) {
        Text text = {error, size, 0};
        text_put(&text, "no shipped ");
        text_put(&text, names->shipped);
        text_put(&text, " named ");
        if (text.used + 1 < size) {
            python_str_repr_n(layout, n, 80, error + text.used, size - text.used);
            text.used += strlen(error + text.used);
        }
        text_put(&text, " (names are letters, digits and '_')");
        return ERROR_VALUE;
    }
    if (resources == NULL) {
        return layout_error(error, size, "no shipped %s named %r", names->shipped, layout);
    }
    path = malloc(strlen(resources) + n + 8);
    if (path == NULL) {
        return layout_error(error, size, "out of memory");
    }
    sprintf(path, "%s/%s.toml", resources, layout);
    if (regular_file(path) != 1) {
        free(path);
        return layout_error(error, size, "no shipped %s named %r", names->shipped, layout);
    }
    status = load_file(path, names, loads, out, error, size);
    free(path);
    return status;
}
