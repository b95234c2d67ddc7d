/* TripodCoupling: tripod sliding universal coupling with a self-aligning output bearing, seed 000
 * (Xiu, Chang, Ju, Zheng 2024; port of driveline/tripod/).
 *
 * Kinematics: eq 18 and its derivative (closed form), or the exact closure in the tripod-plane
 * formulation (plane_solver.py), warm-started from the last step's solution through its
 * first-order predictor. Reactions: the exact force balance (reactions.py, with Coulomb friction
 * by successive substitution), its leading order in r/l (reactions_closed_form.py), or the seed's
 * eqs 20, 30, 33, 34 as printed (dynamics.py). Every expression keeps the Python core's order of
 * operations; where Python's math module or float division raises, the step is refused with
 * Python's words. The exact partial derivatives of the outputs (the ``jacobian`` hook) are in the
 * folder tripod_coupling/ (derivatives.h).
 */
#include <math.h>

#include "driveline_constants.h"
#include "fmi/fmu_instance.h"
#include "derivatives.h"
#include "step.h"

#define INTEGER(name) (data->int_value[V_##name])
/* the exact solver's warm start (plane_solver.Solution): a flag, then phi_in, x, y, dx/dphi, dy/dphi */
#define HAS_SOLUTION (data->internal[0])
#define SOLUTION (data->internal + 1)
/* the bend samples of the last two communication points (beta_rate: the samples or automatic), newest
 * first: their count, then time and beta of each (TripodCouplingModel._beta_samples) */
#define SAMPLE_COUNT (data->internal[6])
#define SAMPLES (data->internal + 7)
/* beta_rate = RATES_AUTOMATIC: 1 once the host has set beta_dot or beta_ddot non-zero (_rates_set) */
#define RATES_SET (data->internal[11])

static double cosine(Guard *guard, double a)
{
    return isinf(a) ? refuse(guard, ERROR_VALUE, MATH_DOMAIN) : cos(a);
}

static double sine(Guard *guard, double a)
{
    return isinf(a) ? refuse(guard, ERROR_VALUE, MATH_DOMAIN) : sin(a);
}

static double arcsine(Guard *guard, double a)
{
    return fabs(a) > 1.0 ? refuse(guard, ERROR_VALUE, MATH_DOMAIN) : asin(a);
}

/* ---- exact kinematics, tripod-plane formulation (plane_solver.py) ------------------------- */

/* The star centre at one axis (x, y) and the terms its directional derivatives reuse; arg(alpha) =
 * atan2(ai, ar) is taken by the solver at its last iterate alone. */
typedef struct {
    double fx, fy, orbit_r, orbit_i;
    double x, y, z, k, cb, sb, E1x, E1z, E2x, E2z, Ux, Uz, f1, f2, ar, ai, norm, tr, ti, qr, qi, turn3[2], r, l;
} StarCentre;

/* Directional derivative of the star centre (two components) and of arg(alpha). */
typedef struct {
    double fx, fy, twist;
} StarTangent;

/* Star centre relative to P in tripod-plane coordinates and the centre's term in turn3 = exp(3i chi);
 * frame vectors mapped to the input frame by eq 2. */
static StarCentre star_centre(Guard *guard, double x, double y, const double turn3[2], double cb, double sb,
                              double r, double l)
{
    StarCentre s;
    double z = root(guard, 1.0 - x * x - y * y), k = divide(guard, 1.0, 1.0 + z), xyk = x * y * k;
    double e1x = 1.0 - x * x * k, e2y = 1.0 - y * y * k;
    double E1x = cb * e1x + sb * x, E1z = sb * e1x - cb * x;
    double E2x = sb * y - cb * xyk, E2z = -sb * xyk - cb * y;
    double Ux = cb * x - sb * z, Uz = sb * x + cb * z;
    double f1 = divide(guard, E1z, Uz), f2 = divide(guard, E2z, Uz);
    double a11 = r * (E1x - Ux * f1), a12 = r * (-xyk - y * f1);
    double a21 = r * (E2x - Ux * f2), a22 = r * (e2y - y * f2);
    double c1 = l * ((z - 1.0) * f1 + x), c2 = l * ((z - 1.0) * f2 + y);
    double ar = 0.5 * (a11 + a22), ai = 0.5 * (a21 - a12);
    double br = 0.5 * (a11 - a22), bi = 0.5 * (a21 + a12);
    double norm = ar * ar + ai * ai;
    double tr = divide(guard, ar * ar - ai * ai, norm), ti = divide(guard, 2.0 * ar * ai, norm);
    double qr = tr * br + ti * bi, qi = ti * br - tr * bi;
    s.orbit_r = qr * turn3[0] - qi * turn3[1];
    s.orbit_i = qr * turn3[1] + qi * turn3[0];
    s.fx = c1 - s.orbit_r;
    s.fy = c2 - s.orbit_i;
    s.x = x;
    s.y = y;
    s.z = z;
    s.k = k;
    s.cb = cb;
    s.sb = sb;
    s.E1x = E1x;
    s.E1z = E1z;
    s.E2x = E2x;
    s.E2z = E2z;
    s.Ux = Ux;
    s.Uz = Uz;
    s.f1 = f1;
    s.f2 = f2;
    s.ar = ar;
    s.ai = ai;
    s.norm = norm;
    s.tr = tr;
    s.ti = ti;
    s.qr = qr;
    s.qi = qi;
    s.turn3[0] = turn3[0];
    s.turn3[1] = turn3[1];
    s.r = r;
    s.l = l;
    return s;
}

