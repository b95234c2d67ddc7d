/* Forward-mode automatic differentiation: a dual number holds a value and its partial derivatives with
 * respect to DUAL_SIZE knowns (a Jacobian's columns), so one evaluation in dual arithmetic gives a whole
 * row of partial derivatives per result. Each operation is the chain rule of the operator or libm function
 * it replaces. The including file defines DUAL_SIZE, its number of knowns, before it includes this header
 * (one size per C file: TripodCoupling's Jacobian columns, PowertrainMounts' halfshaft jets). Header only
 * (static inline functions, no state), standard C99 that MSVC compiles (no complex arithmetic).
 *
 * A file that also evaluates its formulas for their values alone defines DUAL_OPTIONAL: each dual number then
 * says whether it carries partial derivatives (a known does, a constant does not), an operation on numbers
 * that carry none computes the value alone (its partial derivatives 0, set without arithmetic); the values are
 * those of the full evaluation bit for bit, and so are the partial derivatives of the numbers that carry them
 * (up to the sign of a zero that passed through constants alone). Without DUAL_OPTIONAL every number carries them. */
#ifndef LIB_DUAL_H
#define LIB_DUAL_H

#ifndef DUAL_SIZE
#error "define DUAL_SIZE, the number of partial derivatives, before including lib/dual.h"
#endif

#include <math.h>

#if defined(_MSC_VER) && !defined(__cplusplus) && !defined(inline)
#define inline __inline /* MSVC's C before C11 */
#endif

typedef struct {
    double v, d[DUAL_SIZE];
#ifdef DUAL_OPTIONAL
    int carries; /* 1: d holds partial derivatives; 0: d is 0 */
#endif
} Dual;

#ifdef DUAL_OPTIONAL
#define DUAL_CARRIES(a) ((a).carries)
#define DUAL_MARK(r, carrying) ((r).carries = (carrying))
#else
#define DUAL_CARRIES(a) 1
#define DUAL_MARK(r, carrying) ((void)0)
#endif

/* r's partial derivatives 0, for a result whose operands carry none */
static inline void dual_zero(Dual *r)
{
    int c;
    for (c = 0; c < DUAL_SIZE; c++) {
        r->d[c] = 0.0;
    }
}

/* r marked as ``carrying`` partial derivatives or not; 1 when it carries none (its partial derivatives then
 * set 0: the operation's value is all), 0 when the operation computes them (always without DUAL_OPTIONAL) */
static inline int dual_values_only(Dual *r, int carrying)
{
    DUAL_MARK(*r, carrying);
    if (carrying) {
        return 0;
    }
    dual_zero(r);
    return 1;
}

/* v with the partial derivatives ``slope`` times a's: f(a) with f(a.v) = v, f'(a.v) = slope */
static inline Dual dual_chain(Dual a, double v, double slope)
{
    Dual r;
    int c;
    r.v = v;
    if (dual_values_only(&r, DUAL_CARRIES(a))) {
        return r;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        r.d[c] = slope * a.d[c];
    }
    return r;
}

/* v with a's partial derivatives over ``denominator``: f(a) with f(a.v) = v, f'(a.v) = 1 / denominator,
 * rounded as a quotient */
static inline Dual dual_chain_over(Dual a, double v, double denominator)
{
    Dual r;
    int c;
    r.v = v;
    if (dual_values_only(&r, DUAL_CARRIES(a))) {
        return r;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        r.d[c] = a.d[c] / denominator;
    }
    return r;
}

/* a constant: no partial derivatives */
static inline Dual dual_constant(double v)
{
    Dual r;
    r.v = v;
    (void)dual_values_only(&r, 0);
    return r;
}

/* the known ``column`` at value v: its own partial derivative 1 */
static inline Dual dual_known(double v, int column)
{
    Dual r = dual_constant(v);
    DUAL_MARK(r, 1);
    r.d[column] = 1.0;
    return r;
}

