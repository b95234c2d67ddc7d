/* The exact reactions' partial derivatives (reactions.py; the step's exact_reactions and frictional_balance
 * in tripod_coupling.c): the same steps 1-5 in dual numbers, from the closure's axis and its partial
 * derivatives. The two 3x3 Cramer solves (angular velocity, angular acceleration) and the moment balance
 * are differentiated as written (the adjugate's and the determinant's derivatives included).
 *
 * Friction: the balance is a fixed point (lambda, mu) = G(lambda, mu; knowns), a contraction of rate about
 * the friction coefficient, that the step solves by successive substitution. Its derivative is the fixed
 * point of d = G_x d + G_q, the same substitution in dual numbers: from the frictionless forces, the values
 * and the partial derivatives are iterated until both have settled (each column's change of the arm
 * forces below FRICTION_TOLERANCE of their own size in that column). The regularised slip signs are
 * smooth; the normal forces are norms (dual_sqrt: at a vanishing force, a kink, its partial derivatives
 * are taken 0).
 */
#include "derivatives.h"

#include "driveline_constants.h"
#include "illinois.h"

static const double PI = 3.141592653589793; /* math.pi */

/* One arm of the balance in dual numbers (the step's Arm) */
typedef struct {
    Dual gx, gy, bz, ex, ey, ez, dx, dy, dz, exy2, k[3];
    Dual ax, ay, hx, hy, hz;
    Dual zdot, sigma, zddot;
} DualArm;

/* sum_j rhs_j adj_j[i]: Cramer's rule for K v = rhs, component i */
static Dual cramer(const Dual rhs[3], Dual adj[3][3], int i)
{
    return dual_add(dual_mul2(rhs[0], adj[0][i], rhs[1], adj[1][i]), dual_mul(rhs[2], adj[2][i]));
}

/* a . b of two vectors given by components */
static Dual dot(Dual ax, Dual ay, Dual az, Dual bx, Dual by, Dual bz)
{
    return dual_add(dual_mul2(ax, bx, ay, by), dual_mul(az, bz));
}

/* K^T w = M: w_j = M . adj_j / det */
static void transposed_solve(Dual Mx, Dual My, Dual Mz, Dual adj[3][3], Dual inv_det, Dual out[3])
{
    int j;
    for (j = 0; j < 3; j++) {
        out[j] = dual_mul(dot(Mx, My, Mz, adj[j][0], adj[j][1], adj[j][2]), inv_det);
    }
}

/* reactions.slip_sign: u / sqrt(1 + u^2), u = speed / slip_speed */
static Dual slip_sign(Dual speed, double slip_speed)
{
    Dual u = dual_scale(speed, 1.0 / slip_speed);
    return dual_div(u, dual_sqrt(dual_shift(dual_mul(u, u), 1.0)));
}

/* adds |change| weighted by ``weight`` to each column's and the value's tally */
static void tally(Dual change, double weight, double sums[DUAL_SIZE + 1])
{
    int c;
    sums[DUAL_SIZE] += fabs(change.v) * weight;
    for (c = 0; c < DUAL_SIZE; c++) {
        sums[c] += fabs(change.d[c]) * weight;
    }
}

/* The friction balance (frictional_balance) in dual numbers: lams, mus from the frictionless ones to the
 * fixed point, slips, grooves and the dissipated power; 0 when the partial derivatives do not settle. */