/* The star centre's exact derivative along (dx, dy, dbeta, dphi_in): the frame's columns turn with
 * beta as d(E_x, E_z)/d beta = (-E_z, E_x), arg alpha moves by Im(d alpha / alpha), exp(2i arg alpha)
 * by 2i times that and turn3 by 3i turn3 dphi_in (plane_solver._star_centre's tangents). */
static StarTangent star_tangent(Guard *guard, const StarCentre *s, double dx, double dy, double dbeta, double dphi)
{
    StarTangent t;
    double x = s->x, y = s->y, z = s->z, k = s->k, cb = s->cb, sb = s->sb, r = s->r, l = s->l;
    double dz = divide(guard, -(x * dx + y * dy), z), dk = -k * k * dz, dxyk = (dx * y + x * dy) * k + x * y * dk;
    double de1x = -(2.0 * x * dx * k + x * x * dk), de2y = -(2.0 * y * dy * k + y * y * dk);
    double dE1x = cb * de1x + sb * dx - s->E1z * dbeta, dE1z = sb * de1x - cb * dx + s->E1x * dbeta;
    double dE2x = sb * dy - cb * dxyk - s->E2z * dbeta, dE2z = -sb * dxyk - cb * dy + s->E2x * dbeta;
    double dUx = cb * dx - sb * dz - s->Uz * dbeta, dUz = sb * dx + cb * dz + s->Ux * dbeta;
    double df1 = divide(guard, dE1z - s->f1 * dUz, s->Uz), df2 = divide(guard, dE2z - s->f2 * dUz, s->Uz);
    double da11 = r * (dE1x - dUx * s->f1 - s->Ux * df1), da12 = r * (-dxyk - dy * s->f1 - y * df1);
    double da21 = r * (dE2x - dUx * s->f2 - s->Ux * df2), da22 = r * (de2y - dy * s->f2 - y * df2);
    double dc1 = l * (dz * s->f1 + (z - 1.0) * df1 + dx), dc2 = l * (dz * s->f2 + (z - 1.0) * df2 + dy);
    double dar = 0.5 * (da11 + da22), dai = 0.5 * (da21 - da12);
    double dbr = 0.5 * (da11 - da22), dbi = 0.5 * (da21 + da12);
    double dtwist = divide(guard, s->ar * dai - s->ai * dar, s->norm); /* Im(d alpha / alpha) */
    double dqr = s->tr * dbr + s->ti * dbi - 2.0 * dtwist * s->qi;
    double dqi = s->ti * dbr - s->tr * dbi + 2.0 * dtwist * s->qr;
    double dorbit_r = dqr * s->turn3[0] - dqi * s->turn3[1] - 3.0 * dphi * s->orbit_i;
    double dorbit_i = dqr * s->turn3[1] + dqi * s->turn3[0] + 3.0 * dphi * s->orbit_r;
    t.fx = dc1 - dorbit_r;
    t.fy = dc2 - dorbit_i;
    t.twist = dtwist;
    return t;
}

/* Newton's method on "star centre = tripod centre" for the axis (x, y), from the warm start
 * ``solution`` (when ``warm``) or the small-r/l orbit; ``solution`` is overwritten with the new one.
 * Gives phi_out and d(phi_out)/d(phi_in) by the implicit function theorem. ``cb``, ``sb``: cos and
 * sin of beta (libm gives the same bits for the same argument, so each is computed once). */
static void plane_solve(Guard *guard, double phi_in, double cb, double sb, double r, double l, int warm,
                        double solution[5], double *phi_out, double *ratio)
{
    double x, y, turn3[2], jxx = 0.0, jyx = 0.0, jxy = 0.0, jyy = 0.0;
    double det = 0.0, dx = 0.0, dy = 0.0, twist, dx_dphi, dy_dphi;
    StarCentre f;
    StarTangent along_x = {0.0, 0.0, 0.0}, along_y = along_x;
    int i;
    f.orbit_r = f.orbit_i = 0.0;
    if (!warm) {
        double rho_over_l = divide(guard, r * (1.0 - cb), 2.0 * cb * l);
        x = rho_over_l * cosine(guard, 3.0 * phi_in);
        y = rho_over_l * sine(guard, 3.0 * phi_in);
    } else {
        double step = phi_in - solution[0];
        x = solution[1] + solution[3] * step;
        y = solution[2] + solution[4] * step;
    }
    turn3[0] = cosine(guard, 3.0 * phi_in);
    turn3[1] = sine(guard, 3.0 * phi_in);
    for (i = 0; i < TRIPOD_PLANE_SOLVER_MAX_ITERATIONS && guard->failure.kind == ERROR_NONE; i++) {
        f = star_centre(guard, x, y, turn3, cb, sb, r, l);
        along_x = star_tangent(guard, &f, 1.0, 0.0, 0.0, 0.0);
        along_y = star_tangent(guard, &f, 0.0, 1.0, 0.0, 0.0);
        jxx = along_x.fx;
        jyx = along_x.fy;
        jxy = along_y.fx;
        jyy = along_y.fy;
        det = jxx * jyy - jxy * jyx;
        dx = divide(guard, jyy * f.fx - jxy * f.fy, det);
        dy = divide(guard, jxx * f.fy - jyx * f.fx, det);
        x = x - dx;
        y = y - dy;
        if (fabs(dx) + fabs(dy) <= TRIPOD_PLANE_SOLVER_LAST_UPDATE) {
            break;
        }
    }
    if (i == TRIPOD_PLANE_SOLVER_MAX_ITERATIONS) {
        refuse(guard, ERROR_ARITHMETIC, "tripod closure: plane iteration did not converge");
    }
    if (guard->failure.kind != ERROR_NONE) {
        return;
    }
    /* the last update moved (x, y) by (-dx, -dy): carry arg(alpha) along to first order */
    twist = atan2(f.ai, f.ar) - (along_x.twist * dx + along_y.twist * dy);
    /* d(x, y)/d(phi_in) = -J^-1 dF/d(phi_in), dF/d(phi_in) = -3i orbit */
    dx_dphi = -(jyy * (3.0 * f.orbit_i) - jxy * (-3.0 * f.orbit_r)) / det;
    dy_dphi = -(jxx * (-3.0 * f.orbit_r) - jyx * (3.0 * f.orbit_i)) / det;
    *ratio = 1.0 + along_x.twist * dx_dphi + along_y.twist * dy_dphi;
    *phi_out = phi_in + twist;
    solution[0] = phi_in;
    solution[1] = x;
    solution[2] = y;
    solution[3] = dx_dphi;
    solution[4] = dy_dphi;
}

