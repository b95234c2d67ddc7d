/* The roller tripods' balance (driveline/tripod/rollers.py; eqs R1-R18 of docs/tripod_coupling.md): each
 * roller's contacts with its trunnion and its track, the single roller's contact normal by the Illinois method
 * on its bracket, the balance by successive substitution from the plain tripod's frictionless forces. Every
 * expression keeps the Python core's order of operations. */
#include "step.h"

#include "driveline_constants.h"
#include "illinois.h"

static const double PI = 3.141592653589793; /* math.pi */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

/* a / |a| into out (a zero vector stays zero), and |a| (rollers._unit) */
static double unit3(Guard *guard, const double a[3], double out[3])
{
    double size = root(guard, dot3(a, a)), by = size > 0.0 ? size : 1.0;
    out[0] = a[0] / by;
    out[1] = a[1] / by;
    out[2] = a[2] / by;
    return size;
}

/* numpy's remainder: the sign of the divisor */
static double remainder_of(double a, double b)
{
    double mod = fmod(a, b);
    if (mod != 0.0) {
        if ((b < 0.0) != (mod < 0.0)) {
            mod += b;
        }
    } else {
        mod = copysign(0.0, b);
    }
    return mod;
}

/* One arm's track contact (rollers.RollerContacts, the parts the balance needs), with the regularised signs
 * of its rolling and skew speeds. */
typedef struct {
    double k[3], N, u[3], across, s[3], v_roll, v_skew, roll_sign, skew_sign, F_roll, F_skew, miss, pushed[3];
} Contact;

/* The single roller on its track with contact normal at ``angle`` (rollers._skewed_slips and the
 * Illinois method's function in rollers._skewed_contact): slips, g's share and the miss of H's direction. */
static void skewed_slips(Guard *guard, const Load *load, const double axis[3], double zdot, const double spin[3],
                         double angle, double target, Contact *c)
{
    double R = load->roller_radius, along[3], turn[3], v0[3], g[3];
    int i;
    c->k[0] = cos(angle);
    c->k[1] = sin(angle);
    c->k[2] = 0.0;
    cross3(axis, c->k, along);
    c->across = unit3(guard, along, c->u);
    cross3(c->k, c->u, c->s);
    cross3(spin, c->k, turn);
    for (i = 0; i < 3; i++) {
        v0[i] = zdot * (i == 2 ? 1.0 : 0.0) - R * turn[i];
    }
    c->v_roll = dot3(v0, c->u) + R * c->across * dot3(spin, axis);
    c->v_skew = dot3(v0, c->s);
    c->roll_sign = slip_sign(guard, c->v_roll, load->slip_speed);
    c->skew_sign = slip_sign(guard, c->v_skew, load->slip_speed);
    for (i = 0; i < 3; i++) {
        g[i] = -load->mu_roll * c->roll_sign * c->u[i] - load->friction * c->skew_sign * c->s[i];
        c->pushed[i] = c->k[i] + g[i] * (i == 2 ? 0.0 : 1.0);
    }
    c->miss = remainder_of(atan2(c->pushed[1], c->pushed[0]) - target + PI, 2.0 * PI) - PI;
}

#define PROBES_KEPT 2 /* each arm's latest probes: the method ends on one of its brackets' ends, mostly recent */

/* What the miss of the step's contacts needs (illinois.h), and each arm's latest probes and their angles */
typedef struct {
    Guard *guard;
    const Load *load;
    const double (*axis)[3];
    const double *zdot, *spin, *target;
    Contact probe[3][PROBES_KEPT];
    double probe_angle[3][PROBES_KEPT];
    int probes[3];
} MissContext;

static double miss_at(void *context, int arm, double angle)
{
    MissContext *at = (MissContext *)context;
    int slot = at->probes[arm]++ % PROBES_KEPT;
    Contact *probe = &at->probe[arm][slot];
    at->probe_angle[arm][slot] = angle;
    skewed_slips(at->guard, at->load, at->axis[arm], at->zdot[arm], at->spin, angle, at->target[arm], probe);
    return probe->miss;
}

/* Arm ``arm``'s contact at ``angle``: a kept probe at the same angle, bit for bit (a zero's sign included), or
 * computed afresh. */