static int frictional_balance(const DualArm arm[3], Dual adj[3][3], Dual inv_det, const Dual moment[3],
                              const DualLoad *load, Dual lams[3], Dual mus[3], Dual slips[3], Dual grooves[3],
                              Dual *power)
{
    Dual signs[3][2], new_mus[3], new_lams[3];
    double m = load->m, friction = load->friction, change[DUAL_SIZE + 1], scale[DUAL_SIZE + 1];
    int iteration, j, c, settled = 0;
    for (j = 0; j < 3; j++) {
        const DualArm *a = &arm[j];
        signs[j][0] = slip_sign(a->zdot, load->slip_speed);
        signs[j][1] = slip_sign(dual_mul(a->sigma, dual_sqrt(dual_add(a->exy2, dual_mul(a->ez, a->ez)))),
                                load->slip_speed);
    }
    for (iteration = 0; iteration < TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS && !settled; iteration++) {
        Dual Mx = moment[0], My = moment[1], Mz = moment[2];
        for (c = 0; c <= DUAL_SIZE; c++) {
            change[c] = scale[c] = 0.0;
        }
        for (j = 0; j < 3; j++) {
            const DualArm *a = &arm[j];
            Dual lam = lams[j], mu = mus[j], e2 = dual_add(a->exy2, dual_mul(a->ez, a->ez));
            Dual normal = dual_sqrt(dual_mul(a->exy2, dual_add(dual_mul(lam, lam), dual_mul(dual_mul(mu, mu), e2))));
            Dual slip = dual_div(dual_scale(dual_mul(normal, signs[j][1]), friction), dual_sqrt(e2));
            Dual mu_ez = dual_mul(mu, a->ez), groove;
            Dual along = dual_add(mu_ez, slip);
            Dual Nx = dual_add(dual_add(dual_scale(a->ax, m), dual_mul(lam, a->ey)), dual_mul(along, a->ex));
            Dual Ny = dual_add(dual_sub(dual_scale(a->ay, m), dual_mul(lam, a->ex)), dual_mul(along, a->ey));
            Dual new_mu, arm_x, arm_y, arm_z;
            groove = dual_scale(dual_mul(dual_sqrt(dual_mul2(Nx, Nx, Ny, Ny)), signs[j][0]), -friction);
            /* plunger along Z': groove - F_z = m zddot with F_z = -mu |n|^2 + phi e_z */
            new_mu = dual_div(dual_add(dual_sub(dual_scale(a->zddot, m), groove), dual_mul(slip, a->ez)), a->exy2);
            arm_x = dual_neg(dual_mul2(a->dy, a->exy2, a->dz, dual_mul(a->ez, a->ey))); /* d x (e x n) */
            arm_y = dual_mul2(a->dz, dual_mul(a->ez, a->ex), a->dx, a->exy2);
            arm_z = dual_mul(a->ez, dual_cross(a->dx, a->ey, a->dy, a->ex));
            Mx = dual_sub(Mx, dual_mul2(new_mu, arm_x, slip, dual_cross(a->dy, a->ez, a->dz, a->ey)));
            My = dual_sub(My, dual_mul2(new_mu, arm_y, slip, dual_cross(a->dz, a->ex, a->dx, a->ez)));
            Mz = dual_sub(Mz, dual_mul2(new_mu, arm_z, slip, dual_cross(a->dx, a->ey, a->dy, a->ex)));
            tally(dual_sub(new_mu, mu), sqrt(a->exy2.v * e2.v), change);
            tally(new_mu, sqrt(a->exy2.v * e2.v), scale);
            new_mus[j] = new_mu;
            slips[j] = slip;
            grooves[j] = groove;
        }
        transposed_solve(Mx, My, Mz, adj, inv_det, new_lams);
        for (j = 0; j < 3; j++) {
            tally(dual_sub(new_lams[j], lams[j]), sqrt(arm[j].exy2.v), change);
            tally(new_lams[j], sqrt(arm[j].exy2.v), scale);
            lams[j] = new_lams[j];
            mus[j] = new_mus[j];
        }
        settled = 1;
        for (c = 0; c <= DUAL_SIZE; c++) {
            settled = settled && change[c] <= TRIPOD_REACTIONS_FRICTION_TOLERANCE * scale[c];
        }
    }
    *power = dual_constant(0.0);
    for (j = 0; j < 3; j++) {
        /* dissipation: -g_j zdot_j (groove) + phi_j sdot_j (arm), sdot_j |e_j| = sigma_j |e_j|^2 */
        Dual e2 = dual_add(arm[j].exy2, dual_mul(arm[j].ez, arm[j].ez));
        Dual arm_power = dual_mul(dual_mul(slips[j], arm[j].sigma), e2);
        *power = dual_add(dual_sub(*power, dual_mul(grooves[j], arm[j].zdot)), arm_power);
    }
    return settled;
}

/* Step 1, the pose of arm j at groove angle (c, s): ball centre, arm vector e, d = b - S, the row k of K */
static void pose(DualArm *a, Dual c, Dual s, double r, double l, Dual P[3], Dual U[3], Dual p_dot_u)
{
    a->gx = dual_scale(c, r);
    a->gy = dual_scale(s, r);
    a->bz = dual_div(dual_sub(dual_sub(p_dot_u, dual_mul(a->gx, U[0])), dual_mul(a->gy, U[1])), U[2]);
    a->ex = dual_sub(a->gx, P[0]);
    a->ey = dual_sub(a->gy, P[1]);
    a->ez = dual_sub(a->bz, P[2]);
    a->dx = dual_sub(a->ex, dual_scale(U[0], l));
    a->dy = dual_sub(a->ey, dual_scale(U[1], l));
    a->dz = dual_sub(a->ez, dual_scale(U[2], l));
    a->exy2 = dual_mul2(a->ex, a->ex, a->ey, a->ey);
    a->k[0] = dual_mul(a->dz, a->ex);
    a->k[1] = dual_mul(a->dz, a->ey);
    a->k[2] = dual_neg(dual_mul2(a->dx, a->ex, a->dy, a->ey));
}

/* Steps 2 and 3's known terms of arm j: velocities, sliding rates, whirl and Coriolis terms, at the input speed
 * ``omega`` and its rate relative to the bend plane */
