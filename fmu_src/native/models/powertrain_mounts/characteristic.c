/* A mount's force-deflection characteristic along one axis (port of driveline/mounts/characteristic.py):
 * F(d) = k d + k_s [rho(d - g) - rho(-d - g)] (C1) with the C2 ramp rho of blend length w (C2), its tangent
 * rate, its energy and the mean of F over a step's deflections (three-point Gauss-Legendre on each piece). */
#include "mounts.h"

#include <math.h>

/* rho(x) of equation (C2) (characteristic.ramp: the cubic's piece evaluated within its range only; at x <= 0
 * its 0 / w^2 - 0 / (2 w^3) is +0, unless w^3 underflows; powers as products, the same in both cores) */
static double ramp(double x, double w)
{
    double u = fmin(fmax(x, 0.0), w);
    if (x <= 0.0 && w * w * w > 0.0) {
        return 0.0;
    }
    return x >= w ? x - 0.5 * w : u * u * u / (w * w) - u * u * (u * u) / (2.0 * (w * w * w));
}

/* rho'(x) (characteristic.ramp_slope) */
static double ramp_slope(double x, double w)
{
    double u = fmin(fmax(x, 0.0), w) / w;
    return u * u * (3.0 - 2.0 * u);
}

/* P(x), the integral of rho from 0 (characteristic.ramp_integral) */
static double ramp_integral(double x, double w)
{
    double u = fmin(fmax(x, 0.0), w), beyond = fmax(x - w, 0.0), fourth = u * u * (u * u);
    return fourth / (4.0 * w * w) - fourth * u / (10.0 * (w * w * w)) + beyond * (0.5 * beyond + 0.5 * w);
}

double characteristic_force(const Mount *m, int k, double d)
{
    double w = m->stop_blend;
    if (m->stop_rate[k] == 0.0) { /* the linear k d (the same number, and no 0 * inf far out) */
        return m->stiffness[k] * d;
    }
    return m->stiffness[k] * d + m->stop_rate[k] * (ramp(d - m->gap[k], w) - ramp(-d - m->gap[k], w));
}

double characteristic_tangent(const Mount *m, int k, double d)
{
    double w = m->stop_blend;
    return m->stiffness[k] + m->stop_rate[k] * (ramp_slope(d - m->gap[k], w) + ramp_slope(-d - m->gap[k], w));
}

double characteristic_energy(const Mount *m, int k, double d)
{
    double w = m->stop_blend;
    return 0.5 * m->stiffness[k] * d * d +
           m->stop_rate[k] * (ramp_integral(d - m->gap[k], w) + ramp_integral(-d - m->gap[k], w));
}

/* characteristic._ramp_value: rho(x) of one number (Python's scalar arithmetic) */
static double ramp_value(double x, double w)
{
    if (x <= 0.0) {
        return 0.0;
    }
    if (x >= w) {
        return x - 0.5 * w;
    }
    return x * x * x / (w * w) - x * x * (x * x) / (2.0 * (w * w * w));
}

/* characteristic._mean_ramp: the mean of rho over [a, b] (a != b), piecewise Gauss-Legendre (exact) */
static double mean_ramp(double a, double b, double w)
{
    const double root = sqrt(15.0) / 10.0;
    const double nodes[3] = {0.5 - root, 0.5, 0.5 + root}, weights[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
    double low = fmin(a, b), high = fmax(a, b), cuts[4], total = 0.0;
    int count = 0, i, j;
    if (high <= 0.0) {
        return 0.0;
    }
    cuts[count++] = low;
    if (low < 0.0 && 0.0 < high) {
        cuts[count++] = 0.0;
    }
    if (low < w && w < high) {
        cuts[count++] = w;
    }
    cuts[count++] = high;
    for (i = 0; i + 1 < count; i++) {
        double length = cuts[i + 1] - cuts[i], sum = 0.0;
        for (j = 0; j < 3; j++) { /* Python's sum() of the three products, from 0 */
            sum += weights[j] * ramp_value(cuts[i] + length * nodes[j], w);
        }
        total += length * sum;
    }
    return total / (high - low);
}

void characteristic_mean_force(const Mount *m, const double d0[3], const double d1[3], double mean[3],
                               double slope[3])
{
    int k;
    for (k = 0; k < 3; k++) {
        double gap = m->gap[k], end_force;
        mean[k] = 0.5 * m->stiffness[k] * (d0[k] + d1[k]);
        slope[k] = 0.5 * m->stiffness[k];
        if (m->stop_rate[k] == 0.0 || fmax(fabs(d0[k]), fabs(d1[k])) <= gap) {
            continue;
        }
        end_force = characteristic_force(m, k, d1[k]);
        if (d0[k] == d1[k]) {
            mean[k] = end_force;
        } else {
            mean[k] += m->stop_rate[k] * (mean_ramp(d0[k] - gap, d1[k] - gap, m->stop_blend) -
                                          mean_ramp(-d0[k] - gap, -d1[k] - gap, m->stop_blend));
        }
        if (fabs(d1[k] - d0[k]) <= 1e-6 * m->stop_blend) {
            slope[k] = 0.5 * characteristic_tangent(m, k, d1[k]);
        } else {
            slope[k] = (end_force - mean[k]) / (d1[k] - d0[k]);
        }
    }
}