static void contact_at(MissContext *at, int arm, double angle, Contact *c)
{
    int k, kept = at->probes[arm] < PROBES_KEPT ? at->probes[arm] : PROBES_KEPT;
    for (k = 0; k < kept; k++) {
        double probed = at->probe_angle[arm][k];
        if (probed == angle && signbit(probed) == signbit(angle)) {
            *c = at->probe[arm][k];
            return;
        }
    }
    skewed_slips(at->guard, at->load, at->axis[arm], at->zdot[arm], at->spin, angle, at->target[arm], c);
}

/* The three single rollers' track contacts under the horizontal forces H (rollers._skewed_contact): the
 * normal's angle by the Illinois method on the bracket within asin(mu + mu_roll) of H's, all arms together. */
static void skewed_contacts(Guard *guard, const Load *load, const double H[3][3], const double axis[3][3],
                            const double zdot[3], const double spin[3], Contact c[3])
{
    double target[3], size[3], angle[3];
    MissContext context;
    int j;
    for (j = 0; j < 3; j++) {
        target[j] = atan2(H[j][1], H[j][0]);
        size[j] = root(guard, dot3(H[j], H[j]));
    }
    context.guard = guard;
    context.load = load;
    context.axis = axis;
    context.zdot = zdot;
    context.spin = spin;
    context.target = target;
    context.probes[0] = context.probes[1] = context.probes[2] = 0;
    illinois_angles(miss_at, &context, target, load->friction, load->mu_roll, angle);
    for (j = 0; j < 3; j++) {
        contact_at(&context, j, angle[j], &c[j]);
        c[j].N = size[j] / root(guard, dot3(c[j].pushed, c[j].pushed));
        c[j].F_roll = -load->mu_roll * c[j].N * c[j].roll_sign;
        c[j].F_skew = -load->friction * c[j].N * c[j].skew_sign;
    }
}


/* rollers.roller_reactions: the roller tripods' balance by successive substitution from the frictionless
 * lambda_j, mu_j (R5-R13), then the reactions (R14) and the dissipation (R15). */