static void known_terms(DualArm *a, const Dual W[3], Dual W2, Dual omega, Dual omega_dot, const Dual Sv[2],
                        const Dual Sa[2])
{
    Dual omega2 = dual_mul(omega, omega);
    Dual vx = dual_add(dual_add(dual_cross(W[1], a->dz, W[2], a->dy), dual_mul(omega, a->gy)), Sv[0]);
    Dual vy = dual_sub(dual_cross(W[2], a->dx, W[0], a->dz), dual_mul(omega, a->gx));
    Dual wd = dot(W[0], W[1], W[2], a->dx, a->dy, a->dz); /* Omega x (Omega x d) = Omega (Omega . d) - d |Omega|^2 */
    Dual sigma = dual_div(dual_neg(dual_mul2(vx, a->ex, vy, a->ey)), a->exy2), twice_sigma = dual_scale(sigma, 2.0);
    Dual coriolis_x = dual_mul(twice_sigma, dual_cross(W[1], a->ez, W[2], a->ey));
    Dual coriolis_y = dual_mul(twice_sigma, dual_cross(W[2], a->ex, W[0], a->ez));
    Dual coriolis_z = dual_mul(twice_sigma, dual_cross(W[0], a->ey, W[1], a->ex));
    a->sigma = sigma;
    a->hx = dual_add(dual_add(dual_cross(W[0], wd, a->dx, W2), coriolis_x), Sa[0]);
    a->hy = dual_add(dual_cross(W[1], wd, a->dy, W2), coriolis_y);
    a->hz = dual_add(dual_add(dual_cross(W[2], wd, a->dz, W2), coriolis_z), Sa[1]);
    a->ax = dual_neg(dual_mul2(omega_dot, a->gy, omega2, a->gx)); /* groove point's acceleration */
    a->ay = dual_cross(omega_dot, a->gx, omega2, a->gy);
    a->zdot = dual_add(dual_add(dual_cross(W[0], a->dy, W[1], a->dx), dual_mul(a->sigma, a->ez)), Sv[1]);
}

/* Step 5: the reactions from the arm forces (lambda, mu, slip along the arm, groove friction) */
static void bearing_reactions(const DualArm arm[3], const Dual lams[3], const Dual mus[3], const Dual slips[3],
                              const Dual grooves[3], const Dual E1[3], const Dual E2[3], const Dual U[3], double m,
                              DualReactions *out)
{
    Dual R_out[3], R_in[2], L[3];
    int j, i;
    for (i = 0; i < 3; i++) {
        R_out[i] = L[i] = dual_constant(0.0);
    }
    R_in[0] = R_in[1] = dual_constant(0.0);
    for (j = 0; j < 3; j++) {
        const DualArm *a = &arm[j];
        Dual along = dual_add(dual_mul(mus[j], a->ez), slips[j]);
        Dual Fx = dual_add(dual_mul(lams[j], a->ey), dual_mul(along, a->ex));
        Dual Fy = dual_sub(dual_mul(along, a->ey), dual_mul(lams[j], a->ex));
        Dual Fz = dual_cross(slips[j], a->ez, mus[j], a->exy2);
        Dual Nx = dual_add(dual_scale(a->ax, m), Fx), Ny = dual_add(dual_scale(a->ay, m), Fy);
        Dual tx = dual_cross(U[1], a->ez, U[2], a->ey), ty = dual_cross(U[2], a->ex, U[0], a->ez);
        Dual tz = dual_cross(U[0], a->ey, U[1], a->ex); /* U x e_j, in the tripod plane */
        R_out[0] = dual_sub(R_out[0], Fx);
        R_out[1] = dual_sub(R_out[1], Fy);
        R_out[2] = dual_sub(R_out[2], Fz);
        R_in[0] = dual_add(R_in[0], Nx);
        R_in[1] = dual_add(R_in[1], Ny);
        L[0] = dual_add(dual_sub(L[0], dual_mul(a->bz, Ny)), dual_mul(a->gy, grooves[j]));
        L[1] = dual_sub(dual_add(L[1], dual_mul(a->bz, Nx)), dual_mul(a->gx, grooves[j]));
        L[2] = dual_add(L[2], dual_cross(a->gx, Ny, a->gy, Nx));
        out->F_arm[j] = dual_div(dot(Fx, Fy, Fz, tx, ty, tz), dual_sqrt(dot(tx, ty, tz, tx, ty, tz)));
        out->F_plunger[j] = dual_scale(a->zddot, m);
    }
    out->Rx_in = R_in[0];
    out->Ry_in = R_in[1];
    out->Mx_in = L[0];
    out->My_in = L[1];
    out->T_in = L[2];
    out->Rx_out = dot(R_out[0], R_out[1], R_out[2], E1[0], E1[1], E1[2]);
    out->Ry_out = dot(R_out[0], R_out[1], R_out[2], E2[0], E2[1], E2[2]);
    out->Rz_out = dot(R_out[0], R_out[1], R_out[2], U[0], U[1], U[2]);
    out->a_plunger_sum = dual_add(dual_add(arm[0].zddot, arm[1].zddot), arm[2].zddot);
    out->Rz_in = dual_add(dual_add(grooves[0], grooves[1]), grooves[2]);
}

/* ---- the roller tripods (rollers.py; the step's roller_reactions in tripod_coupling.c) ---------------
 * The same successive substitution in dual numbers until values and partial derivatives have settled. The
 * single roller's contact normal is the root of the miss of H's direction in its angle: its value by the
 * step's bracketed Illinois iteration, its partial derivatives by the implicit function theorem,
 * -(d miss / d knowns) / (d miss / d angle), the latter from the miss with the angle alone seeded. */