/* ---- reactions ----------------------------------------------------------------------------- */

/* One arm in the friction balance: what its iterations do not change (reactions._friction_arm) */
typedef struct {
    double ex, ey, ez, exy2, e2, e_norm, ne_norm, n_norm; /* e_j, |n|^2, |e|^2, |e|, |n||e|, |n| */
    double m_ax, m_ay, m_zddot, groove_sign, arm_sign;    /* m a_xy, m zddot, the slips' regularised signs */
    double mu_arm[3], slip_arm[3];                        /* the moment arms of mu_j and phi_j */
} FrictionArm;

/* Arm forces with Coulomb friction in both sliding pairs of each arm, by successive substitution
 * from the frictionless forces (reactions._frictional_balance): lambda_j, mu_j, the slip forces
 * phi_j along the arms, the groove forces g_j and the dissipated power. Nothing in the iterations can
 * fail as Python would: sigma_j's division has refused |n_j|^2 = 0 before, so |e_j| > 0, and every square
 * root is of a sum of squares; their arithmetic runs unguarded, on copies the compiler may keep at hand. */
static void frictional_balance(Guard *guard, const Arm arm[3], const double adj[3][3], double inv_det,
                               const double load_moment[3], const Load *load, double lams[3], double mus[3],
                               double slips[3], double grooves[3], double *power)
{
    FrictionArm fixed[3];
    double lam_now[3], mu_now[3], new_mus[3], new_lams[3], slip_now[3] = {0.0, 0.0, 0.0};
    double groove_now[3] = {0.0, 0.0, 0.0}, inverse[3][3], m = load->m, friction = load->friction;
    int iteration = 0, i, j;
    for (j = 0; j < 3; j++) {
        const Arm *a = &arm[j];
        FrictionArm *f = &fixed[j];
        f->ex = a->ex;
        f->ey = a->ey;
        f->ez = a->ez;
        f->exy2 = a->exy2;
        f->e2 = a->exy2 + a->ez * a->ez;
        f->e_norm = root(guard, f->e2);
        f->ne_norm = root(guard, a->exy2 * f->e2);
        f->n_norm = root(guard, a->exy2);
        f->m_ax = m * a->ax;
        f->m_ay = m * a->ay;
        f->m_zddot = m * a->zddot;
        f->groove_sign = slip_sign(guard, a->zdot, load->slip_speed);
        f->arm_sign = slip_sign(guard, a->sigma * f->e_norm, load->slip_speed);
        f->mu_arm[0] = a->dy * -a->exy2 - a->dz * a->ez * a->ey;
        f->mu_arm[1] = a->dz * a->ez * a->ex + a->dx * a->exy2;
        f->mu_arm[2] = a->dx * a->ez * a->ey - a->dy * a->ez * a->ex;
        f->slip_arm[0] = a->dy * a->ez - a->dz * a->ey;
        f->slip_arm[1] = a->dz * a->ex - a->dx * a->ez;
        f->slip_arm[2] = a->dx * a->ey - a->dy * a->ex;
        lam_now[j] = lams[j];
        mu_now[j] = mus[j];
        for (i = 0; i < 3; i++) {
            inverse[j][i] = adj[j][i];
        }
    }
    for (; iteration < TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS && guard->failure.kind == ERROR_NONE; iteration++) {
        double Mx = load_moment[0], My = load_moment[1], Mz = load_moment[2], change = 0.0, scale = 0.0;
        for (j = 0; j < 3; j++) {
            const FrictionArm *a = &fixed[j];
            double lam = lam_now[j], mu = mu_now[j];
            double normal = sqrt(a->exy2 * (lam * lam + mu * mu * a->e2));
            double slip = friction * normal * a->arm_sign / a->e_norm;
            double Nx = a->m_ax + lam * a->ey + mu * a->ez * a->ex + slip * a->ex;
            double Ny = a->m_ay - lam * a->ex + mu * a->ez * a->ey + slip * a->ey;
            double groove = -friction * sqrt(Nx * Nx + Ny * Ny) * a->groove_sign;
            /* plunger along Z': groove - F_z = m zddot with F_z = -mu |n|^2 + phi e_z */
            double new_mu = (a->m_zddot - groove + slip * a->ez) / a->exy2;
            Mx = Mx - new_mu * a->mu_arm[0] - slip * a->slip_arm[0];
            My = My - new_mu * a->mu_arm[1] - slip * a->slip_arm[1];
            Mz = Mz - new_mu * a->mu_arm[2] - slip * a->slip_arm[2];
            change = change + fabs(new_mu - mu) * a->ne_norm;
            scale = scale + normal;
            new_mus[j] = new_mu;
            slip_now[j] = slip;
            groove_now[j] = groove;
        }
        for (j = 0; j < 3; j++) {
            new_lams[j] = (Mx * inverse[j][0] + My * inverse[j][1] + Mz * inverse[j][2]) * inv_det;
        }
        for (j = 0; j < 3; j++) {
            change = change + fabs(new_lams[j] - lam_now[j]) * fixed[j].n_norm;
        }
        for (j = 0; j < 3; j++) {
            lam_now[j] = new_lams[j];
            mu_now[j] = new_mus[j];
        }
        if (change <= TRIPOD_REACTIONS_FRICTION_TOLERANCE * scale) {
            break;
        }
    }
    if (iteration == TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS) {
        refuse(guard, ERROR_ARITHMETIC, "tripod friction balance did not converge (friction coefficient too large?)");
    }
    *power = 0.0;
    for (j = 0; j < 3; j++) {
        lams[j] = lam_now[j];
        mus[j] = mu_now[j];
        slips[j] = slip_now[j];
        grooves[j] = groove_now[j];
        /* dissipation: -g_j zdot_j (groove) + phi_j sdot_j (arm), sdot_j |e_j| = sigma_j |e_j|^2 */
        *power = *power - grooves[j] * arm[j].zdot + slips[j] * arm[j].sigma * (arm[j].exy2 + arm[j].ez * arm[j].ez);
    }
}