static inline Dual dual_add(Dual a, Dual b)
{
    int c;
    a.v += b.v;
    if (dual_values_only(&a, DUAL_CARRIES(a) || DUAL_CARRIES(b))) {
        return a;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        a.d[c] += b.d[c];
    }
    return a;
}

static inline Dual dual_sub(Dual a, Dual b)
{
    int c;
    a.v -= b.v;
    if (dual_values_only(&a, DUAL_CARRIES(a) || DUAL_CARRIES(b))) {
        return a;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        a.d[c] -= b.d[c];
    }
    return a;
}

static inline Dual dual_mul(Dual a, Dual b)
{
    Dual r;
    int c;
    r.v = a.v * b.v;
    if (dual_values_only(&r, DUAL_CARRIES(a) || DUAL_CARRIES(b))) {
        return r;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        r.d[c] = a.d[c] * b.v + a.v * b.d[c];
    }
    return r;
}

static inline Dual dual_div(Dual a, Dual b)
{
    Dual r;
    int c;
    r.v = a.v / b.v;
    if (dual_values_only(&r, DUAL_CARRIES(a) || DUAL_CARRIES(b))) {
        return r;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        r.d[c] = (a.d[c] - r.v * b.d[c]) / b.v;
    }
    return r;
}

/* a times the constant s */
static inline Dual dual_scale(Dual a, double s)
{
    return dual_chain(a, s * a.v, s);
}

/* a plus the constant s */
static inline Dual dual_shift(Dual a, double s)
{
    a.v += s;
    return a;
}

/* -a, exactly: every sign flipped */
static inline Dual dual_neg(Dual a)
{
    int c;
    a.v = -a.v;
    for (c = 0; c < DUAL_SIZE; c++) {
        a.d[c] = -a.d[c];
    }
    return a;
}

/* a b + c d, the pattern of the cross products */
static inline Dual dual_mul2(Dual a, Dual b, Dual c, Dual d)
{
    return dual_add(dual_mul(a, b), dual_mul(c, d));
}

/* a b - c d */
static inline Dual dual_cross(Dual a, Dual b, Dual c, Dual d)
{
    return dual_sub(dual_mul(a, b), dual_mul(c, d));
}

/* The square root; where a is 0 (a norm of a vector that vanishes: a kink, whose directional derivative
 * |dv| is no linear map) its partial derivatives are taken 0, the smallest of the one-sided ones. */
static inline Dual dual_sqrt(Dual a)
{
    double v = sqrt(a.v);
    return dual_chain(a, v, v > 0.0 ? 0.5 / v : 0.0);
}

static inline Dual dual_sin(Dual a)
{
    return dual_chain(a, sin(a.v), cos(a.v));
}

static inline Dual dual_cos(Dual a)
{
    return dual_chain(a, cos(a.v), -sin(a.v));
}

static inline Dual dual_tan(Dual a)
{
    double c = cos(a.v);
    return dual_chain(a, tan(a.v), 1.0 / (c * c));
}

static inline Dual dual_asin(Dual a)
{
    return dual_chain(a, asin(a.v), 1.0 / sqrt(1.0 - a.v * a.v));
}

/* atan2(y, x): d = (x dy - y dx) / (x^2 + y^2) */
static inline Dual dual_atan2(Dual y, Dual x)
{
    Dual r;
    double norm = x.v * x.v + y.v * y.v;
    int c;
    r.v = atan2(y.v, x.v);
    if (dual_values_only(&r, DUAL_CARRIES(x) || DUAL_CARRIES(y))) {
        return r;
    }
    for (c = 0; c < DUAL_SIZE; c++) {
        r.d[c] = (x.v * y.d[c] - y.v * x.d[c]) / norm;
    }
    return r;
}

/* the partial derivatives of ``a`` into row ``row`` of the Jacobian ``partial`` (DUAL_SIZE columns) */
static inline void dual_row(double partial[], int row, Dual a)
{
    int c;
    for (c = 0; c < DUAL_SIZE; c++) {
        partial[row * DUAL_SIZE + c] = a.d[c];
    }
}

#endif
