/* Python's repr() of the strings the rotor library's messages show (unicode_repr; a float's is
 * python_float_repr of the shared python_numbers.c). Every function writes at most ``size`` bytes,
 * always terminated. */
#include "toml.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void text_append(char *out, size_t size, size_t *used, const char *bytes, size_t count)
{
    if (size == 0 || *used + 1 >= size) {
        return;
    }
    if (count > size - 1 - *used) {
        count = size - 1 - *used;
    }
    memcpy(out + *used, bytes, count);
    *used += count;
    out[*used] = '\0';
}

/* The code point at ``text`` (``left`` bytes) and its length in ``*width``; -1 for a byte that starts
 * no valid UTF-8 sequence (width 1). */
static long next_code_point(const unsigned char *text, size_t left, size_t *width)
{
    unsigned char lead = text[0];
    size_t follow, k;
    long code;
    *width = 1;
    if (lead < 0x80) {
        return lead;
    }
    if (lead >= 0xC2 && lead <= 0xDF) {
        follow = 1;
        code = lead & 0x1F;
    } else if (lead >= 0xE0 && lead <= 0xEF) {
        follow = 2;
        code = lead & 0x0F;
    } else if (lead >= 0xF0 && lead <= 0xF4) {
        follow = 3;
        code = lead & 0x07;
    } else {
        return -1;
    }
    if (left <= follow) {
        return -1;
    }
    for (k = 1; k <= follow; k++) {
        if ((text[k] & 0xC0) != 0x80) {
            return -1;
        }
        code = (code << 6) | (text[k] & 0x3F);
    }
    if ((follow == 2 && code < 0x800) || (follow == 3 && (code < 0x10000 || code > 0x10FFFF)) ||
        (code >= 0xD800 && code <= 0xDFFF)) {
        return -1;
    }
    *width = follow + 1;
    return code;
}

/* str.isprintable for one non-ASCII code point: false for the control, format, separator, private-use
 * and non-characters (unassigned code points count as printable here). */
static int printable(long code)
{
    static const long hidden[][2] = {
        {0x80, 0xA0},       {0xAD, 0xAD},       {0x600, 0x605},     {0x61C, 0x61C},     {0x6DD, 0x6DD},
        {0x70F, 0x70F},     {0x890, 0x891},     {0x8E2, 0x8E2},     {0x1680, 0x1680},   {0x180E, 0x180E},
        {0x2000, 0x200F},   {0x2028, 0x202F},   {0x205F, 0x206F},   {0x3000, 0x3000},   {0xD800, 0xF8FF},
        {0xFDD0, 0xFDEF},   {0xFEFF, 0xFEFF},   {0xFFF0, 0xFFFB},   {0x110BD, 0x110BD}, {0x110CD, 0x110CD},
        {0x13430, 0x1343F}, {0x1BCA0, 0x1BCA3}, {0x1D173, 0x1D17A}, {0xE0000, 0xE00FF}, {0xE01F0, 0x10FFFF},
    };
    size_t i;
    if ((code & 0xFFFE) == 0xFFFE) {
        return 0;
    }
    for (i = 0; i < sizeof hidden / sizeof hidden[0]; i++) {
        if (code >= hidden[i][0] && code <= hidden[i][1]) {
            return 0;
        }
    }
    return 1;
}

/* unicode_repr: quotes, then every code point as itself or escaped. A byte that is no UTF-8 shows as
 * the surrogate Python's file system decoding gives it ('\udcNN'). */
void python_str_repr_n(const char *text, size_t length, size_t max_chars, char *out, size_t size)
{
    const unsigned char *bytes = (const unsigned char *)text;
    size_t used = 0;
    size_t at, width, end = 0, chars = 0;
    int single = 0, double_ = 0;
    char quote, piece[16];
    if (size > 0) {
        out[0] = '\0';
    }
    /* the bytes of the first max_chars code points */
    while (end < length && (max_chars == 0 || chars < max_chars)) {
        next_code_point(bytes + end, length - end, &width);
        single |= bytes[end] == '\'';
        double_ |= bytes[end] == '"';
        end += width;
        chars++;
    }
    quote = single && !double_ ? '"' : '\'';
    text_append(out, size, &used, &quote, 1);
    for (at = 0; at < end; at += width) {
        long code = next_code_point(bytes + at, end - at, &width);
        if (code < 0) {
            snprintf(piece, sizeof piece, "\\udc%02x", bytes[at]);
        } else if (code == quote || code == '\\') {
            piece[0] = '\\';
            piece[1] = (char)code;
            piece[2] = '\0';
        } else if (code == '\t' || code == '\n' || code == '\r') {
            snprintf(piece, sizeof piece, "\\%c", code == '\t' ? 't' : code == '\n' ? 'n' : 'r');
        } else if (code < 0x20 || code == 0x7F) {
            snprintf(piece, sizeof piece, "\\x%02x", (unsigned int)code);
        } else if (code < 0x80 || printable(code)) {
            memcpy(piece, text + at, width);
            piece[width] = '\0';
        } else if (code < 0x100) {
            snprintf(piece, sizeof piece, "\\x%02x", (unsigned int)code);
        } else if (code < 0x10000) {
            snprintf(piece, sizeof piece, "\\u%04x", (unsigned int)code);
        } else {
            snprintf(piece, sizeof piece, "\\U%08x", (unsigned int)(code & 0x1FFFFFL));
        }
        text_append(out, size, &used, piece, strlen(piece));
    }
    text_append(out, size, &used, &quote, 1);
}

void python_str_repr(const char *text, size_t max_chars, char *out, size_t size)
{
    python_str_repr_n(text, strlen(text), max_chars, out, size);
}