/* The exact reactions (reactions.exact_reactions, steps 1-5) for the output-shaft axis (x, y). */
static void exact_reactions(Guard *guard, const Load *load, double x, double y, Reactions *out)
{
    const double half_root_3 = 0.5 * sqrt(3.0), r = load->r, l = load->l, m = load->m;
    const double omega = load->omega, omega_dot = load->omega_dot;
    /* the mechanism in the bend plane's frame, turning at psi_dot: the input speed relative to it (M3) */
    const double spin = omega - load->psi_dot, spin_dot = omega_dot - load->psi_ddot;
    double cb = load->cb, sb = load->sb, zn = root(guard, 1.0 - x * x - y * y);
    double k = divide(guard, 1.0, 1.0 + zn);
    /* twist-free frame (E1, E2, U) of the output shaft, nominal output frame -> input frame (eq 2) */
    double e1x = 1.0 - x * x * k, e1y = -x * y * k, e2x = -x * y * k, e2y = 1.0 - y * y * k;
    double E1x = cb * e1x + sb * x, E1y = e1y, E1z = sb * e1x - cb * x;
    double E2x = cb * e2x + sb * y, E2y = e2y, E2z = sb * e2x - cb * y;
    double Ux = cb * x - sb * zn, Uy = y, Uz = sb * x + cb * zn;
    double Sx = -l * sb, Sz = l * cb, Px = Sx - l * Ux, Py = -l * Uy, Pz = Sz - l * Uz;
    /* the moving bearing: Sdot = l betadot (-cos, 0, -sin), Sddot = l betaddot (-cos, 0, -sin) - l betadot^2 e_out */
    double bd = load->beta_dot, bdd = load->beta_ddot;
    double Svx = -l * cb * bd, Svz = -l * sb * bd + load->plunge_dot; /* the spider's plunge joins zdot_j (M5) */
    double Sax = l * (sb * bd * bd - cb * bdd), Saz = -l * (cb * bd * bd + sb * bdd);
    double p_dot_u = Px * Ux + Py * Uy + Pz * Uz, omega2 = omega * omega, spin2 = spin * spin;
    double c[3], s[3], adj[3][3], inv_det, rhs[3], Wx, Wy, Wz, W2, Ax, Ay, Az, Mx, My, Mz;
    double lams[3], mus[3], slips[3] = {0.0, 0.0, 0.0}, grooves[3] = {0.0, 0.0, 0.0}, moment[3];
    double Rx_out = 0.0, Ry_out = 0.0, Rz_out = 0.0, Rx_in = 0.0, Ry_in = 0.0, Lx = 0.0, Ly = 0.0, Lz = 0.0;
    double power = 0.0;
    Arm arm[3];
    int j;
    c[0] = cosine(guard, load->phi_in);
    s[0] = sine(guard, load->phi_in);
    c[1] = -0.5 * c[0] - half_root_3 * s[0];
    s[1] = -0.5 * s[0] + half_root_3 * c[0];
    c[2] = -0.5 * c[0] + half_root_3 * s[0];
    s[2] = -0.5 * s[0] - half_root_3 * c[0];
    for (j = 0; j < 3; j++) {
        Arm *a = &arm[j];
        a->gx = r * c[j];
        a->gy = r * s[j];
        /* 1. pose: the ball centre b = (gx, gy, bz) on groove j in the tripod plane */
        a->bz = divide(guard, p_dot_u - a->gx * Ux - a->gy * Uy, Uz);
        a->ex = a->gx - Px;
        a->ey = a->gy - Py;
        a->ez = a->bz - Pz;
        a->dx = a->ex - l * Ux;
        a->dy = a->ey - l * Uy;
        a->dz = a->ez - l * Uz;
        a->exy2 = a->ex * a->ex + a->ey * a->ey;
        a->k[0] = a->dz * a->ex;
        a->k[1] = a->dz * a->ey;
        a->k[2] = -(a->dx * a->ex + a->dy * a->ey);
    }
    /* Cramer's rule: K v = c <=> v = sum_j c_j adj_j / det; K^T w = c <=> w_j = c . adj_j / det */
    for (j = 0; j < 3; j++) {
        const double *p = arm[(j + 1) % 3].k, *q = arm[(j + 2) % 3].k;
        adj[j][0] = p[1] * q[2] - p[2] * q[1];
        adj[j][1] = p[2] * q[0] - p[0] * q[2];
        adj[j][2] = p[0] * q[1] - p[1] * q[0];
    }
    inv_det = divide(guard, 1.0, arm[0].k[0] * adj[0][0] + arm[0].k[1] * adj[0][1] + arm[0].k[2] * adj[0][2]);
    /* 2. angular velocity of the output shaft: (e_z x g_j) . n_j = -(g_x e_x + g_y e_y), Sdot . n_j = Sdot_x e_y */
    for (j = 0; j < 3; j++) {
        rhs[j] = (-spin * (arm[j].gx * arm[j].ex + arm[j].gy * arm[j].ey) - Svx * arm[j].ey) * inv_det;
    }
    Wx = rhs[0] * adj[0][0] + rhs[1] * adj[1][0] + rhs[2] * adj[2][0];
    Wy = rhs[0] * adj[0][1] + rhs[1] * adj[1][1] + rhs[2] * adj[2][1];
    Wz = rhs[0] * adj[0][2] + rhs[1] * adj[1][2] + rhs[2] * adj[2][2];
    W2 = Wx * Wx + Wy * Wy + Wz * Wz;
    /* 3. accelerations: known terms per arm, then K Omegadot = (known . n_j) */
    for (j = 0; j < 3; j++) {
        Arm *a = &arm[j];
        double vx = Wy * a->dz - Wz * a->dy + spin * a->gy + Svx, vy = Wz * a->dx - Wx * a->dz - spin * a->gx;
        double wd = Wx * a->dx + Wy * a->dy + Wz * a->dz; /* Omega x (Omega x d) = Omega (Omega . d) - d |Omega|^2 */
        a->sigma = divide(guard, -(vx * a->ex + vy * a->ey), a->exy2);
        a->hx = Wx * wd - a->dx * W2 + 2.0 * a->sigma * (Wy * a->ez - Wz * a->ey) + Sax;
        a->hy = Wy * wd - a->dy * W2 + 2.0 * a->sigma * (Wz * a->ex - Wx * a->ez);
        a->hz = Wz * wd - a->dz * W2 + 2.0 * a->sigma * (Wx * a->ey - Wy * a->ex) + Saz;
        a->ax = -spin_dot * a->gy - spin2 * a->gx; /* groove point's acceleration in the bend plane's frame */
        a->ay = spin_dot * a->gx - spin2 * a->gy;
        a->zdot = Wx * a->dy - Wy * a->dx + a->sigma * a->ez + Svz;
    }
    for (j = 0; j < 3; j++) {
        rhs[j] = ((arm[j].ax - arm[j].hx) * arm[j].ey - (arm[j].ay - arm[j].hy) * arm[j].ex) * inv_det;
    }
    Ax = rhs[0] * adj[0][0] + rhs[1] * adj[1][0] + rhs[2] * adj[2][0];
    Ay = rhs[0] * adj[0][1] + rhs[1] * adj[1][1] + rhs[2] * adj[2][1];
    Az = rhs[0] * adj[0][2] + rhs[1] * adj[1][2] + rhs[2] * adj[2][2];
    /* plunger accelerations and 4. the Z' parts of the arm forces, F_j = lambda_j n_j + mu_j (e_j x n_j) */
    moment[0] = load->T_load * Ux;
    moment[1] = load->T_load * Uy;
    moment[2] = load->T_load * Uz;
    Mx = moment[0];
    My = moment[1];
    Mz = moment[2];
    for (j = 0; j < 3; j++) {
        Arm *a = &arm[j];
        double wx = Ay * a->dz - Az * a->dy + a->hx - a->ax, wy = Az * a->dx - Ax * a->dz + a->hy - a->ay;
        double wz = Ax * a->dy - Ay * a->dx + a->hz, qx = a->ez * a->ex, qy = a->ez * a->ey, qz = -a->exy2;
        a->zddot = wz - divide(guard, wx * a->ex + wy * a->ey, a->exy2) * a->ez;
        mus[j] = divide(guard, m * a->zddot, a->exy2);
        Mx -= mus[j] * (a->dy * qz - a->dz * qy);
        My -= mus[j] * (a->dz * qx - a->dx * qz);
        Mz -= mus[j] * (a->dx * qy - a->dy * qx);
        a->ax = -omega_dot * a->gy - omega2 * a->gx; /* ... and in the housing, what the forces take (M4) */
        a->ay = omega_dot * a->gx - omega2 * a->gy;
    }
    for (j = 0; j < 3; j++) {
        lams[j] = (Mx * adj[j][0] + My * adj[j][1] + Mz * adj[j][2]) * inv_det;
    }
    Wz = Wz + load->psi_dot; /* the output shaft's angular velocity in the housing (M6) */
    if (load->tripod_type != TRIPOD_SPEC_PLAIN_TRIPOD) { /* outputs.coupling_outputs: the rollers' balance */
        Shaft shaft = {{Ux, Uy, Uz}, {E1x, E1y, E1z}, {E2x, E2y, E2z}, {Wx, Wy, Wz}};
        if (guard->failure.kind == ERROR_NONE) {
            roller_reactions(guard, arm, (const double(*)[3])adj, inv_det, load, &shaft, lams, mus, out);
        }
        return;
    }
    if (load->friction != 0.0 && guard->failure.kind == ERROR_NONE) {
        frictional_balance(guard, arm, (const double(*)[3])adj, inv_det, moment, load, lams, mus, slips, grooves,
                           &power);
    }
    /* 5. reactions: R_out = -sum F_j; groove force on plunger j N_j = m bddot_j + F_j, its moment about O */
    for (j = 0; j < 3; j++) {
        const Arm *a = &arm[j];
        double Fx = lams[j] * a->ey + mus[j] * a->ez * a->ex + slips[j] * a->ex;
        double Fy = -lams[j] * a->ex + mus[j] * a->ez * a->ey + slips[j] * a->ey;
        double Fz = -mus[j] * a->exy2 + slips[j] * a->ez, Nx, Ny, tx, ty, tz;
        Rx_out = Rx_out - Fx;
        Ry_out = Ry_out - Fy;
        Rz_out = Rz_out - Fz;
        Nx = m * a->ax + Fx;
        Ny = m * a->ay + Fy;
        Rx_in = Rx_in + Nx;
        Ry_in = Ry_in + Ny;
        Lx = Lx - a->bz * Ny + a->gy * grooves[j];
        Ly = Ly + a->bz * Nx - a->gx * grooves[j];
        Lz = Lz + a->gx * Ny - a->gy * Nx;
        tx = Uy * a->ez - Uz * a->ey; /* U x e_j, in the tripod plane */
        ty = Uz * a->ex - Ux * a->ez;
        tz = Ux * a->ey - Uy * a->ex;
        out->F_arm[j] = divide(guard, Fx * tx + Fy * ty + Fz * tz, root(guard, tx * tx + ty * ty + tz * tz));
        out->F_plunger[j] = m * a->zddot;
    }
    out->Rx_in = Rx_in;
    out->Ry_in = Ry_in;
    out->Mx_in = Lx;
    out->My_in = Ly;
    out->T_in = Lz;
    out->Rx_out = Rx_out * E1x + Ry_out * E1y + Rz_out * E1z;
    out->Ry_out = Rx_out * E2x + Ry_out * E2y + Rz_out * E2z;
    out->Rz_out = Rx_out * Ux + Ry_out * Uy + Rz_out * Uz;
    out->a_plunger_sum = arm[0].zddot + arm[1].zddot + arm[2].zddot;
    out->omega_spin = Wx * Ux + Wy * Uy + Wz * Uz;
    out->Rz_in = grooves[0] + grooves[1] + grooves[2];
    out->P_friction = power;
}

