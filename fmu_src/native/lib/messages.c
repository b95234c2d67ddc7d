/* The layout messages: Python's repr() of the values read (as the loaded ones show) and the loader's
 * message format. */
#include "toml.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

void text_put_bytes(Text *text, const char *bytes, size_t count)
{
    text_append(text->out, text->size, &text->used, bytes, count);
}

void text_put(Text *text, const char *piece)
{
    text_put_bytes(text, piece, strlen(piece));
}

void text_put_str_repr(Text *text, const char *bytes, size_t count)
{
    if (text->size > 0 && text->used + 1 < text->size) {
        python_str_repr_n(bytes, count, 0, text->out + text->used, text->size - text->used);
        text->used += strlen(text->out + text->used);
    }
}

void text_put_float(Text *text, double value)
{
    char shown[40];
    python_float_repr(value, shown, sizeof shown);
    text_put(text, shown);
}

/* repr() of a scalar as Python shows the loaded one (str, int, float, bool). */
static void put_scalar_repr(Text *text, const Value *value)
{
    char shown[32];
    if (value->kind == V_STRING) {
        text_put_str_repr(text, value->text, value->length);
    } else if (value->kind == V_INTEGER) {
        snprintf(shown, sizeof shown, "%lld", value->integer);
        text_put(text, shown);
    } else if (value->kind == V_FLOAT) {
        text_put_float(text, value->number);
    } else {
        text_put(text, value->integer ? "True" : "False");
    }
}

/* repr() of a value as Python shows the loaded one, lists and dicts too: walked with a stack of the
 * open containers (no recursion; the reader makes none deeper than TREE_DEPTH). */
void text_put_repr(Text *text, const Value *value)
{
    const Value *open[TREE_DEPTH + 2];
    const Item *next[TREE_DEPTH + 2];
    int top = -1;
    for (;;) {
        if ((value->kind == V_ARRAY || value->kind == V_TABLE) && top + 1 < TREE_DEPTH + 2) {
            text_put(text, value->kind == V_ARRAY ? "[" : "{");
            open[++top] = value;
            next[top] = value->first;
        } else if (value->kind == V_ARRAY || value->kind == V_TABLE) {
            text_put(text, "...");
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
                text_put(text, open[top]->kind == V_ARRAY ? "]" : "}");
                top--;
                continue;
            }
            if (item != open[top]->first) {
                text_put(text, ", ");
            }
            if (open[top]->kind == V_TABLE) {
                text_put_str_repr(text, item->key, item->key_length);
                text_put(text, ": ");
            }
            next[top] = item->next;
            value = item->value;
            break;
        }
    }
}

/* The message into ``error``: ``format`` with %s (C string), %d (int), %v (a Value's repr), %g (a
 * double's repr), %r (a C string's repr). Returns ERROR_VALUE: the loader raises ValueError only. */
ErrorKind layout_error(char *error, size_t size, const char *format, ...)
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
            text_put_bytes(&text, c, 1);
            continue;
        }
        switch (*++c) {
        case 's':
            text_put(&text, va_arg(args, const char *));
            break;
        case 'd':
            snprintf(shown, sizeof shown, "%d", va_arg(args, int));
            text_put(&text, shown);
            break;
        case 'v':
            text_put_repr(&text, va_arg(args, const Value *));
            break;
        case 'g':
            text_put_float(&text, va_arg(args, double));
            break;
        case 'r':
            s = va_arg(args, const char *);
            text_put_str_repr(&text, s, strlen(s));
            break;
        default:
            text_put_bytes(&text, c, 1);
            break;
        }
    }
    va_end(args);
    return ERROR_VALUE;
}