typedef struct {
    Dual v[3];
} Vec;

static Vec vec(Dual x, Dual y, Dual z)
{
    Vec r;
    r.v[0] = x;
    r.v[1] = y;
    r.v[2] = z;
    return r;
}

static Dual vdot(Vec a, Vec b)
{
    return dot(a.v[0], a.v[1], a.v[2], b.v[0], b.v[1], b.v[2]);
}

static Vec vcross(Vec a, Vec b)
{
    return vec(dual_cross(a.v[1], b.v[2], a.v[2], b.v[1]), dual_cross(a.v[2], b.v[0], a.v[0], b.v[2]),
               dual_cross(a.v[0], b.v[1], a.v[1], b.v[0]));
}

static Vec vscale(Vec a, Dual s)
{
    return vec(dual_mul(a.v[0], s), dual_mul(a.v[1], s), dual_mul(a.v[2], s));
}

static Vec vadd(Vec a, Vec b)
{
    return vec(dual_add(a.v[0], b.v[0]), dual_add(a.v[1], b.v[1]), dual_add(a.v[2], b.v[2]));
}

/* a / |a| (a zero vector stays zero) and |a| */
static Vec vunit(Vec a, Dual *size)
{
    Dual by;
    *size = dual_sqrt(vdot(a, a));
    by = size->v > 0.0 ? *size : dual_constant(1.0);
    return vec(dual_div(a.v[0], by), dual_div(a.v[1], by), dual_div(a.v[2], by));
}

/* its value alone: the same vector without partial derivatives */
static Vec vvalue(Vec a)
{
    return vec(dual_constant(a.v[0].v), dual_constant(a.v[1].v), dual_constant(a.v[2].v));
}

/* The single roller's contact at normal angle ``angle`` (rollers._skewed_slips and the miss) */
typedef struct {
    Vec k, u, s, pushed;
    Dual across, v_roll, v_skew, miss;
} DualContact;

static DualContact skewed_contact_at(const DualLoad *load, Dual angle, Dual target, Vec axis, Dual zdot, Vec spin)
{
    DualContact c;
    Dual R = dual_constant(load->roller_radius), zero = dual_constant(0.0), roll, skew;
    Vec v0, g;
    int i;
    c.k = vec(dual_cos(angle), dual_sin(angle), zero);
    c.u = vunit(vcross(axis, c.k), &c.across);
    c.s = vcross(c.k, c.u);
    v0 = vadd(vec(zero, zero, zdot), vscale(vcross(spin, c.k), dual_neg(R)));
    c.v_roll = dual_add(vdot(v0, c.u), dual_mul(dual_mul(R, c.across), vdot(spin, axis)));
    c.v_skew = vdot(v0, c.s);
    roll = dual_scale(slip_sign(c.v_roll, load->slip_speed), -load->mu_roll);
    skew = dual_scale(slip_sign(c.v_skew, load->slip_speed), load->friction);
    g = vadd(vscale(c.u, roll), vscale(c.s, dual_neg(skew)));
    for (i = 0; i < 2; i++) {
        c.pushed.v[i] = dual_add(c.k.v[i], g.v[i]);
    }
    c.pushed.v[2] = zero;
    /* the angle's miss, wrapped into [-pi, pi): a shift by whole turns, which moves no derivative */
    c.miss = dual_sub(dual_atan2(c.pushed.v[1], c.pushed.v[0]), target);
    c.miss.v = fmod(fmod(c.miss.v + PI, 2.0 * PI) + 2.0 * PI, 2.0 * PI) - PI;
    return c;
}

/* What the miss of the contacts' values needs (illinois.h) */
typedef struct {
    const DualLoad *load;
    const Vec *axis;
    const double *zdot, *target;
    Vec spin;
} MissContext;

static double miss_at(void *context, int arm, double angle)
{
    MissContext *at = (MissContext *)context;
    return skewed_contact_at(at->load, dual_constant(angle), dual_constant(at->target[arm]), at->axis[arm],
                             dual_constant(at->zdot[arm]), at->spin).miss.v;
}

/* rollers._skewed_contact for the three arms together: the angle's value by the Illinois method, then its
 * partial derivatives; N = |H| / |k + g_h| and the friction forces. */