/* Leading order in r/l (reactions_closed_form.py) with A = 3/2 m r^2 tan(beta) / cos^2(beta) and
 * t = tan(beta / 2); ``ratio`` from eq 18's derivative, ``pin`` from eq 24 (corrected eq 21); in the bend
 * plane's frame, at the input speed relative to it (outputs.coupling_outputs). */
static void leading_order_reactions(Guard *guard, const Load *load, double ratio, double pin, Reactions *out)
{
    double m = load->m, r = load->r, l = load->l, omega_dot = load->omega_dot - load->psi_ddot, T = load->T_load;
    double omega = load->omega - load->psi_dot;
    double cb = load->cb, tb = divide(guard, load->sb, cb), half = divide(guard, load->sb, 1.0 + cb);
    double A = divide(guard, 1.5 * m * r * r * tb, cb * cb), omega2 = omega * omega;
    double ry_in = divide(guard, -(T * half + A * omega_dot * cb), l);
    double bend = divide(guard, m * r, cb * cb);
    double bend_rates = load->beta_ddot + 2.0 * tb * load->beta_dot * load->beta_dot;
    int j;
    for (j = 0; j < 3; j++) {
        double angle = load->phi_in + TRIPOD_GEOMETRY_THIRD_TURN * j, c = cosine(guard, angle), s = sine(guard, angle);
        out->F_plunger[j] = -m * r * tb * (omega2 * c + omega_dot * s) +
                            bend * (c * bend_rates - 2.0 * omega * load->beta_dot * s);
        out->F_arm[j] = pin;
    }
    out->Rx_in = divide(guard, -A * omega2, l * cb);
    out->Ry_in = ry_in;
    out->Mx_in = -T * half - 1.5 * m * r * r * tb * omega_dot;
    out->My_in = -A * omega2;
    out->T_in = T * ratio + 3.0 * m * r * r * (1.0 + 0.5 * tb * tb) * omega_dot;
    out->Rx_out = divide(guard, A * omega2, l);
    out->Ry_out = -ry_in;
    out->Rz_out = divide(guard, -A * omega2 * tb, l);
    out->a_plunger_sum = 0.0 * load->phi_in;
}

