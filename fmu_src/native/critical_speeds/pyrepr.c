/* Python's repr() of the values the rotor library's messages show: str (unicode_repr) and float
 * (float_repr). Every function writes at most ``size`` bytes, always terminated. */
#include "rotor.h"

#include <locale.h>
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
            snprintf(piece, sizeof piece, "\\x%02lx", code);
        } else if (code < 0x80 || printable(code)) {
            memcpy(piece, text + at, width);
            piece[width] = '\0';
        } else if (code < 0x100) {
            snprintf(piece, sizeof piece, "\\x%02lx", code);
        } else if (code < 0x10000) {
            snprintf(piece, sizeof piece, "\\u%04lx", code);
        } else {
            snprintf(piece, sizeof piece, "\\U%08lx", (unsigned long)code & 0x1FFFFFUL);
        }
        text_append(out, size, &used, piece, strlen(piece));
    }
    text_append(out, size, &used, &quote, 1);
}

void python_str_repr(const char *text, size_t max_chars, char *out, size_t size)
{
    python_str_repr_n(text, strlen(text), max_chars, out, size);
}

/* Whether the decimal digits[0..count) x 10^(exponent - count + 1) reads back as ``value``
 * (written without a decimal point, so that no locale matters). */
static int reads_back(const char *digits, int count, int exponent, double value)
{
    char text[64];
    snprintf(text, sizeof text, "%.*se%d", count, digits, exponent - count + 1);
    return strtod(text, NULL) == value;
}

/* Adds ``step`` (+1 or -1) to the last of ``count`` decimal digits, keeping ``count`` digits. */
static void step_digits(char *digits, int count, int *exponent, int step)
{
    int i = count - 1;
    while (i >= 0) {
        int d = digits[i] - '0' + step;
        if (d >= 0 && d <= 9) {
            digits[i] = (char)('0' + d);
            break;
        }
        digits[i] = step > 0 ? '0' : '9';
        i--;
    }
    if (i < 0) { /* 99..9 + 1 */
        digits[0] = '1';
        (*exponent)++;
    } else if (digits[0] == '0') { /* 10..0 - 1: one digit fewer, the last a 9 */
        memmove(digits, digits + 1, (size_t)count - 1);
        digits[count - 1] = '9';
        (*exponent)--;
    }
}

/* float_repr's digits: the fewest significant digits that read back as ``value`` (> 0, finite), the
 * nearer of two such. printf's rounding gives the nearer of the two neighbours at each precision;
 * where the doubles' spacing halves (powers of two) only the other may read back. */
static int shortest_repr_digits(double value, char digits[24], int *exponent)
{
    char text[48], point = *localeconv()->decimal_point;
    int precision, count = 0;
    for (precision = 1; precision <= 17; precision++) {
        const char *c;
        snprintf(text, sizeof text, "%.*e", precision - 1, value);
        for (count = 0, c = text; *c != 'e'; c++) {
            if (*c != point) {
                digits[count++] = *c;
            }
        }
        *exponent = atoi(c + 1);
        if (reads_back(digits, count, *exponent, value)) {
            return count;
        }
        if (precision < 17) {
            char other[24];
            int other_exponent = *exponent;
            double nearest;
            snprintf(text, sizeof text, "%.*se%d", count, digits, *exponent - count + 1);
            nearest = strtod(text, NULL);
            memcpy(other, digits, (size_t)count);
            step_digits(other, count, &other_exponent, nearest < value ? 1 : -1);
            if (reads_back(other, count, other_exponent, value)) {
                memcpy(digits, other, (size_t)count);
                *exponent = other_exponent;
                return count;
            }
        }
    }
    return count;
}

/* float_repr (repr of a Python float): "inf", "nan", "-0.0", "1e-05", "1e+16", "0.1". */
void pyrepr_float(double value, char *out, size_t size)
{
    char digits[24], text[64];
    int count, exponent, used = 0, i;
    if (isnan(value)) {
        snprintf(out, size, "nan");
        return;
    }
    if (isinf(value)) {
        snprintf(out, size, "%sinf", value < 0 ? "-" : "");
        return;
    }
    if (signbit(value)) {
        text[used++] = '-';
    }
    if (value == 0.0) {
        snprintf(out, size, "%s0.0", used ? "-" : "");
        return;
    }
    count = shortest_repr_digits(fabs(value), digits, &exponent);
    while (count > 1 && digits[count - 1] == '0') {
        count--;
    }
    if (exponent < -4 || exponent >= 16) {
        text[used++] = digits[0];
        if (count > 1) {
            text[used++] = '.';
            memcpy(text + used, digits + 1, (size_t)count - 1);
            used += count - 1;
        }
        used += snprintf(text + used, sizeof text - (size_t)used, "e%c%02d", exponent < 0 ? '-' : '+',
                         exponent < 0 ? -exponent : exponent);
    } else {
        int point_at = exponent + 1; /* digits before the point (<= 0: leading zeros after it) */
        if (point_at <= 0) {
            text[used++] = '0';
            text[used++] = '.';
            for (i = point_at; i < 0; i++) {
                text[used++] = '0';
            }
            memcpy(text + used, digits, (size_t)count);
            used += count;
        } else {
            for (i = 0; i < point_at; i++) {
                text[used++] = i < count ? digits[i] : '0';
            }
            text[used++] = '.';
            if (count <= point_at) {
                text[used++] = '0';
            }
            for (i = point_at; i < count; i++) {
                text[used++] = digits[i];
            }
        }
        text[used] = '\0';
    }
    snprintf(out, size, "%s", text);
}
