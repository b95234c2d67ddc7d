/* The rotor library's complex type (models/critical_speeds/cplx.h) against the C99 complex arithmetic it
 * replaces, on the host that compiles this: every operation, on random operands of every
 * magnitude and on the special values (signed zeros, infinities, NaN, subnormals, the extremes).
 *
 * Usage: native_complex_check COUNT; prints the mismatches of each operation, exits 0 when none. */
#include <complex.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cplx.h"

static uint64_t state = 88172645463325252u;

static uint64_t next(void)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

/* a special value, a moderate number, or any bit pattern */
static double operand(void)
{
    static const double special[] = {0.0, -0.0, 1.0, -1.0, 2.0, 0.5, DBL_MIN, DBL_MAX, 4.9e-324, DBL_EPSILON,
                                     1e-300, 1e300};
    uint64_t kind = next() % 100, bits;
    double x;
    if (kind < 6) {
        return special[next() % (sizeof special / sizeof special[0])];
    }
    if (kind < 8) {
        return kind == 6 ? (next() & 1 ? INFINITY : -INFINITY) : NAN;
    }
    if (kind < 40) {
        x = (double)(next() >> 11) / 9007199254740992.0 + 0.5;
        return (next() & 1 ? -x : x) * ldexp(1.0, (int)(next() % 40) - 20);
    }
    bits = next();
    memcpy(&x, &bits, sizeof x);
    return x;
}

static int same(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0 || (isnan(a) && isnan(b));
}

static int differ(double complex expected, cplx got)
{
    return !same(creal(expected), got.re) || !same(cimag(expected), got.im);
}

int main(int argc, char **argv)
{
    enum { DIV, SQRT, EXPI, ABS, MUL, SCALE, DIV_REAL, ADD_REAL, KINDS };
    static const char *const names[KINDS] = {"div", "sqrt", "expi", "abs", "mul", "scale", "div_real", "add_real"};
    long count = argc > 1 ? atol(argv[1]) : 100000, mismatches[KINDS] = {0}, total = 0;
    for (long k = 0; k < count; k++) {
        double a = operand(), b = operand(), c = operand(), d = operand();
        double complex z = CMPLX(a, b), w = CMPLX(c, d);
        cplx Z = cplx_make(a, b), W = cplx_make(c, d);
        mismatches[DIV] += differ(z / w, cplx_div(Z, W));
        mismatches[SQRT] += differ(csqrt(z), cplx_sqrt(Z));
        mismatches[EXPI] += differ(cexp(CMPLX(0.0, c)), cplx_expi(c));
        mismatches[ABS] += !same(cabs(z), cplx_abs(Z));
        /* C99's product recovers infinities from NaN (Annex G), which cplx_mul leaves out */
        mismatches[MUL] += isfinite(a) && isfinite(b) && isfinite(c) && isfinite(d) && differ(z * w, cplx_mul(Z, W));
        mismatches[SCALE] += differ(c * z, cplx_scale(c, Z)) + differ(z * c, cplx_scale(c, Z));
        mismatches[DIV_REAL] += differ(z / c, cplx_div_real(Z, c));
        mismatches[ADD_REAL] += differ(z + c, cplx_make(a + c, b));
    }
    for (int kind = 0; kind < KINDS; kind++) {
        printf("%s %ld\n", names[kind], mismatches[kind]);
        total += mismatches[kind];
    }
    return total != 0;
}
