/* The halfshafts on the moving powertrain (port of driveline/halfshaft/geometry.py, shaft_geometry and
 * design_wheel, and driveline/mounts/halfshafts.py): each inboard joint's bend angle, bend-plane angle and
 * plunge with their rates from the powertrain's motion, with their exact partial derivatives.
 *
 * The geometry is evaluated once in dual numbers (lib/dual.h): each quantity carries its partial derivatives
 * by the wheel centre in the housing frame and its rates, (a, a', a''), nine numbers; a = F^T (W - O - T(W) q),
 * a' = -F^T T(W) q', a'' = -F^T T(W) q'' turn them into derivatives by (q, q', q''). The values are those of
 * the Python core's operations, in its order. Without ``partial`` (a step's outputs) the knowns enter as
 * constants, and the same operations give the values alone.
 */
#include <math.h>

#include "mounts.h"

#define DUAL_SIZE HALFSHAFT_JET
#define DUAL_OPTIONAL /* a step's outputs take the values alone */
#include "lib/dual.h"

/* sqrt, its derivative a' / (2 sqrt a) taken 0 at 0 (a straight shaft: rho's one-sided slope, no bend plane) */
static Dual root(Dual a)
{
    double v = sqrt(a.v);
    return v > 0.0 ? dual_chain_over(a, v, 2.0 * v) : dual_constant(v);
}

/* the known ``column`` at v, a constant when no partial derivatives are asked for */
static Dual known(double v, int column, const void *partial)
{
    return partial != NULL ? dual_known(v, column) : dual_constant(v);
}

/* atan2, its derivative taken 0 at the origin */
static Dual angle(Dual y, Dual x)
{
    return x.v * x.v + y.v * y.v > 0.0 ? dual_atan2(y, x) : dual_constant(atan2(y.v, x.v));
}

/* mounts/halfshafts.Halfshaft.of with geometry.design_wheel: W = O + F (-L sin beta cos psi, -L sin beta sin psi,
 * plunge + L cos beta), T(W) = [I, -(W - c)x] */
void halfshaft_place(Halfshaft *shaft, const double *frame, const double centre[3], const double gravity[3],
                     double length, double beta, double psi, double plunge)
{
    double rho = length * sin(beta), h = length * cos(beta), local[3], r[3];
    int i, k;
    local[0] = -rho * cos(psi);
    local[1] = -rho * sin(psi);
    local[2] = plunge + h;
    for (i = 0; i < 3; i++) {
        double sum = 0.0;
        for (k = 0; k < 3; k++) {
            sum += frame[3 * i + k] * local[k];
        }
        shaft->wheel[i] = centre[i] + sum;
        shaft->centre[i] = centre[i];
        r[i] = shaft->wheel[i] - gravity[i];
        for (k = 0; k < 3; k++) {
            shaft->frame[i][k] = frame[3 * i + k];
            shaft->wheel_map[i][k] = i == k ? 1.0 : 0.0;
        }
    }
    shaft->wheel_map[0][3] = 0.0, shaft->wheel_map[0][4] = r[2], shaft->wheel_map[0][5] = -r[1];
    shaft->wheel_map[1][3] = -r[2], shaft->wheel_map[1][4] = 0.0, shaft->wheel_map[1][5] = r[0];
    shaft->wheel_map[2][3] = r[1], shaft->wheel_map[2][4] = -r[0], shaft->wheel_map[2][5] = 0.0;
    shaft->length = length;
    shaft->design[0] = beta, shaft->design[3] = psi, shaft->design[6] = plunge;
    shaft->design[1] = shaft->design[2] = shaft->design[4] = shaft->design[5] = shaft->design[7] =
        shaft->design[8] = 0.0;
}

/* F^T x for x = s (order 0: the wheel from the moved point), -T(W) q' (1) or -T(W) q'' (2) */
static void in_housing(const Halfshaft *shaft, const double motion[6], int order, double out[3])
{
    double moved[3], s[3];
    int i, k;
    for (i = 0; i < 3; i++) {
        double sum = 0.0;
        for (k = 0; k < 6; k++) {
            sum += shaft->wheel_map[i][k] * motion[k];
        }
        moved[i] = sum;
    }
    for (i = 0; i < 3; i++) {
        s[i] = order == 0 ? shaft->wheel[i] - (shaft->centre[i] + moved[i]) : -moved[i];
    }
    for (i = 0; i < 3; i++) {
        out[i] = shaft->frame[0][i] * s[0] + shaft->frame[1][i] * s[1] + shaft->frame[2][i] * s[2];
    }
}

