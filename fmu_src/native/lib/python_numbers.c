/* Python's repr() of a float and math.fsum, for the native FMUs' messages and for sums that must
 * equal the Python core's to the last bit. */
#include "python_numbers.h"

#include <locale.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
void python_float_repr(double value, char *out, size_t size)
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

/* Python's math.fsum: exact partial sums (Shewchuk), rounded once; the text of Python's exception
 * when a partial sum of finite values overflows (OverflowError) or +inf and -inf meet
 * (ValueError), else NULL with the sum in ``*sum``. Each value adds at most one partial: exact for
 * up to FSUM_VALUES values (the Real outputs, a layout's segments). */
#define FSUM_VALUES 256
ErrorKind python_fsum(const double values[], int count, double *sum, const char **message)
{
    return python_fsum_strided(values, count, 1, sum, message);
}

ErrorKind python_fsum_strided(const double *first, int count, size_t stride, double *sum, const char **message)
{
    double partials[FSUM_VALUES], special = 0.0, infinities = 0.0, high = 0.0, low = 0.0, x, y;
    int used = 0, i, j;
    for (i = 0; i < count; i++) {
        double original = first[(size_t)i * stride];
        int kept = 0;
        x = original;
        for (j = 0; j < used; j++) {
            y = partials[j];
            if (fabs(x) < fabs(y)) {
                double swap = x;
                x = y;
                y = swap;
            }
            high = x + y;
            low = y - (high - x);
            if (low != 0.0) {
                partials[kept++] = low;
            }
            x = high;
        }
        used = kept;
        if (x != 0.0) {
            if (!isfinite(x)) {
                if (isfinite(original)) {
                    *message = "intermediate overflow in fsum";
                    return ERROR_OVERFLOW;
                }
                if (isinf(original)) {
                    infinities += original;
                }
                special += original;
                used = 0;
            } else if (used < (int)(sizeof partials / sizeof partials[0])) {
                partials[used++] = x;
            }
        }
    }
    if (special != 0.0 || isnan(special)) {
        if (isnan(infinities)) {
            *message = "-inf + inf in fsum";
            return ERROR_VALUE;
        }
        *sum = special;
        return ERROR_NONE;
    }
    high = 0.0;
    if (used > 0) { /* add the partials from the top until the sum is inexact, then round half even */
        high = partials[--used];
        while (used > 0) {
            x = high;
            y = partials[--used];
            high = x + y;
            low = y - (high - x);
            if (low != 0.0) {
                break;
            }
        }
        if (used > 0 && ((low < 0.0 && partials[used - 1] < 0.0) || (low > 0.0 && partials[used - 1] > 0.0))) {
            y = low * 2.0;
            x = high + y;
            if (y == x - high) {
                high = x;
            }
        }
    }
    *sum = high;
    return ERROR_NONE;
}

void python_format_g(double value, int digits, char *out, size_t size)
{
    if (isnan(value)) {
        snprintf(out, size, "nan");
    } else if (isinf(value)) {
        snprintf(out, size, value > 0 ? "inf" : "-inf");
    } else {
        snprintf(out, size, "%.*g", digits, value);
    }
}