static void skewed_contacts(const DualLoad *load, const Vec H[3], const Vec axis[3], const Dual zdot[3], Vec spin,
                            DualContact c[3], Dual N[3], Dual F_roll[3], Dual F_skew[3])
{
    double target_v[3], zdot_v[3], angles[3], angle;
    Dual target[3], size[3];
    Vec axis_v[3], spin_v = vvalue(spin);
    MissContext context;
    int j;
    for (j = 0; j < 3; j++) {
        target[j] = dual_atan2(H[j].v[1], H[j].v[0]);
        size[j] = dual_sqrt(vdot(H[j], H[j]));
        axis_v[j] = vvalue(axis[j]);
        target_v[j] = target[j].v;
        zdot_v[j] = zdot[j].v;
    }
    context = (MissContext){load, axis_v, zdot_v, target_v, spin_v};
    illinois_angles(miss_at, &context, target_v, load->friction, load->mu_roll, angles);
    for (j = 0; j < 3; j++) {
        Dual theta, slope;
        DualContact knowns, own;
        int col;
        angle = angles[j];
        knowns = skewed_contact_at(load, dual_constant(angle), target[j], axis[j], zdot[j], spin);
        own = skewed_contact_at(load, dual_known(angle, 0), dual_constant(target[j].v), axis_v[j],
                                dual_constant(zdot[j].v), spin_v);
        slope = own.miss;
        theta = dual_constant(angle);
        for (col = 0; col < DUAL_SIZE; col++) {
            theta.d[col] = -knowns.miss.d[col] / slope.d[0];
        }
        c[j] = skewed_contact_at(load, theta, target[j], axis[j], zdot[j], spin);
        N[j] = dual_div(size[j], dual_sqrt(vdot(c[j].pushed, c[j].pushed)));
        F_roll[j] = dual_mul(dual_scale(N[j], -load->mu_roll), slip_sign(c[j].v_roll, load->slip_speed));
        F_skew[j] = dual_mul(dual_scale(N[j], -load->friction), slip_sign(c[j].v_skew, load->slip_speed));
    }
}

/* rollers.roller_reactions in dual numbers (R5-R15), from the frictionless lams, mus; 0 when the partial
 * derivatives do not settle. */
