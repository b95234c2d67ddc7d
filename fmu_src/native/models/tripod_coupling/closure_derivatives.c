/* The exact kinematics' partial derivatives (plane_solver.py; the step's plane_solve in tripod_coupling.c).
 *
 * The closure F(x, y; phi_in, beta) = star centre - P = 0 holds at the solution (x, y) the step found.
 * By the implicit function theorem d(x, y)/dq = -J^-1 dF/dq for every known q, J the analytic Jacobian in
 * (x, y) (star_tangent's): the star centre in dual numbers at the fixed (x, y) gives dF/dq, its tangents
 * give J. With the axis's partial derivatives so found, the star centre and its tangents once more in dual
 * numbers give arg(alpha) (phi_out - phi_in) and the step's ratio 1 + grad(arg alpha) . d(x, y)/d(phi_in)
 * as functions of the knowns alone: their partial derivatives are the closure's first and second ones.
 */
#include "derivatives.h"

/* Where the star centre is evaluated: the axis (x, y), cos and sin of beta and of 3 phi_in (turn3), r, l */
typedef struct {
    Dual x, y, cb, sb, turn3[2];
    double r, l;
} Place;

/* The star centre relative to P and the terms its tangents reuse (the step's StarCentre) */
typedef struct {
    Dual fx, fy, twist, orbit_r, orbit_i;
    Dual z, k, E1x, E1z, E2x, E2z, Ux, Uz, f1, f2, ar, ai, norm, tr, ti, qr, qi;
    Place at;
} Star;

/* Its derivative along (dx, dy) at constant phi_in and beta: the residual's two components and arg(alpha)'s */
typedef struct {
    Dual fx, fy, twist;
} Tangent;

/* plane_solver._star_centre's values in dual numbers */
static Star star_centre(const Place *at)
{
    Star s;
    Dual one = dual_constant(1.0), x = at->x, y = at->y, cb = at->cb, sb = at->sb;
    Dual z = dual_sqrt(dual_sub(one, dual_mul2(x, x, y, y))), k = dual_div(one, dual_shift(z, 1.0));
    Dual xyk = dual_mul(dual_mul(x, y), k);
    Dual e1x = dual_sub(one, dual_mul(dual_mul(x, x), k)), e2y = dual_sub(one, dual_mul(dual_mul(y, y), k));
    Dual a11, a12, a21, a22, c1, c2, br, bi;
    double r = at->r, l = at->l;
    s.at = *at;
    s.z = z;
    s.k = k;
    s.E1x = dual_mul2(cb, e1x, sb, x);
    s.E1z = dual_cross(sb, e1x, cb, x);
    s.E2x = dual_cross(sb, y, cb, xyk);
    s.E2z = dual_neg(dual_mul2(sb, xyk, cb, y));
    s.Ux = dual_cross(cb, x, sb, z);
    s.Uz = dual_mul2(sb, x, cb, z);
    s.f1 = dual_div(s.E1z, s.Uz);
    s.f2 = dual_div(s.E2z, s.Uz);
    a11 = dual_scale(dual_sub(s.E1x, dual_mul(s.Ux, s.f1)), r);
    a12 = dual_scale(dual_neg(dual_add(xyk, dual_mul(y, s.f1))), r);
    a21 = dual_scale(dual_sub(s.E2x, dual_mul(s.Ux, s.f2)), r);
    a22 = dual_scale(dual_sub(e2y, dual_mul(y, s.f2)), r);
    c1 = dual_scale(dual_add(dual_mul(dual_shift(z, -1.0), s.f1), x), l);
    c2 = dual_scale(dual_add(dual_mul(dual_shift(z, -1.0), s.f2), y), l);
    s.ar = dual_scale(dual_add(a11, a22), 0.5);
    s.ai = dual_scale(dual_sub(a21, a12), 0.5);
    br = dual_scale(dual_sub(a11, a22), 0.5);
    bi = dual_scale(dual_add(a21, a12), 0.5);
    s.norm = dual_mul2(s.ar, s.ar, s.ai, s.ai);
    s.tr = dual_div(dual_cross(s.ar, s.ar, s.ai, s.ai), s.norm);
    s.ti = dual_div(dual_scale(dual_mul(s.ar, s.ai), 2.0), s.norm);
    s.qr = dual_mul2(s.tr, br, s.ti, bi);
    s.qi = dual_cross(s.ti, br, s.tr, bi);
    s.orbit_r = dual_cross(s.qr, at->turn3[0], s.qi, at->turn3[1]);
    s.orbit_i = dual_mul2(s.qr, at->turn3[1], s.qi, at->turn3[0]);
    s.fx = dual_sub(c1, s.orbit_r);
    s.fy = dual_sub(c2, s.orbit_i);
    s.twist = dual_atan2(s.ai, s.ar);
    return s;
}