/* ---- outputs (outputs.coupling_outputs) ------------------------------------------------------ */

/* The turn by psi about Z' from the bend plane's frame into the housing's X'Y' (M8, outputs.to_housing):
 * its cosine and sine, taken once for every vector the step turns; none at psi = 0. */
typedef struct {
    int turned;
    double c, s;
} HousingTurn;

static HousingTurn housing_turn(Guard *guard, double psi)
{
    HousingTurn turn = {0, 1.0, 0.0};
    if (psi != 0.0) {
        turn.turned = 1;
        turn.c = cosine(guard, psi);
        turn.s = sine(guard, psi);
    }
    return turn;
}

/* Components (x, y) in the bend plane's frame turned into the housing's; at psi = 0 they stay as they are, a
 * zero's sign included. */
static void to_housing(const HousingTurn *turn, double *x, double *y)
{
    if (turn->turned) {
        double turned_x = turn->c * *x - turn->s * *y;
        *y = turn->s * *x + turn->c * *y;
        *x = turned_x;
    }
}

/* Rate and acceleration of beta at the newest of ``count`` (time, beta) samples, newest first
 * (tripod.model.sampled_rates: the derivatives of the polynomial through them). */
static void sampled_rates(const double *samples, int count, double *rate, double *acceleration)
{
    double slope, curvature;
    *rate = 0.0;
    *acceleration = 0.0;
    if (count < 2) {
        return;
    }
    slope = (samples[1] - samples[3]) / (samples[0] - samples[2]);
    if (count < 3) {
        *rate = slope;
        return;
    }
    curvature = (slope - (samples[3] - samples[5]) / (samples[2] - samples[4])) / (samples[0] - samples[4]);
    *rate = slope + curvature * (samples[0] - samples[2]);
    *acceleration = 2.0 * curvature;
}