static int roller_reactions(const DualArm arm[3], Dual adj[3][3], Dual inv_det, const DualLoad *load,
                            const Dual E1[3], const Dual E2[3], const Dual U[3], const Dual W[3], Dual lam[3],
                            Dual mu_q[3], DualReactions *out)
{
    const double m = load->m, R = load->roller_radius, mu = load->friction;
    const double needle_share = load->roller_bore_radius / R; /* r_b / R */
    Vec centre[3], e[3], d[3], n[3], q[3], axis[3], groove_acc[3], force[3], friction[3], couple[3], H[3];
    Vec friction_h[3], spin, load_moment, Uv = vec(U[0], U[1], U[2]), Wv = vec(W[0], W[1], W[2]);
    Dual length[3], zdot[3], zddot[3], v_trunnion[3], trunnion_sign[3], N_trunnion[3], phi[3], N[3], F_roll[3];
    Dual F_skew[3], v_roll[3], v_skew[3], zero = dual_constant(0.0), power = zero;
    Vec R_out = vec(zero, zero, zero), R_in = R_out, L = R_out;
    DualContact c[3];
    Dual step_lam[3], step_mu[3], next_lam[3], next_mu[3];
    double change[DUAL_SIZE + 1], scale[DUAL_SIZE + 1];
    double relax = 1.0, last_lam[3] = {0.0, 0.0, 0.0}, last_mu[3] = {0.0, 0.0, 0.0};
    int iteration, i, j, col, settled = 0;
    for (j = 0; j < 3; j++) {
        const DualArm *a = &arm[j];
        centre[j] = vec(a->gx, a->gy, a->bz);
        e[j] = vec(a->ex, a->ey, a->ez);
        d[j] = vec(a->dx, a->dy, a->dz);
        n[j] = vec(a->ey, dual_neg(a->ex), zero);
        q[j] = vcross(e[j], n[j]);
        axis[j] = vunit(e[j], &length[j]);
        groove_acc[j] = vec(a->ax, a->ay, zero);
        zdot[j] = a->zdot;
        zddot[j] = a->zddot;
        v_trunnion[j] = dual_mul(a->sigma, length[j]);
        trunnion_sign[j] = slip_sign(v_trunnion[j], load->slip_speed);
        friction_h[j] = vec(zero, zero, zero);
    }
    spin = vec(W[0], W[1], dual_sub(W[2], load->omega));
    load_moment = vscale(Uv, load->T_load);
    for (iteration = 0; iteration < TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS && !settled; iteration++) {
        Vec moment = load_moment;
        for (col = 0; col <= DUAL_SIZE; col++) {
            change[col] = scale[col] = 0.0;
        }
        for (j = 0; j < 3; j++) {
            N_trunnion[j] = dual_sqrt(dual_mul(arm[j].exy2, dual_add(dual_mul(lam[j], lam[j]),
                                               dual_mul(dual_mul(mu_q[j], mu_q[j]), dual_mul(length[j], length[j])))));
            phi[j] = dual_div(dual_scale(dual_mul(N_trunnion[j], trunnion_sign[j]), mu), length[j]);
            force[j] = vadd(vadd(vscale(n[j], lam[j]), vscale(q[j], mu_q[j])), vscale(e[j], phi[j]));
            H[j] = vec(dual_add(dual_scale(groove_acc[j].v[0], m), force[j].v[0]),
                       dual_add(dual_scale(groove_acc[j].v[1], m), force[j].v[1]), zero);
        }
        if (load->tripod_type == TRIPOD_SPEC_SINGLE_ROLLER) {
            skewed_contacts(load, H, axis, zdot, spin, c, N, F_roll, F_skew);
            for (j = 0; j < 3; j++) {
                friction[j] = vadd(vscale(c[j].u, F_roll[j]), vscale(c[j].s, F_skew[j]));
                couple[j] = vadd(vcross(vscale(c[j].k, dual_constant(-R)), friction[j]),
                                 vscale(axis[j], dual_mul(dual_scale(F_roll[j], R), c[j].across)));
                v_roll[j] = c[j].v_roll;
                v_skew[j] = c[j].v_skew;
            }
        } else {
            for (j = 0; j < 3; j++) {
                Vec lever = vcross(vunit(H[j], &N[j]), axis[j]); /* k x a */
                v_roll[j] = zdot[j];
                v_skew[j] = dual_scale(dual_sub(dual_scale(dual_mul(zdot[j], axis[j].v[2]), 1.0 / R),
                                                vdot(spin, lever)), load->roller_bore_radius); /* R16 */
                F_roll[j] = dual_mul(dual_scale(N[j], -load->mu_roll), slip_sign(v_roll[j], load->slip_speed));
                F_skew[j] = dual_mul(dual_scale(N[j], -mu), slip_sign(v_skew[j], load->slip_speed));
                friction[j] = vec(zero, zero, dual_add(F_roll[j], dual_mul(dual_scale(axis[j].v[2], needle_share),
                                                                           F_skew[j]))); /* R17 */
                couple[j] = vscale(lever, dual_scale(F_skew[j], -load->roller_bore_radius)); /* R18 */
            }
        }
        for (j = 0; j < 3; j++) {
            Dual new_mu = dual_div(dual_add(dual_sub(dual_scale(zddot[j], m), friction[j].v[2]),
                                            dual_mul(phi[j], e[j].v[2])), arm[j].exy2);
            Vec h = vec(friction[j].v[0], friction[j].v[1], zero);
            double weight = sqrt(arm[j].exy2.v) * length[j].v;
            moment = vadd(moment, vscale(vcross(d[j], q[j]), dual_neg(new_mu)));
            moment = vadd(moment, vscale(vcross(d[j], e[j]), dual_neg(phi[j])));
            moment = vadd(moment, vscale(couple[j], dual_constant(-1.0)));
            tally(dual_sub(new_mu, mu_q[j]), weight, change);
            tally(new_mu, weight, scale);
            for (i = 0; i < 2; i++) {
                tally(dual_sub(h.v[i], friction_h[j].v[i]), 1.0, change);
                tally(h.v[i], 1.0, scale);
            }
            friction_h[j] = h;
            step_mu[j] = dual_sub(new_mu, mu_q[j]);
            next_mu[j] = new_mu;
        }
        for (j = 0; j < 3; j++) {
            Dual new_lam = dual_mul(vdot(moment, vec(adj[j][0], adj[j][1], adj[j][2])), inv_det);
            tally(dual_sub(new_lam, lam[j]), sqrt(arm[j].exy2.v), change);
            tally(new_lam, sqrt(arm[j].exy2.v), scale);
            step_lam[j] = dual_sub(new_lam, lam[j]);
            next_lam[j] = new_lam;
        }
        if (load->tripod_type != TRIPOD_SPEC_SINGLE_ROLLER) { /* the double roller's relaxation, on the values */
            double last = 0.0, along = 0.0, ratio, shared;
            for (j = 0; j < 3; j++) {
                double length2 = length[j].v * length[j].v;
                last = last + arm[j].exy2.v * (last_lam[j] * last_lam[j] + length2 * last_mu[j] * last_mu[j]);
                along = along + arm[j].exy2.v * (step_lam[j].v * last_lam[j] + length2 * step_mu[j].v * last_mu[j]);
                last_lam[j] = step_lam[j].v;
                last_mu[j] = step_mu[j].v;
            }
            ratio = along / (last > 0.0 ? last : 1.0);
            shared = relax / (ratio < 1.0 ? 1.0 - ratio : 1.0);
            shared = ratio < 1.0 ? (1.0 < shared ? 1.0 : shared) : 0.5 * relax;
            relax = last > 0.0 ? shared : relax;
            for (j = 0; j < 3; j++) {
                next_lam[j] = dual_add(lam[j], dual_scale(step_lam[j], relax));
                next_mu[j] = dual_add(mu_q[j], dual_scale(step_mu[j], relax));
            }
        }
        for (j = 0; j < 3; j++) {
            lam[j] = next_lam[j];
            mu_q[j] = next_mu[j];
        }
        settled = iteration > 0;
        for (col = 0; col <= DUAL_SIZE; col++) {
            settled = settled && change[col] <= TRIPOD_REACTIONS_FRICTION_TOLERANCE * scale[col];
        }
    }
    /* R14, R15 */
    for (j = 0; j < 3; j++) {
        Vec track, t;
        N_trunnion[j] = dual_sqrt(dual_mul(arm[j].exy2, dual_add(dual_mul(lam[j], lam[j]),
                                           dual_mul(dual_mul(mu_q[j], mu_q[j]), dual_mul(length[j], length[j])))));
        phi[j] = dual_div(dual_scale(dual_mul(N_trunnion[j], trunnion_sign[j]), mu), length[j]);
        force[j] = vadd(vadd(vscale(n[j], lam[j]), vscale(q[j], mu_q[j])), vscale(e[j], phi[j]));
        track = vadd(vscale(vadd(groove_acc[j], vec(zero, zero, zddot[j])), dual_constant(m)), force[j]);
        t = vcross(Uv, e[j]);
        R_out = vadd(R_out, vscale(force[j], dual_constant(-1.0)));
        R_in = vadd(R_in, track);
        L = vadd(L, vadd(vcross(centre[j], track), couple[j]));
        out->F_arm[j] = dual_div(vdot(force[j], t), dual_sqrt(vdot(t, t)));
        out->F_plunger[j] = dual_scale(zddot[j], m);
        power = dual_add(power, dual_sub(dual_mul(dual_mul(phi[j], length[j]), v_trunnion[j]),
                                         dual_add(dual_mul(F_roll[j], v_roll[j]), dual_mul(F_skew[j], v_skew[j]))));
    }
    out->Rx_in = R_in.v[0];
    out->Ry_in = R_in.v[1];
    out->Mx_in = L.v[0];
    out->My_in = L.v[1];
    out->T_in = L.v[2];
    out->Rx_out = vdot(R_out, vec(E1[0], E1[1], E1[2]));
    out->Ry_out = vdot(R_out, vec(E2[0], E2[1], E2[2]));
    out->Rz_out = vdot(R_out, Uv);
    out->a_plunger_sum = dual_add(dual_add(zddot[0], zddot[1]), zddot[2]);
    out->omega_spin = vdot(Wv, Uv);
    out->Rz_in = R_in.v[2];
    out->P_friction = power;
    return settled;
}