void roller_reactions(Guard *guard, const Arm arm[3], const double adj[3][3], double inv_det,
                             const Load *load, const Shaft *shaft, double lam[3], double mu_q[3], Reactions *out)
{
    const double m = load->m, R = load->roller_radius, mu = load->friction;
    const double needle_share = load->roller_bore_radius / R; /* r_b / R */
    double centre[3][3], e[3][3], d[3][3], n[3][3], q[3][3], axis[3][3], length[3], groove_acc[3][3];
    double zdot[3], zddot[3], v_trunnion[3], trunnion_sign[3], roll_sign[3], n_norm[3], spin[3], load_moment[3];
    double friction_h[3][3];
    double N_trunnion[3], phi[3], force[3][3], friction[3][3], couple[3][3], H[3][3];
    double R_out[3] = {0.0, 0.0, 0.0}, R_in[3] = {0.0, 0.0, 0.0}, L[3] = {0.0, 0.0, 0.0}, power = 0.0;
    double relax = 1.0, last_lam[3] = {0.0, 0.0, 0.0}, last_mu[3] = {0.0, 0.0, 0.0};
    Contact c[3];
    int iteration, i, j;
    for (j = 0; j < 3; j++) {
        const Arm *a = &arm[j];
        centre[j][0] = a->gx;
        centre[j][1] = a->gy;
        centre[j][2] = a->bz;
        e[j][0] = a->ex;
        e[j][1] = a->ey;
        e[j][2] = a->ez;
        d[j][0] = a->dx;
        d[j][1] = a->dy;
        d[j][2] = a->dz;
        n[j][0] = a->ey;
        n[j][1] = -a->ex;
        n[j][2] = 0.0;
        cross3(e[j], n[j], q[j]);
        length[j] = unit3(guard, e[j], axis[j]);
        groove_acc[j][0] = a->ax;
        groove_acc[j][1] = a->ay;
        groove_acc[j][2] = 0.0;
        zdot[j] = a->zdot;
        zddot[j] = a->zddot;
        v_trunnion[j] = a->sigma * length[j];
        trunnion_sign[j] = slip_sign(guard, v_trunnion[j], load->slip_speed);
        /* the double roller rolls at zdot_j whatever the forces: its rolling sign is the iterations' constant */
        roll_sign[j] = load->tripod_type == TRIPOD_SPEC_SINGLE_ROLLER ? 0.0
                                                                       : slip_sign(guard, zdot[j], load->slip_speed);
        n_norm[j] = root(guard, a->exy2);
        friction_h[j][0] = friction_h[j][1] = friction_h[j][2] = 0.0;
    }
    for (i = 0; i < 3; i++) {
        spin[i] = shaft->W[i] - load->omega * (i == 2 ? 1.0 : 0.0);
        load_moment[i] = load->T_load * shaft->U[i];
    }
    for (iteration = 0; iteration < TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS && guard->failure.kind == ERROR_NONE;
         iteration++) {
        double new_lam[3], new_mu[3], moment[3], sums[3][3], change = 0.0, scale = 0.0;
        for (j = 0; j < 3; j++) {
            N_trunnion[j] = root(guard, arm[j].exy2 * (lam[j] * lam[j] + mu_q[j] * mu_q[j] * length[j] * length[j]));
            phi[j] = divide(guard, mu * N_trunnion[j] * trunnion_sign[j], length[j]);
            for (i = 0; i < 3; i++) {
                force[j][i] = lam[j] * n[j][i] + mu_q[j] * q[j][i] + phi[j] * e[j][i];
                H[j][i] = m * groove_acc[j][i] + force[j][i] * (i == 2 ? 0.0 : 1.0);
            }
        }
        if (load->tripod_type == TRIPOD_SPEC_SINGLE_ROLLER) {
            skewed_contacts(guard, load, (const double(*)[3])H, (const double(*)[3])axis, zdot, spin, c);
            for (j = 0; j < 3; j++) {
                double arm_k[3];
                for (i = 0; i < 3; i++) {
                    friction[j][i] = c[j].F_roll * c[j].u[i] + c[j].F_skew * c[j].s[i];
                    arm_k[i] = -R * c[j].k[i];
                }
                cross3(arm_k, friction[j], couple[j]);
                for (i = 0; i < 3; i++) {
                    couple[j][i] = couple[j][i] + R * c[j].F_roll * c[j].across * axis[j][i];
                }
            }
        } else {
            for (j = 0; j < 3; j++) {
                double lever[3]; /* k x a */
                c[j].N = unit3(guard, H[j], c[j].k);
                cross3(c[j].k, axis[j], lever);
                c[j].v_roll = zdot[j];
                c[j].v_skew = load->roller_bore_radius * (zdot[j] * axis[j][2] / R - dot3(spin, lever)); /* R16 */
                c[j].F_roll = -load->mu_roll * c[j].N * roll_sign[j];
                c[j].F_skew = -mu * c[j].N * slip_sign(guard, c[j].v_skew, load->slip_speed);
                for (i = 0; i < 3; i++) { /* R17, R18 */
                    friction[j][i] = (c[j].F_roll + needle_share * axis[j][2] * c[j].F_skew) * (i == 2 ? 1.0 : 0.0);
                    couple[j][i] = -load->roller_bore_radius * c[j].F_skew * lever[i];
                }
            }
        }
        for (j = 0; j < 3; j++) {
            double lever_q[3], lever_e[3];
            new_mu[j] = divide(guard, m * zddot[j] - friction[j][2] + phi[j] * e[j][2], arm[j].exy2);
            cross3(d[j], q[j], lever_q);
            cross3(d[j], e[j], lever_e);
            for (i = 0; i < 3; i++) {
                sums[0][i] = j ? sums[0][i] + new_mu[j] * lever_q[i] : new_mu[j] * lever_q[i];
                sums[1][i] = j ? sums[1][i] + phi[j] * lever_e[i] : phi[j] * lever_e[i];
                sums[2][i] = j ? sums[2][i] + couple[j][i] : couple[j][i];
            }
        }
        for (i = 0; i < 3; i++) {
            moment[i] = load_moment[i] - sums[0][i] - sums[1][i] - sums[2][i];
        }
        for (j = 0; j < 3; j++) {
            double change_h[3];
            new_lam[j] = dot3(moment, adj[j]) * inv_det;
            for (i = 0; i < 3; i++) {
                double h = friction[j][i] * (i == 2 ? 0.0 : 1.0);
                change_h[i] = h - friction_h[j][i];
                friction_h[j][i] = h;
            }
            change = change + (fabs(new_lam[j] - lam[j]) * n_norm[j] + fabs(new_mu[j] - mu_q[j]) * n_norm[j] * length[j]
                               + root(guard, dot3(change_h, change_h)));
            scale = scale + (N_trunnion[j] + c[j].N);
        }
        if (load->tripod_type != TRIPOD_SPEC_SINGLE_ROLLER) { /* the double roller's relaxation (rollers.py) */
            double last = 0.0, along = 0.0, ratio, shared;
            for (j = 0; j < 3; j++) {
                double step_lam = new_lam[j] - lam[j], step_mu = new_mu[j] - mu_q[j];
                double length2 = length[j] * length[j];
                last = last + arm[j].exy2 * (last_lam[j] * last_lam[j] + length2 * last_mu[j] * last_mu[j]);
                along = along + arm[j].exy2 * (step_lam * last_lam[j] + length2 * step_mu * last_mu[j]);
                last_lam[j] = step_lam;
                last_mu[j] = step_mu;
            }
            ratio = along / (last > 0.0 ? last : 1.0);
            shared = relax / (ratio < 1.0 ? 1.0 - ratio : 1.0);
            shared = ratio < 1.0 ? (1.0 < shared ? 1.0 : shared) : 0.5 * relax;
            relax = last > 0.0 ? shared : relax;
            for (j = 0; j < 3; j++) {
                new_lam[j] = lam[j] + relax * last_lam[j];
                new_mu[j] = mu_q[j] + relax * last_mu[j];
            }
        }
        for (j = 0; j < 3; j++) {
            lam[j] = new_lam[j];
            mu_q[j] = new_mu[j];
        }
        if (change <= TRIPOD_REACTIONS_FRICTION_TOLERANCE * scale) {
            break;
        }
    }
    if (iteration == TRIPOD_REACTIONS_MAX_FRICTION_ITERATIONS) {
        refuse(guard, ERROR_ARITHMETIC, ROLLERS_NOT_CONVERGED);
    }
    /* R14, R15: the track's force on roller j, T_j = m bddot_j + F_j, its moment about O with the couple */
    for (j = 0; j < 3; j++) {
        double track[3], moment_O[3], t[3], P;
        N_trunnion[j] = root(guard, arm[j].exy2 * (lam[j] * lam[j] + mu_q[j] * mu_q[j] * length[j] * length[j]));
        phi[j] = divide(guard, mu * N_trunnion[j] * trunnion_sign[j], length[j]);
        for (i = 0; i < 3; i++) {
            force[j][i] = lam[j] * n[j][i] + mu_q[j] * q[j][i] + phi[j] * e[j][i];
            track[i] = m * (groove_acc[j][i] + zddot[j] * (i == 2 ? 1.0 : 0.0)) + force[j][i];
        }
        cross3(centre[j], track, moment_O);
        cross3(shaft->U, e[j], t);
        for (i = 0; i < 3; i++) {
            R_out[i] = j ? R_out[i] - force[j][i] : -force[j][i];
            R_in[i] = j ? R_in[i] + track[i] : track[i];
            L[i] = j ? L[i] + (moment_O[i] + couple[j][i]) : moment_O[i] + couple[j][i];
        }
        out->F_arm[j] = divide(guard, dot3(force[j], t), root(guard, dot3(t, t)));
        out->F_plunger[j] = m * zddot[j];
        P = phi[j] * length[j] * v_trunnion[j] + -c[j].F_roll * c[j].v_roll + -c[j].F_skew * c[j].v_skew;
        power = j ? power + P : P;
    }
    out->Rx_in = R_in[0];
    out->Ry_in = R_in[1];
    out->Mx_in = L[0];
    out->My_in = L[1];
    out->T_in = L[2];
    out->Rx_out = dot3(R_out, shaft->E1);
    out->Ry_out = dot3(R_out, shaft->E2);
    out->Rz_out = dot3(R_out, shaft->U);
    out->a_plunger_sum = zddot[0] + zddot[1] + zddot[2];
    out->omega_spin = dot3(shaft->W, shaft->U);
    out->Rz_in = R_in[2];
    out->P_friction = power;
}

