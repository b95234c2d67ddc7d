/* Complex numbers as a pair of doubles, with the arithmetic the rotor library needs: standard C99
 * that every compiler accepts (MSVC has no C99 complex arithmetic). Each operation rounds as the
 * C99 operator or libm function it replaces did on the reference platform (gcc 12 and glibc on
 * x86_64), so the results stay those of numpy's complex128 ports bit for bit there and become the
 * same on every platform:
 *   a real times a complex and a complex over a real: each part on its own;
 *   a product: the textbook formula (C99 Annex G's recovery of infinities from NaN is left out:
 *   finite operands give the same result);
 *   a quotient: Smith's method with the scaling against overflow and underflow of libgcc's
 *   __divdc3, and its recovery of infinities and zeros;
 *   the modulus: hypot; the square root: the principal root by the half-angle identities with
 *   glibc's scaling and special values; e^(i phi): cos and sin of phi.
 * Header only (static inline functions), included by the modules that compute with it. */
#ifndef CPLX_H
#define CPLX_H

#include <float.h>
#include <math.h>

#if defined(_MSC_VER) && !defined(__cplusplus) && !defined(inline)
#define inline __inline /* MSVC's C before C11 */
#endif

typedef struct {
    double re, im;
} cplx;

static inline cplx cplx_make(double re, double im)
{
    cplx z;
    z.re = re;
    z.im = im;
    return z;
}

/* a real as a complex: im = +0 */
static inline cplx cplx_real(double x)
{
    return cplx_make(x, 0.0);
}

static inline int cplx_is_zero(cplx z)
{
    return z.re == 0.0 && z.im == 0.0;
}

static inline cplx cplx_add(cplx a, cplx b)
{
    return cplx_make(a.re + b.re, a.im + b.im);
}

static inline cplx cplx_sub(cplx a, cplx b)
{
    return cplx_make(a.re - b.re, a.im - b.im);
}

static inline cplx cplx_neg(cplx a)
{
    return cplx_make(-a.re, -a.im);
}

static inline cplx cplx_conj(cplx a)
{
    return cplx_make(a.re, -a.im);
}

/* x a for a real x */
static inline cplx cplx_scale(double x, cplx a)
{
    return cplx_make(x * a.re, x * a.im);
}

/* a / x for a real x */
static inline cplx cplx_div_real(cplx a, double x)
{
    return cplx_make(a.re / x, a.im / x);
}