/* plane_solver._star_centre's tangent along (dx, dy, 0, 0) in dual numbers (the step's star_tangent) */
static Tangent star_tangent(const Star *s, double dx, double dy)
{
    Tangent t;
    Dual x = s->at.x, y = s->at.y, z = s->z, k = s->k, cb = s->at.cb, sb = s->at.sb, f1 = s->f1, f2 = s->f2;
    Dual dz = dual_div(dual_neg(dual_add(dual_scale(x, dx), dual_scale(y, dy))), z);
    Dual dk = dual_neg(dual_mul(dual_mul(k, k), dz));
    Dual dxyk = dual_add(dual_mul(dual_add(dual_scale(y, dx), dual_scale(x, dy)), k), dual_mul(dual_mul(x, y), dk));
    Dual de1x = dual_neg(dual_add(dual_scale(dual_mul(x, k), 2.0 * dx), dual_mul(dual_mul(x, x), dk)));
    Dual de2y = dual_neg(dual_add(dual_scale(dual_mul(y, k), 2.0 * dy), dual_mul(dual_mul(y, y), dk)));
    Dual dE1x = dual_add(dual_mul(cb, de1x), dual_scale(sb, dx));
    Dual dE1z = dual_sub(dual_mul(sb, de1x), dual_scale(cb, dx));
    Dual dE2x = dual_sub(dual_scale(sb, dy), dual_mul(cb, dxyk));
    Dual dE2z = dual_neg(dual_add(dual_mul(sb, dxyk), dual_scale(cb, dy)));
    Dual dUx = dual_sub(dual_scale(cb, dx), dual_mul(sb, dz)), dUz = dual_add(dual_scale(sb, dx), dual_mul(cb, dz));
    Dual df1 = dual_div(dual_sub(dE1z, dual_mul(f1, dUz)), s->Uz);
    Dual df2 = dual_div(dual_sub(dE2z, dual_mul(f2, dUz)), s->Uz);
    Dual da11 = dual_scale(dual_sub(dual_sub(dE1x, dual_mul(dUx, f1)), dual_mul(s->Ux, df1)), s->at.r);
    Dual da12 = dual_scale(dual_sub(dual_sub(dual_neg(dxyk), dual_scale(f1, dy)), dual_mul(y, df1)), s->at.r);
    Dual da21 = dual_scale(dual_sub(dual_sub(dE2x, dual_mul(dUx, f2)), dual_mul(s->Ux, df2)), s->at.r);
    Dual da22 = dual_scale(dual_sub(dual_sub(de2y, dual_scale(f2, dy)), dual_mul(y, df2)), s->at.r);
    Dual dc1 = dual_scale(dual_shift(dual_add(dual_mul(dz, f1), dual_mul(dual_shift(z, -1.0), df1)), dx), s->at.l);
    Dual dc2 = dual_scale(dual_shift(dual_add(dual_mul(dz, f2), dual_mul(dual_shift(z, -1.0), df2)), dy), s->at.l);
    Dual dar = dual_scale(dual_add(da11, da22), 0.5), dai = dual_scale(dual_sub(da21, da12), 0.5);
    Dual dbr = dual_scale(dual_sub(da11, da22), 0.5), dbi = dual_scale(dual_add(da21, da12), 0.5);
    Dual dtwist = dual_div(dual_cross(s->ar, dai, s->ai, dar), s->norm); /* Im(d alpha / alpha) */
    Dual dqr = dual_sub(dual_mul2(s->tr, dbr, s->ti, dbi), dual_scale(dual_mul(dtwist, s->qi), 2.0));
    Dual dqi = dual_add(dual_cross(s->ti, dbr, s->tr, dbi), dual_scale(dual_mul(dtwist, s->qr), 2.0));
    t.fx = dual_sub(dc1, dual_cross(dqr, s->at.turn3[0], dqi, s->at.turn3[1]));
    t.fy = dual_sub(dc2, dual_mul2(dqr, s->at.turn3[1], dqi, s->at.turn3[0]));
    t.twist = dtwist;
    return t;
}

DualClosure closure_derivatives(double x0, double y0, Dual phi_in, Dual cb, Dual sb, double r, double l)
{
    DualClosure out;
    Dual det, d_chi_x, d_chi_y, dx_dphi, dy_dphi;
    Place at;
    Star s;
    Tangent along_x, along_y;
    double jxx, jyx, jxy, jyy, value_det, fx, fy;
    int c;
    at.x = dual_constant(x0);
    at.y = dual_constant(y0);
    at.cb = cb;
    at.sb = sb;
    at.turn3[0] = dual_cos(dual_scale(phi_in, 3.0));
    at.turn3[1] = dual_sin(dual_scale(phi_in, 3.0));
    at.r = r;
    at.l = l;
    /* the residual at the fixed axis: its partial derivatives dF/dq; the tangents' values: J */
    s = star_centre(&at);
    along_x = star_tangent(&s, 1.0, 0.0);
    along_y = star_tangent(&s, 0.0, 1.0);
    jxx = along_x.fx.v;
    jyx = along_x.fy.v;
    jxy = along_y.fx.v;
    jyy = along_y.fy.v;
    value_det = jxx * jyy - jxy * jyx;
    for (c = 0; c < DUAL_SIZE; c++) {
        fx = s.fx.d[c];
        fy = s.fy.d[c];
        at.x.d[c] = -(jyy * fx - jxy * fy) / value_det;
        at.y.d[c] = -(jxx * fy - jyx * fx) / value_det;
    }
    /* again along the solution: the residual's partial derivatives vanish, the rest are total */
    s = star_centre(&at);
    along_x = star_tangent(&s, 1.0, 0.0);
    along_y = star_tangent(&s, 0.0, 1.0);
    det = dual_cross(along_x.fx, along_y.fy, along_y.fx, along_x.fy);
    d_chi_x = dual_scale(s.orbit_i, 3.0);
    d_chi_y = dual_scale(s.orbit_r, -3.0);
    dx_dphi = dual_neg(dual_div(dual_cross(along_y.fy, d_chi_x, along_y.fx, d_chi_y), det));
    dy_dphi = dual_neg(dual_div(dual_cross(along_x.fx, d_chi_y, along_x.fy, d_chi_x), det));
    out.x = at.x;
    out.y = at.y;
    out.twist = s.twist;
    out.ratio = dual_shift(dual_mul2(along_x.twist, dx_dphi, along_y.twist, dy_dphi), 1.0);
    return out;
}