int halfshaft_geometry(const Halfshaft *shaft, const double q[6], const double velocity[6],
                       const double acceleration[6], double values[HALFSHAFT_VALUES],
                       double partial[HALFSHAFT_VALUES][HALFSHAFT_MOTION], double *reach)
{
    double a[3][3], length2 = shaft->length * shaft->length;
    Dual ax, ay, az, a1[3], a2[3], rho2, rho, h, er[2], radial, tangential, radial_acc, tangential_acc, psi,
        psi_dot, psi_ddot, rho_ddot, beta_ddot, h_dot, h_ddot, found[HALFSHAFT_VALUES];
    int i, j, k;
    in_housing(shaft, q, 0, a[0]);
    in_housing(shaft, velocity, 1, a[1]);
    in_housing(shaft, acceleration, 2, a[2]);
    ax = known(a[0][0], 0, partial), ay = known(a[0][1], 1, partial), az = known(a[0][2], 2, partial);
    for (k = 0; k < 3; k++) {
        a1[k] = known(a[1][k], 3 + k, partial);
        a2[k] = known(a[2][k], 6 + k, partial);
    }
    rho2 = dual_add(dual_mul(ax, ax), dual_mul(ay, ay));
    if (!(rho2.v < length2)) {
        *reach = sqrt(rho2.v);
        return 0;
    }
    rho = root(rho2);
    h = root(dual_sub(dual_constant(length2), rho2));
    if (rho.v > 0.0) {
        er[0] = dual_div(ax, rho), er[1] = dual_div(ay, rho);
    } else {
        er[0] = dual_constant(-1.0), er[1] = dual_constant(0.0);
    }
    radial = dual_add(dual_mul(er[0], a1[0]), dual_mul(er[1], a1[1]));
    tangential = dual_sub(dual_mul(er[0], a1[1]), dual_mul(er[1], a1[0]));
    radial_acc = dual_add(dual_mul(er[0], a2[0]), dual_mul(er[1], a2[1]));
    tangential_acc = dual_sub(dual_mul(er[0], a2[1]), dual_mul(er[1], a2[0]));
    psi = angle(dual_neg(ay), dual_neg(ax));
    if (rho.v > 0.0) {
        psi_dot = dual_div(tangential, rho);
        rho_ddot = dual_add(radial_acc, dual_mul(dual_mul(rho, psi_dot), psi_dot));
        psi_ddot = dual_div(dual_sub(tangential_acc, dual_mul(dual_mul(dual_constant(2.0), radial), psi_dot)), rho);
    } else {
        psi_dot = psi_ddot = dual_constant(0.0);
        rho_ddot = radial_acc;
    }
    h_dot = dual_div(dual_mul(dual_neg(rho), radial), h);
    beta_ddot = dual_div(dual_sub(dual_mul(rho_ddot, h), dual_mul(radial, h_dot)), dual_mul(h, h));
    h_ddot = dual_neg(dual_div(
        dual_add(dual_add(dual_mul(h_dot, h_dot), dual_mul(rho, rho_ddot)), dual_mul(radial, radial)), h));
    found[0] = angle(rho, h);
    found[1] = dual_div(radial, h);
    found[2] = beta_ddot;
    found[3] = psi, found[4] = psi_dot, found[5] = psi_ddot;
    found[6] = dual_sub(az, h);
    found[7] = dual_sub(a1[2], h_dot);
    found[8] = dual_sub(a2[2], h_ddot);
    for (j = 0; j < HALFSHAFT_VALUES; j++) {
        values[j] = found[j].v;
        if (partial == NULL) {
            continue;
        }
        for (i = 0; i < 3; i++) { /* d/d(motion of order i) = d/da_i . (-F^T T(W)) */
            for (k = 0; k < 6; k++) {
                double sum = 0.0;
                int m;
                for (m = 0; m < 3; m++) {
                    double row = shaft->frame[0][m] * shaft->wheel_map[0][k] +
                                 shaft->frame[1][m] * shaft->wheel_map[1][k] + shaft->frame[2][m] * shaft->wheel_map[2][k];
                    sum -= found[j].d[3 * i + m] * row;
                }
                partial[j][6 * i + k] = sum;
            }
        }
    }
    return 1;
}
