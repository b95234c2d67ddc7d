/* Python's repr() of a float and math.fsum in C (python_numbers.c): shared by the native FMUs'
 * layer and their models. */
#ifndef PYTHON_NUMBERS_H
#define PYTHON_NUMBERS_H

#include <stddef.h>

#define FMU_PI 3.14159265358979323846 /* math.pi */

/* Python's math.fsum of ``count`` values into ``*sum``: NULL, or the text of the exception Python
 * raises ("intermediate overflow in fsum", "-inf + inf in fsum"). */
const char *python_fsum(const double values[], int count, double *sum);
/* The same of ``count`` values ``stride`` doubles apart from ``first`` (a field of an array of structs). */
const char *python_fsum_strided(const double *first, int count, size_t stride, double *sum);
/* Python's repr() of a float: shortest round-trip digits, "inf", "nan", "-0.0", "1e-05". */
void python_float_repr(double value, char *out, size_t size);

#endif