/* a b */
static inline cplx cplx_mul(cplx a, cplx b)
{
    return cplx_make(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}

/* conj(a) b */
static inline cplx cplx_mul_conj(cplx a, cplx b)
{
    return cplx_make(a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
}

/* |re| + |im| (LAPACK's cabs1) */
static inline double cplx_abs1(cplx z)
{
    return fabs(z.re) + fabs(z.im);
}

static inline double cplx_abs(cplx z)
{
    return hypot(z.re, z.im);
}

/* e^(i phi) */
static inline cplx cplx_expi(double phi)
{
    if (!isfinite(phi)) {
        return cplx_make(NAN, NAN);
    }
    if (fabs(phi) > DBL_MIN) {
        return cplx_make(cos(phi), sin(phi));
    }
    return cplx_make(1.0, phi);
}

/* a / b: Smith's method on operands brought into range by powers of two (exact scalings) */
static inline cplx cplx_div(cplx numerator, cplx denominator)
{
    const double big = DBL_MAX / 2.0, small = DBL_MIN, tiny = DBL_EPSILON, up = 1.0 / DBL_EPSILON;
    const double large = big * tiny;
    double a = numerator.re, b = numerator.im, c = denominator.re, d = denominator.im;
    double ratio, scale, x, y;
    int swap = fabs(c) < fabs(d); /* divide by the larger part of the denominator */
    double p = swap ? d : c;      /* the larger part */
    if (fabs(p) >= big) {
        a /= 2.0;
        b /= 2.0;
        c /= 2.0;
        d /= 2.0;
        p /= 2.0;
    }
    if (fabs(p) < tiny ||
        (fabs(a) < small && fabs(b) < large && fabs(p) < large) ||
        (fabs(b) < small && fabs(a) < large && fabs(p) < large)) {
        a *= up;
        b *= up;
        c *= up;
        d *= up;
    }
    if (swap) {
        ratio = c / d;
        scale = c * ratio + d;
        if (fabs(ratio) > small) {
            x = (a * ratio + b) / scale;
            y = (b * ratio - a) / scale;
        } else {
            x = (c * (a / d) + b) / scale;
            y = (c * (b / d) - a) / scale;
        }
    } else {
        ratio = d / c;
        scale = d * ratio + c;
        if (fabs(ratio) > small) {
            x = (b * ratio + a) / scale;
            y = (b - a * ratio) / scale;
        } else {
            x = (d * (b / c) + a) / scale;
            y = (b - d * (a / c)) / scale;
        }
    }
    if (isnan(x) && isnan(y)) { /* infinities and zeros that came out as NaN */
        if (c == 0.0 && d == 0.0 && (!isnan(a) || !isnan(b))) {
            x = copysign(INFINITY, c) * a;
            y = copysign(INFINITY, c) * b;
        } else if ((isinf(a) || isinf(b)) && isfinite(c) && isfinite(d)) {
            a = copysign(isinf(a) ? 1.0 : 0.0, a);
            b = copysign(isinf(b) ? 1.0 : 0.0, b);
            x = INFINITY * (a * c + b * d);
            y = INFINITY * (b * c - a * d);
        } else if ((isinf(c) || isinf(d)) && isfinite(a) && isfinite(b)) {
            c = copysign(isinf(c) ? 1.0 : 0.0, c);
            d = copysign(isinf(d) ? 1.0 : 0.0, d);
            x = 0.0 * (a * c + b * d);
            y = 0.0 * (b * c - a * d);
        }
    }
    return cplx_make(x, y);
}

/* The principal square root (branch cut along the negative real axis, the sign of im kept) */
static inline cplx cplx_sqrt(cplx z)
{
    double re = z.re, im = z.im, r, s, d;
    int scale = 0;
    if (isinf(im)) {
        return cplx_make(HUGE_VAL, im);
    }
    if (isinf(re)) {
        if (re < 0.0) {
            return cplx_make(isnan(im) ? NAN : 0.0, copysign(HUGE_VAL, im));
        }
        return cplx_make(re, isnan(im) ? NAN : copysign(0.0, im));
    }
    if (isnan(re) || isnan(im)) {
        return cplx_make(NAN, NAN);
    }
    if (im == 0.0) {
        if (re < 0.0) {
            return cplx_make(0.0, copysign(sqrt(-re), im));
        }
        return cplx_make(fabs(sqrt(re)), copysign(0.0, im));
    }
    if (re == 0.0) {
        r = fabs(im) >= 2.0 * DBL_MIN ? sqrt(0.5 * fabs(im)) : 0.5 * sqrt(2.0 * fabs(im));
        return cplx_make(r, copysign(r, im));
    }
    if (fabs(re) > DBL_MAX / 4.0) {
        scale = 1;
        re = ldexp(re, -2);
        im = ldexp(im, -2);
    } else if (fabs(im) > DBL_MAX / 4.0) {
        scale = 1;
        re = fabs(re) >= 4.0 * DBL_MIN ? ldexp(re, -2) : 0.0;
        im = ldexp(im, -2);
    } else if (fabs(re) < 2.0 * DBL_MIN && fabs(im) < 2.0 * DBL_MIN) {
        scale = -((DBL_MANT_DIG + 1) / 2);
        re = ldexp(re, -2 * scale);
        im = ldexp(im, -2 * scale);
    }
    d = hypot(re, im);
    if (re > 0.0) { /* 2 Re(root) Im(root) = im: no cancellation in d +- re */
        r = sqrt(0.5 * (d + re));
        if (scale == 1 && fabs(im) < 1.0) {
            s = im / r;
            r = ldexp(r, scale);
            scale = 0;
        } else {
            s = 0.5 * (im / r);
        }
    } else {
        s = sqrt(0.5 * (d - re));
        if (scale == 1 && fabs(im) < 1.0) {
            r = fabs(im / s);
            s = ldexp(s, scale);
            scale = 0;
        } else {
            r = fabs(0.5 * (im / s));
        }
    }
    if (scale) {
        r = ldexp(r, scale);
        s = ldexp(s, scale);
    }
    return cplx_make(r, copysign(s, z.im));
}

#endif