/* Outputs ``elapsed`` after ``input_time`` (TripodCouplingModel._evaluate), with the speed and the
 * bend moved on by their rates. */
static Failure evaluate(ModelData *data, double input_time, double elapsed)
{
    Guard guard = {{ERROR_NONE, NULL}};
    Load load;
    Reactions forces;
    double beta_dot = VALUE(beta_dot), beta_ddot = VALUE(beta_ddot), beta, omega;
    double phi_in = VALUE(phi_in), r = VALUE(r), l = VALUE(l), T_load = VALUE(T_load);
    double cos_beta, sin_beta, rho, pin, phi_out = 0.0, ratio = 0.0, theta, omega_spin;
    double output_power, total, psi, psi_dot, phi, spin;
    HousingTurn turn;
    if (INTEGER(beta_rate) != RATES_FROM_INPUTS) { /* the samples are kept for the automatic choice too */
        double samples[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        int count = 1, k;
        samples[0] = input_time;
        samples[1] = VALUE(beta);
        for (k = 0; k < (int)SAMPLE_COUNT; k++) {
            if (SAMPLES[2 * k] < input_time) {
                samples[2 * count] = SAMPLES[2 * k];
                samples[2 * count + 1] = SAMPLES[2 * k + 1];
                count++;
            }
        }
        if (beta_dot != 0.0 || beta_ddot != 0.0) {
            RATES_SET = 1.0;
        }
        if (INTEGER(beta_rate) == RATES_FROM_SAMPLES || RATES_SET == 0.0) {
            sampled_rates(samples, count, &beta_dot, &beta_ddot);
        }
        SAMPLE_COUNT = count < 2 ? count : 2;
        for (k = 0; k < 4; k++) {
            SAMPLES[k] = samples[k];
        }
    }
    beta = VALUE(beta) + (beta_dot + 0.5 * beta_ddot * elapsed) * elapsed;
    if (!(0.0 <= beta && beta <= VALUE(beta_max))) {
        return FAILURE(ERROR_VALUE, BETA_LEAVES_RANGE);
    }
    psi = VALUE(psi) + (VALUE(psi_dot) + 0.5 * VALUE(psi_ddot) * elapsed) * elapsed;
    psi_dot = VALUE(psi_dot) + VALUE(psi_ddot) * elapsed;
    omega = VALUE(omega_in) + VALUE(alpha_in) * elapsed;
    phi = phi_in - psi;    /* the input angle from the bend plane (M1) */
    spin = omega - psi_dot; /* the input speed relative to it (M3) */
    cos_beta = cos(beta);
    sin_beta = sin(beta);
    load.phi_in = phi;
    load.cb = cos_beta;
    load.sb = sin_beta;
    load.beta_dot = beta_dot + beta_ddot * elapsed;
    load.beta_ddot = beta_ddot;
    load.psi_dot = psi_dot;
    load.psi_ddot = VALUE(psi_ddot);
    load.plunge_dot = VALUE(plunge_dot);
    load.omega = omega;
    load.omega_dot = VALUE(alpha_in);
    load.T_load = T_load;
    load.r = r;
    load.l = l;
    load.m = VALUE(m_plunger);
    load.friction = VALUE(mu);
    load.slip_speed = VALUE(v_slip);
    load.tripod_type = INTEGER(tripod_type);
    load.mu_roll = VALUE(mu_roll);
    load.roller_radius = VALUE(roller_radius);
    load.roller_bore_radius = VALUE(roller_bore_radius);
    rho = divide(&guard, r * (1.0 - cos_beta), 2.0 * cos_beta); /* orbit radius of the tripod centre */
    pin = divide(&guard, T_load, 3.0 * (r + rho));              /* eq 24 with the corrected eq 21 */
    if (INTEGER(kinematics) == TRIPOD_SPEC_EXACT) {
        plane_solve(&guard, phi, cos_beta, sin_beta, r, l, HAS_SOLUTION != 0.0, SOLUTION, &phi_out, &ratio);
        if (guard.failure.kind != ERROR_NONE) {
            return guard.failure;
        }
        HAS_SOLUTION = 1.0;
        theta = arcsine(&guard, hypot(SOLUTION[1], SOLUTION[2]));
        exact_reactions(&guard, &load, SOLUTION[1], SOLUTION[2], &forces);
        omega_spin = forces.omega_spin;
    } else {
        /* eq 18 with the seed's phi, A cos 3 phi = A sin 3 phi_in, and its derivative (not eq 19) */
        double amplitude = divide(&guard, r * (1.0 - cos_beta), 2.0 * l * (1.0 + cos_beta)) * tan(beta);
        double phase = 3.0 * (phi + TRIPOD_CLOSED_FORM_PAPER_PHASE);
        double deviation = amplitude * cosine(&guard, phase);
        ratio = 1.0 - 3.0 * amplitude * sine(&guard, phase);
        phi_out = phi + deviation;
        theta = arcsine(&guard, divide(&guard, rho, l));
        leading_order_reactions(&guard, &load, ratio, pin, &forces);
        omega_spin = spin * ratio + psi_dot;
        forces.Rz_in = 0.0 * ratio;
        forces.P_friction = 0.0 * ratio;
    }
    phi_out = phi_out + psi; /* (M2) */
    output_power = T_load * omega_spin;
    total = output_power + forces.P_friction;
    turn = housing_turn(&guard, psi);
    to_housing(&turn, &forces.Rx_in, &forces.Ry_in);
    to_housing(&turn, &forces.Mx_in, &forces.My_in);
    VALUE(phi_out) = phi_out;
    VALUE(delta_phi) = phi_out - phi_in;
    VALUE(omega_out) = spin * ratio + psi_dot; /* (M7) */
    VALUE(omega_spin) = omega_spin;
    VALUE(T_in) = forces.T_in;
    VALUE(F_pin) = pin;
    VALUE(rho) = rho;
    VALUE(theta) = theta;
    VALUE(a_plunger_sum) = forces.a_plunger_sum;
    VALUE(Rz_out) = forces.Rz_out;
    VALUE(Rx_out) = forces.Rx_out;
    VALUE(Ry_out) = forces.Ry_out;
    VALUE(Rx_in) = forces.Rx_in;
    VALUE(Ry_in) = forces.Ry_in;
    VALUE(Mx_in) = forces.Mx_in;
    VALUE(My_in) = forces.My_in;
    VALUE(Rz_in) = forces.Rz_in;
    VALUE(P_friction) = forces.P_friction;
    /* delivered over supplied power (outputs.efficiency): drive, coast, 0 in between */
    if (output_power >= 0.0) {
        VALUE(efficiency) = total != 0.0 ? output_power / total : 1.0;
    } else {
        double coast = total / output_power;
        VALUE(efficiency) = coast > 0.0 ? coast : 0.0;
    }
    VALUE(F_arm1) = forces.F_arm[0];
    VALUE(F_arm2) = forces.F_arm[1];
    VALUE(F_arm3) = forces.F_arm[2];
    VALUE(F_plunger1) = forces.F_plunger[0];
    VALUE(F_plunger2) = forces.F_plunger[1];
    VALUE(F_plunger3) = forces.F_plunger[2];
    if (INTEGER(seed_reactions)) {
        /* eqs 20, 30, 33, 34 as printed, with the seed's phi */
        double omega_squared = spin * spin, tan_beta = tan(beta), seed_x, seed_y;
        double seed_phi = phi + TRIPOD_CLOSED_FORM_PAPER_PHASE, cos_3phi = cosine(&guard, 3.0 * seed_phi);
        double a_sum = -6.0 * omega_squared * rho * sin_beta * cos_3phi, m = VALUE(m_plunger);
        VALUE(a_plunger_sum) = a_sum;                                                        /* eq 20 */
        VALUE(Rz_out) = -6.0 * m * rho * omega_squared * tan_beta * cos_3phi;               /* eq 30 */
        seed_x = tan_beta * m * a_sum;                                                       /* eq 33 */
        seed_y = divide(&guard, -3.0 * m * rho * rho * omega_squared * tan_beta * sine(&guard, 6.0 * seed_phi),
                        l);                                                                  /* eq 34 */
        to_housing(&turn, &seed_x, &seed_y);
        VALUE(Rx_in) = seed_x;
        VALUE(Ry_in) = seed_y;
    }
    return guard.failure;
}

/* The warm start, the bend samples and the rates' choice are empty at the start, as
 * TripodCouplingModel.start leaves them: reset clears them and a refused start is undone. */
static Failure start(ModelData *data, double start_time)
{
    HAS_SOLUTION = 0.0;
    SAMPLE_COUNT = 0.0;
    RATES_SET = 0.0;
    VALUE(phi_in) = VALUE(phi_in_start);
    return evaluate(data, start_time, 0.0);
}

/* phi_in advances by omega_in h + alpha_in h^2 / 2 (TripodCouplingModel.advance). */
static Failure advance(ModelData *data, double current_time, double step_size)
{
    VALUE(phi_in) = VALUE(phi_in) + (VALUE(omega_in) + 0.5 * VALUE(alpha_in) * step_size) * step_size;
    return evaluate(data, current_time, step_size);
}

/* No warm start, no bend samples, no rates set (Model Exchange evaluates afresh each time). */
static void reset_internal(ModelData *data)
{
    HAS_SOLUTION = 0.0;
    SAMPLE_COUNT = 0.0;
    RATES_SET = 0.0;
}

/* The outputs at the current phi_in and inputs (TripodCouplingModel.evaluate). */
static Failure evaluate_now(ModelData *data, double time)
{
    return evaluate(data, time, 0.0);
}

/* TripodCouplingModel.extra_parameter_errors: friction, and the rollers' rolling resistance, need the exact
 * kinematics. */
static void extra_parameter_errors(const ModelData *data, Messages *out)
{
    if (VALUE(mu) > 0.0 && INTEGER(kinematics) != TRIPOD_SPEC_EXACT) {
        messages_add_extra(out, data, MESSAGE_friction_needs_exact);
    } else if (INTEGER(tripod_type) != TRIPOD_SPEC_PLAIN_TRIPOD && VALUE(mu_roll) > 0.0
               && INTEGER(kinematics) != TRIPOD_SPEC_EXACT) {
        messages_add_extra(out, data, MESSAGE_rollers_need_exact);
    }
}

/* TripodCouplingModel.start_notice: the automatic rates with none set are estimated, and the log says so. */
static const char *start_notice(const ModelData *data)
{
    return INTEGER(beta_rate) == RATES_AUTOMATIC && RATES_SET == 0.0 ? RATES_ESTIMATED : NULL;
}

/* The outputs' partial derivatives at the point the step has just computed (tripod_coupling/derivatives.h),
 * the exact closure's at the solution the step found there. */
static Failure jacobian(const ModelData *data, double partial[])
{
    return tripod_jacobian(data, INTEGER(kinematics) == TRIPOD_SPEC_EXACT ? SOLUTION + 1 : NULL, partial);
}

const ModelHooks model_hooks = {.reset_internal = reset_internal, .start = start, .advance = advance,
                                .evaluate = evaluate_now, .extra_parameter_errors = extra_parameter_errors,
                                .start_notice = start_notice, .jacobian = jacobian};