Failure reaction_derivatives(const DualLoad *load, Dual x, Dual y, DualReactions *out)
{
    const double half_root_3 = 0.5 * sqrt(3.0), r = load->r, l = load->l, m = load->m;
    Dual one = dual_constant(1.0), cb = load->cb, sb = load->sb, bd = load->beta_dot, bdd = load->beta_ddot;
    Dual zn = dual_sqrt(dual_sub(one, dual_mul2(x, x, y, y))), k = dual_div(one, dual_shift(zn, 1.0));
    Dual xyk = dual_mul(dual_mul(x, y), k), e1x = dual_sub(one, dual_mul(dual_mul(x, x), k));
    Dual e2y = dual_sub(one, dual_mul(dual_mul(y, y), k)), bd2 = dual_mul(bd, bd);
    /* the mechanism in the bend plane's frame, turning at psi_dot: the input speed relative to it (M3) */
    Dual spin = dual_sub(load->omega, load->psi_dot), spin_dot = dual_sub(load->omega_dot, load->psi_ddot);
    Dual omega2 = dual_mul(load->omega, load->omega);
    Dual E1[3], E2[3], U[3], P[3], Sv[2], Sa[2], c[3], s[3], adj[3][3], inv_det, rhs[3], W[3], W2, A[3];
    Dual moment[3], Mx, My, Mz, p_dot_u, lams[3], mus[3], slips[3], grooves[3], power = dual_constant(0.0);
    DualArm arm[3];
    int j;
    /* twist-free frame (E1, E2, U) of the output shaft, nominal output frame -> input frame (eq 2) */
    E1[0] = dual_mul2(cb, e1x, sb, x);
    E1[1] = dual_neg(xyk);
    E1[2] = dual_cross(sb, e1x, cb, x);
    E2[0] = dual_cross(sb, y, cb, xyk);
    E2[1] = e2y;
    E2[2] = dual_neg(dual_mul2(sb, xyk, cb, y));
    U[0] = dual_cross(cb, x, sb, zn);
    U[1] = y;
    U[2] = dual_mul2(sb, x, cb, zn);
    P[0] = dual_scale(dual_add(sb, U[0]), -l); /* P = S - l U, S = l (-sin, 0, cos) */
    P[1] = dual_scale(U[1], -l);
    P[2] = dual_scale(dual_sub(cb, U[2]), l);
    /* the moving bearing: Sdot = l betadot (-cos, 0, -sin), Sddot = l betaddot (-cos, 0, -sin) - l betadot^2 e_out */
    Sv[0] = dual_scale(dual_mul(cb, bd), -l);
    Sv[1] = dual_add(dual_scale(dual_mul(sb, bd), -l), load->plunge_dot); /* the spider's plunge joins zdot_j (M5) */
    Sa[0] = dual_scale(dual_cross(sb, bd2, cb, bdd), l);
    Sa[1] = dual_scale(dual_mul2(cb, bd2, sb, bdd), -l);
    p_dot_u = dot(P[0], P[1], P[2], U[0], U[1], U[2]);
    c[0] = dual_cos(load->phi_in);
    s[0] = dual_sin(load->phi_in);
    c[1] = dual_sub(dual_scale(c[0], -0.5), dual_scale(s[0], half_root_3));
    s[1] = dual_add(dual_scale(s[0], -0.5), dual_scale(c[0], half_root_3));
    c[2] = dual_add(dual_scale(c[0], -0.5), dual_scale(s[0], half_root_3));
    s[2] = dual_sub(dual_scale(s[0], -0.5), dual_scale(c[0], half_root_3));
    for (j = 0; j < 3; j++) {
        pose(&arm[j], c[j], s[j], r, l, P, U, p_dot_u);
    }
    /* Cramer's rule with the adjugate's rows, the cross products of the rows of K */
    for (j = 0; j < 3; j++) {
        const Dual *p = arm[(j + 1) % 3].k, *q = arm[(j + 2) % 3].k;
        adj[j][0] = dual_cross(p[1], q[2], p[2], q[1]);
        adj[j][1] = dual_cross(p[2], q[0], p[0], q[2]);
        adj[j][2] = dual_cross(p[0], q[1], p[1], q[0]);
    }
    inv_det = dual_div(one, dot(arm[0].k[0], arm[0].k[1], arm[0].k[2], adj[0][0], adj[0][1], adj[0][2]));
    /* 2. angular velocity of the output shaft */
    for (j = 0; j < 3; j++) {
        Dual g_dot_e = dual_mul2(arm[j].gx, arm[j].ex, arm[j].gy, arm[j].ey);
        rhs[j] = dual_mul(dual_neg(dual_mul2(spin, g_dot_e, Sv[0], arm[j].ey)), inv_det);
    }
    for (j = 0; j < 3; j++) {
        W[j] = cramer(rhs, adj, j);
    }
    W2 = dot(W[0], W[1], W[2], W[0], W[1], W[2]);
    /* 3. accelerations: known terms per arm, then K Omegadot = (known . n_j) */
    for (j = 0; j < 3; j++) {
        known_terms(&arm[j], W, W2, spin, spin_dot, Sv, Sa);
    }
    for (j = 0; j < 3; j++) {
        const DualArm *a = &arm[j];
        rhs[j] = dual_mul(dual_cross(dual_sub(a->ax, a->hx), a->ey, dual_sub(a->ay, a->hy), a->ex), inv_det);
    }
    for (j = 0; j < 3; j++) {
        A[j] = cramer(rhs, adj, j);
    }
    /* plunger accelerations and 4. the Z' parts of the arm forces, F_j = lambda_j n_j + mu_j (e_j x n_j) */
    for (j = 0; j < 3; j++) {
        moment[j] = dual_mul(load->T_load, U[j]);
    }
    Mx = moment[0];
    My = moment[1];
    Mz = moment[2];
    for (j = 0; j < 3; j++) {
        DualArm *a = &arm[j];
        Dual wx = dual_sub(dual_add(dual_cross(A[1], a->dz, A[2], a->dy), a->hx), a->ax);
        Dual wy = dual_sub(dual_add(dual_cross(A[2], a->dx, A[0], a->dz), a->hy), a->ay);
        Dual wz = dual_add(dual_cross(A[0], a->dy, A[1], a->dx), a->hz);
        Dual qx = dual_mul(a->ez, a->ex), qy = dual_mul(a->ez, a->ey), qz = dual_neg(a->exy2);
        a->zddot = dual_sub(wz, dual_mul(dual_div(dual_mul2(wx, a->ex, wy, a->ey), a->exy2), a->ez));
        mus[j] = dual_div(dual_scale(a->zddot, m), a->exy2);
        Mx = dual_sub(Mx, dual_mul(mus[j], dual_cross(a->dy, qz, a->dz, qy)));
        My = dual_sub(My, dual_mul(mus[j], dual_cross(a->dz, qx, a->dx, qz)));
        Mz = dual_sub(Mz, dual_mul(mus[j], dual_cross(a->dx, qy, a->dy, qx)));
        slips[j] = grooves[j] = dual_constant(0.0);
        /* the groove point's acceleration in the housing, what the forces take (M4) */
        a->ax = dual_neg(dual_mul2(load->omega_dot, a->gy, omega2, a->gx));
        a->ay = dual_cross(load->omega_dot, a->gx, omega2, a->gy);
    }
    transposed_solve(Mx, My, Mz, adj, inv_det, lams);
    W[2] = dual_add(W[2], load->psi_dot); /* the output shaft's angular velocity in the housing (M6) */
    if (load->tripod_type != TRIPOD_SPEC_PLAIN_TRIPOD) { /* outputs.coupling_outputs: the rollers' balance */
        if (!roller_reactions(arm, adj, inv_det, load, E1, E2, U, W, lams, mus, out)) {
            return FAILURE(ERROR_ARITHMETIC, "roller tripod friction balance: its partial derivatives did not converge");
        }
        return NO_FAILURE;
    }
    if (load->friction != 0.0 &&
        !frictional_balance(arm, adj, inv_det, moment, load, lams, mus, slips, grooves, &power)) {
        return FAILURE(ERROR_ARITHMETIC, "tripod friction balance: its partial derivatives did not converge");
    }
    bearing_reactions(arm, lams, mus, slips, grooves, E1, E2, U, m, out);
    out->omega_spin = dot(W[0], W[1], W[2], U[0], U[1], U[2]);
    out->P_friction = power;
    return NO_FAILURE;
}
