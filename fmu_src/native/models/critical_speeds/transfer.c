/* Element transfer matrices and the scaled frequency determinant: a port of driveline/rotor/elements.py
 * (ShaftSegment, ConcentratedMass, Bearing, Hinge) and driveline/rotor/transfer.py (Chain, _propagate,
 * determinant, mode_shape's forward fraction); seed Eqs. 16-31.
 *
 * The state at a station is s = [U, psi, M, V] (elements.py), carried non-dimensionally as
 * s~_i = scale_i s_i. An isotropic chain propagates two columns of the 4-row state, an anisotropic one
 * four columns of the 8-row state [s_a, s_b] (forward and backward circular components). The basis is
 * re-orthonormalised after every piece of a segment (beta1 l <= 2) and the logarithm of the discarded
 * triangular factors is summed, so that nothing overflows. */
#include "rotor.h"

#include "elements.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#define JACOBI_SWEEPS 60

enum { POINT_MASS, POINT_BEARING, POINT_HINGE };

/* A point element: mass (mass, polar, diametral), bearing (mean stiffness, dk), hinge (stiffness). */
typedef struct {
    int kind;
    double p1, p2, p3;
} ChainPoint;

/* The constants of a ShaftSegment the transfer matrices use, computed once. */
typedef struct {
    double length, EI, mass_per_length, rho_I, shear_stiffness;
    int rotary_inertia, gyroscopic, shear;
} ChainSegment;

struct Chain {
    int n_segments;
    ChainSegment *segments;
    int *first;         /* points of node k: first[k] .. first[k + 1] - 1 */
    ChainPoint *points; /* in the order applied: masses, bearings, hinges */
    EndCondition left, right;
    int isotropic, freedoms;
    double kappa;
    double scale[4];    /* Chain.scale: [1/L0, 1, L0/EI0, L0^2/EI0] */
    double ratio[4][4]; /* scale_i / scale_j */
    int stations;       /* Chain.stations: nodes and point elements */
    Budget *budget;     /* what every propagation pays (budget.py), NULL: nothing */
};

/* The propagated basis: ``rows`` x ``cols`` (4 x 2 isotropic, 8 x 4 anisotropic). */
typedef struct {
    int rows, cols;
    double y[8][4];
} Basis;

/* mode_shape's trace, reduced to what the forward fraction needs: with c_k the coefficients of
 * snapshot k (_Trace.coefficients) and e the U rows, sum_k (e Y_k c_k)^2 = q^T G q, where G is built
 * forwards as G <- M^T G M + Y_k^T e^T e Y_k for the map M of each snapshot (c_prev = M c). */
typedef struct {
    int cols;
    double forward[4][4], backward[4][4];
} Gram;

/* ---- elements.ShaftSegment ------------------------------------------------------------------- */

/* ShaftSegment._couple: c = rho I w^2 - rho Ip Omega w, Ip = 2 I */
static double couple(const ChainSegment *seg, double w, double spin)
{
    double c = 0.0;
    if (seg->rotary_inertia) {
        c = c + seg->rho_I * w * w;
    }
    if (seg->gyroscopic) {
        c = c - 2.0 * seg->rho_I * spin * w;
    }
    return c;
}

/* a, b of lam^4 + a lam^2 - b (Rayleigh, or _shear_wave_coefficients) */
static void wave_coefficients(const ChainSegment *seg, double c, double w, double *a, double *b)
{
    if (seg->shear) {
        double inertia = seg->mass_per_length * w * w;
        *a = c / seg->EI + inertia / seg->shear_stiffness;
        *b = inertia * (1.0 - c / seg->shear_stiffness) / seg->EI;
    } else {
        *a = c / seg->EI;
        *b = seg->mass_per_length * w * w / seg->EI;
    }
}

/* ShaftSegment.beta1 (seed Eq. 22) */
static double beta1(const ChainSegment *seg, double w, double spin)
{
    double a, b, b1sq, b2sq;
    wave_coefficients(seg, couple(seg, w, spin), w, &a, &b);
    element_betas(a, b, &b1sq, &b2sq);
    return sqrt(b1sq > 0.0 ? b1sq : 0.0);
}

/* elements.shear_beam_field_matrix: expm(A l) = C0 + C1 A + C2 A^2 + C3 A^3 */
static void shear_beam_field_matrix(const ChainSegment *seg, double z, double c, double w, double a, double b,
                                    double H[4][4])
{
    double C[4], A[4][4] = {{0.0}}, power[4][4], next[4][4];
    int i, j, k, p;
    element_krylov(a, b, z, C);
    A[0][1] = 1.0;
    A[0][3] = -1.0 / seg->shear_stiffness;
    A[1][2] = 1.0 / seg->EI;
    A[2][1] = -c;
    A[2][3] = 1.0;
    A[3][0] = seg->mass_per_length * w * w;
    for (i = 0; i < 4; i++) {
        for (j = 0; j < 4; j++) {
            H[i][j] = C[0] * (i == j ? 1.0 : 0.0);
            power[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (p = 1; p < 4; p++) {
        for (i = 0; i < 4; i++) {
            for (j = 0; j < 4; j++) {
                double sum = 0.0;
                for (k = 0; k < 4; k++) {
                    sum += power[i][k] * A[k][j];
                }
                next[i][j] = sum;
            }
        }
        for (i = 0; i < 4; i++) {
            for (j = 0; j < 4; j++) {
                power[i][j] = next[i][j];
                H[i][j] = H[i][j] + C[p] * power[i][j];
            }
        }
    }
}

/* ShaftSegment.transfer_matrix over ``z``, scaled to the non-dimensional state (H * ratio) */
static void field_matrix(const Chain *chain, const ChainSegment *seg, double w, double spin, double z, double H[4][4])
{
    double c = couple(seg, w, spin), a, b;
    int i, j;
    wave_coefficients(seg, c, w, &a, &b);
    if (seg->shear) {
        shear_beam_field_matrix(seg, z, c, w, a, b, H);
    } else {
        beam_field_matrix(z, seg->EI, c, a, b, H);
    }
    for (i = 0; i < 4; i++) {
        for (j = 0; j < 4; j++) {
            H[i][j] *= chain->ratio[i][j];
        }
    }
}

/* ---- small dense linear algebra ------------------------------------------------------------- */

/* x <- (I - tau v v^T) x for the reflector v = [0..0, 1, V[k+1..m-1][k]] of column k; x[i * stride] is row i */
static void reflect(int m, int k, double V[8][4], double tau, double *x, int stride)
{
    int i;
    double s = x[k * stride];
    for (i = k + 1; i < m; i++) {
        s += V[i][k] * x[i * stride];
    }
    s *= tau;
    x[k * stride] -= s;
    for (i = k + 1; i < m; i++) {
        x[i * stride] -= s * V[i][k];
    }
}

/* Householder QR of the m x n (n <= m <= 8, n <= 4) matrix A as LAPACK's dgeqrf: A is overwritten
 * by R in its upper triangle, v (below the diagonal) and tau hold the reflectors. Returns the number
 * of non-trivial reflectors (det Q = (-1)^that). */
static int householder(int m, int n, double A[8][4], double tau[4])
{
    int i, j, k, reflections = 0;
    for (j = 0; j < n; j++) {
        double alpha = A[j][j], xnorm = 0.0, norm, beta, scale;
        for (i = j + 1; i < m; i++) {
            xnorm += A[i][j] * A[i][j];
        }
        xnorm = sqrt(xnorm);
        if (xnorm == 0.0) {
            tau[j] = 0.0;
            continue;
        }
        norm = fabs(alpha) > xnorm ? fabs(alpha) * sqrt(1.0 + (xnorm / alpha) * (xnorm / alpha))
                                   : xnorm * sqrt(1.0 + (alpha / xnorm) * (alpha / xnorm));
        beta = -copysign(norm, alpha);
        tau[j] = (beta - alpha) / beta;
        scale = 1.0 / (alpha - beta);
        for (i = j + 1; i < m; i++) {
            A[i][j] *= scale;
        }
        A[j][j] = beta;
        reflections++;
        for (k = j + 1; k < n; k++) { /* the remaining columns */
            reflect(m, j, A, tau[j], &A[0][k], 4);
        }
    }
    return reflections;
}

/* The first ``cols`` columns of Q = H_0 ... H_{n-1} from householder()'s reflectors (dorgqr). */
static void householder_q(int m, int n, int cols, double V[8][4], const double tau[4], double Q[8][8])
{
    int i, j, k;
    for (i = 0; i < m; i++) {
        for (j = 0; j < cols; j++) {
            Q[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (k = n - 1; k >= 0; k--) {
        if (tau[k] == 0.0) {
            continue;
        }
        for (j = 0; j < cols; j++) {
            reflect(m, k, V, tau[k], &Q[0][j], 8);
        }
    }
}

/* transfer._orthonormalize: Y = Q R, Q orthonormal, R with a positive diagonal; returns log det R
 * (transfer._log_det) and R in ``R`` (upper triangle). */
static double orthonormalize(Basis *Y, double R[4][4])
{
    int i, j, k;
    if (Y->cols == 2) { /* Gram-Schmidt in closed form */
        double n1 = 0.0, r12 = 0.0, n2 = 0.0, y2[8];
        for (i = 0; i < Y->rows; i++) {
            n1 += Y->y[i][0] * Y->y[i][0];
        }
        n1 = sqrt(n1);
        for (i = 0; i < Y->rows; i++) {
            Y->y[i][0] = Y->y[i][0] / n1;
            r12 += Y->y[i][0] * Y->y[i][1];
        }
        for (i = 0; i < Y->rows; i++) {
            y2[i] = Y->y[i][1] - r12 * Y->y[i][0];
            n2 += y2[i] * y2[i];
        }
        n2 = sqrt(n2);
        for (i = 0; i < Y->rows; i++) {
            Y->y[i][1] = y2[i] / n2;
        }
        R[0][0] = n1; R[0][1] = r12; R[1][0] = 0.0; R[1][1] = n2;
        return log(n1) + log(n2);
    } else { /* Householder QR, signs turned to a positive diagonal */
        double A[8][4], tau[4], Q[8][8], log_det = 0.0;
        for (i = 0; i < Y->rows; i++) {
            for (j = 0; j < Y->cols; j++) {
                A[i][j] = Y->y[i][j];
            }
        }
        householder(Y->rows, Y->cols, A, tau);
        householder_q(Y->rows, Y->cols, Y->cols, A, tau, Q);
        for (j = 0; j < Y->cols; j++) {
            double d = A[j][j] < 0.0 ? -1.0 : 1.0;
            for (i = 0; i < Y->rows; i++) {
                Y->y[i][j] = Q[i][j] * d;
            }
            for (k = 0; k < Y->cols; k++) {
                R[j][k] = k < j ? 0.0 : A[j][k] * d;
            }
            log_det += log(R[j][j]);
        }
        return log_det;
    }
}

/* det of the n x n matrix A (n <= 4) as numpy.linalg.det: LU with partial pivoting, sign * exp(sum log|u_ii|) */
static double lu_det(int n, double A[4][4])
{
    int i, j, k;
    double sign = 1.0, log_abs = 0.0;
    for (k = 0; k < n; k++) {
        int p = k;
        for (i = k + 1; i < n; i++) {
            if (fabs(A[i][k]) > fabs(A[p][k])) {
                p = i;
            }
        }
        if (p != k) {
            for (j = 0; j < n; j++) {
                double t = A[k][j];
                A[k][j] = A[p][j];
                A[p][j] = t;
            }
            sign = -sign;
        }
        if (A[k][k] == 0.0) {
            return 0.0;
        }
        for (i = k + 1; i < n; i++) {
            double l = A[i][k] / A[k][k];
            for (j = k + 1; j < n; j++) {
                A[i][j] -= l * A[k][j];
            }
        }
        if (A[k][k] < 0.0) {
            sign = -sign;
        }
        log_abs += log(fabs(A[k][k]));
    }
    return sign * exp(log_abs);
}

/* ---- point elements: ConcentratedMass, Bearing, Hinge.propagate ----------------------------- */

/* ConcentratedMass.transfer_matrix (seed Eq. 25): M+ = M- - (Jd w^2 - Jp Omega w) psi, V+ = V- + m w^2 U,
 * on the component whose rows start at ``o`` */
static void apply_mass(const Chain *chain, const ChainPoint *p, double w, double spin, Basis *Y, int o)
{
    double p21 = -(p->p3 * w * w - p->p2 * spin * w) * chain->ratio[2][1];
    double p30 = p->p1 * w * w * chain->ratio[3][0];
    int j;
    for (j = 0; j < Y->cols; j++) {
        Y->y[o + 2][j] = p21 * Y->y[o + 1][j] + Y->y[o + 2][j];
        Y->y[o + 3][j] = p30 * Y->y[o][j] + Y->y[o + 3][j];
    }
}

/* Bearing.transfer_matrix (seed Eq. 27: V+ = V- - kbar U) and transfer_matrix_pair (dk couples a and b) */
static void apply_bearing(const Chain *chain, const ChainPoint *p, Basis *Y)
{
    double k = -p->p1 * chain->ratio[3][0];
    int j;
    if (Y->rows == 4) {
        for (j = 0; j < Y->cols; j++) {
            Y->y[3][j] = k * Y->y[0][j] + Y->y[3][j];
        }
    } else {
        double dk = -p->p2 * chain->ratio[3][0];
        for (j = 0; j < Y->cols; j++) {
            double a = Y->y[0][j], b = Y->y[4][j];
            Y->y[3][j] = k * a + Y->y[3][j] + dk * b;
            Y->y[7][j] = dk * a + k * b + Y->y[7][j];
        }
    }
}

/* Hinge.propagate: Y_after = P Y T with the full QR m^T = [Q1 Q2] [R1; 0] of the moment rows m,
 * T = [Q2, k Q1]; returns the sign det[Q2 Q1] and T (cols x cols). */
static double apply_hinge(const Chain *chain, const ChainPoint *p, Basis *Y, double T[4][4])
{
    int r = Y->rows == 4 ? 1 : 2, cols = Y->cols, i, j, l, reflections;
    double k = p->p1 / chain->ratio[1][2]; /* scaled: psi~ jumps by M~ ratio[1, 2] / k */
    double A[8][4], tau[4], Q[8][8], after[8][4] = {{0.0}};
    for (i = 0; i < cols; i++) { /* m^T: cols x r */
        for (j = 0; j < r; j++) {
            A[i][j] = Y->y[4 * j + 2][i];
        }
    }
    reflections = householder(cols, r, A, tau);
    householder_q(cols, r, cols, A, tau, Q);
    for (i = 0; i < cols; i++) {
        for (j = 0; j < cols; j++) {
            T[i][j] = j < cols - r ? Q[i][j + r] : k * Q[i][j - (cols - r)];
        }
    }
    for (i = 0; i < Y->rows; i++) {
        for (j = 0; j < cols; j++) {
            double s = 0.0;
            for (l = 0; l < cols; l++) {
                s += Y->y[i][l] * T[l][j];
            }
            after[i][j] = s;
        }
    }
    for (j = 0; j < r; j++) { /* the slope jumps E R1^T */
        for (i = 0; i < r; i++) {
            after[4 * i + 1][cols - r + j] += j <= i ? A[j][i] : 0.0; /* R1 is upper triangular */
        }
    }
    for (i = 0; i < Y->rows; i++) {
        for (j = 0; j < cols; j++) {
            Y->y[i][j] = after[i][j];
        }
    }
    return ((reflections % 2) ? -1.0 : 1.0) * (((r * (cols - r)) % 2) ? -1.0 : 1.0);
}

/* ---- the trace of mode_shape as Gram matrices ------------------------------------------------ */

/* M <- M R^-1 for upper triangular R (n x n) */
static void right_solve(int n, double M[4][4], double R[4][4])
{
    int i, j, k;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            double s = M[i][j];
            for (k = 0; k < j; k++) {
                s -= M[i][k] * R[k][j];
            }
            M[i][j] = s / R[j][j];
        }
    }
}

static void transpose(int n, double M[4][4])
{
    int i, j;
    for (i = 0; i < n; i++) {
        for (j = i + 1; j < n; j++) {
            double t = M[i][j];
            M[i][j] = M[j][i];
            M[j][i] = t;
        }
    }
}

static void mat_product(int n, double A[4][4], double B[4][4])
{ /* A <- A B */
    double C[4][4];
    int i, j, k;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            double s = 0.0;
            for (k = 0; k < n; k++) {
                s += A[i][k] * B[k][j];
            }
            C[i][j] = s;
        }
    }
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            A[i][j] = C[i][j];
        }
    }
}

/* G <- M^T G M for the snapshot map: R^-1 ("solve") or T ("multiply") */
static void gram_map(int n, double G[4][4], double R[4][4], double T[4][4])
{
    if (R != NULL) {
        right_solve(n, G, R); /* G R^-1 */
        transpose(n, G);
        right_solve(n, G, R); /* (G R^-1)^T R^-1 = R^-T G R^-1 (G symmetric) */
    } else if (T != NULL) {
        mat_product(n, G, T); /* G T */
        transpose(n, G);
        mat_product(n, G, T); /* (G T)^T T = T^T G T */
    }
}

/* _Trace.add: a snapshot Y with the map to the previous one */
static void trace_add(Gram *g, const Basis *Y, double R[4][4], double T[4][4])
{
    int i, j;
    if (g == NULL) {
        return;
    }
    gram_map(Y->cols, g->forward, R, T);
    gram_map(Y->cols, g->backward, R, T);
    for (i = 0; i < Y->cols; i++) {
        for (j = 0; j < Y->cols; j++) {
            g->forward[i][j] += Y->y[0][i] * Y->y[0][j];
            if (Y->rows == 8) {
                g->backward[i][j] += Y->y[4][i] * Y->y[4][j];
            }
        }
    }
}

/* ---- transfer._propagate ----------------------------------------------------------------------- */

static const int FREE_COMPONENTS[3][2] = {{0, 1}, {1, 3}, {2, 3}}; /* EndCondition.free_components */
static const int ZERO_COMPONENTS[3][2] = {{2, 3}, {0, 2}, {0, 1}}; /* EndCondition.zero_components */

/* the point elements at node ``k`` (_propagate.points): returns whether a T was formed */
static int apply_points(const Chain *chain, int node, double w, double spin, Basis *Y, double *sign, double T[4][4])
{
    int e, formed = 0;
    for (e = chain->first[node]; e < chain->first[node + 1]; e++) {
        const ChainPoint *p = &chain->points[e];
        if (p->kind == POINT_MASS) {
            apply_mass(chain, p, w, spin, Y, 0);
            if (Y->rows == 8) {
                apply_mass(chain, p, -w, spin, Y, 4);
            }
        } else if (p->kind == POINT_BEARING) {
            apply_bearing(chain, p, Y);
        } else {
            double Te[4][4];
            *sign = *sign * apply_hinge(chain, p, Y, Te);
            if (formed) {
                mat_product(Y->cols, T, Te);
            } else {
                int i, j;
                for (i = 0; i < Y->cols; i++) {
                    for (j = 0; j < Y->cols; j++) {
                        T[i][j] = Te[i][j];
                    }
                }
                formed = 1;
            }
        }
    }
    return formed;
}

/* H Y for the (block-diagonal) field matrices: Hf on the forward rows, Hb on the backward ones */
static void field_product(double Hf[4][4], double Hb[4][4], Basis *Y)
{
    double out[8][4];
    int i, j, k, b;
    for (b = 0; b < Y->rows; b += 4) {
        double (*H)[4] = b == 0 ? Hf : Hb;
        for (i = 0; i < 4; i++) {
            for (j = 0; j < Y->cols; j++) {
                double s = 0.0;
                for (k = 0; k < 4; k++) {
                    s += H[i][k] * Y->y[b + k][j];
                }
                out[b + i][j] = s;
            }
        }
    }
    for (i = 0; i < Y->rows; i++) {
        for (j = 0; j < Y->cols; j++) {
            Y->y[i][j] = out[i][j];
        }
    }
}

/* transfer._propagate for one (w, spin): the orthonormal Y_N, its log scale and sign; every segment cut into
 * extra_pieces more pieces than it needs (the same in exact arithmetic, other round-off) */
static void propagate(const Chain *chain, double w, double spin, int min_pieces, int extra_pieces, Basis *Y,
                      double *log_scale, double *sign, Gram *trace)
{
    int pair = !chain->isotropic, k, i, j, piece_count, per_step = pair ? ROTOR_BUDGET_ANISOTROPIC_STEP : 1;
    const int *free_rows = FREE_COMPONENTS[chain->left];
    double R[4][4], T[4][4];
    Y->rows = pair ? 8 : 4;
    Y->cols = pair ? 4 : 2;
    for (i = 0; i < Y->rows; i++) { /* transfer._initial */
        for (j = 0; j < Y->cols; j++) {
            Y->y[i][j] = 0.0;
        }
    }
    for (j = 0; j < Y->cols; j++) {
        Y->y[4 * (j / 2) + free_rows[j % 2]][j] = 1.0;
    }
    *log_scale = 0.0;
    *sign = 1.0;
    budget_charge(chain->budget, (long long)per_step * chain->stations);
    trace_add(trace, Y, NULL, NULL);
    for (k = 0; k < chain->n_segments; k++) {
        const ChainSegment *seg = &chain->segments[k];
        double growth, Hf[4][4], Hb[4][4], piece, phase;
        int formed = apply_points(chain, k, w, spin, Y, sign, T);
        trace_add(trace, Y, NULL, formed ? T : NULL);
        growth = beta1(seg, w, spin);
        *log_scale -= growth * seg->length;
        if (pair) { /* the backward component grows with beta1(-w) */
            double backward = beta1(seg, -w, spin);
            *log_scale -= backward * seg->length;
            growth = growth > backward ? growth : backward;
        }
        phase = ceil(growth * seg->length / ROTOR_TRANSFER_MAX_PIECE_PHASE);
        piece_count = phase > 1.0 ? (int)phase : 1;
        if (piece_count < min_pieces) {
            piece_count = min_pieces;
        }
        piece_count += extra_pieces;
        budget_charge(chain->budget, (long long)per_step * piece_count);
        piece = seg->length / piece_count;
        field_matrix(chain, seg, w, spin, piece, Hf);
        if (pair) {
            field_matrix(chain, seg, -w, spin, piece, Hb);
        }
        for (i = 0; i < piece_count; i++) {
            field_product(Hf, Hb, Y);
            *log_scale += orthonormalize(Y, R);
            trace_add(trace, Y, R, NULL);
        }
    }
    if (apply_points(chain, chain->n_segments, w, spin, Y, sign, T)) {
        trace_add(trace, Y, NULL, T);
    }
    *log_scale += orthonormalize(Y, R);
    trace_add(trace, Y, R, NULL);
}

/* the end-condition rows of Y (transfer._final_rows), square */
static int final_rows(const Chain *chain, const Basis *Y, double S[4][4])
{
    const int *zero = ZERO_COMPONENTS[chain->right];
    int i, j;
    for (i = 0; i < Y->cols; i++) {
        for (j = 0; j < Y->cols; j++) {
            S[i][j] = Y->y[4 * (i / 2) + zero[i % 2]][j];
        }
    }
    return Y->cols;
}

/* the sum of the magnitudes of the 24 terms of the 4x4 determinant of S, its permutations in lexicographic
 * order summed as numpy sums 24 numbers (eight running sums, combined pairwise) */
static double determinant_terms(double S[4][4])
{
    double r[8] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    int a, b, c, term = 0;
    for (a = 0; a < 4; a++) {
        for (b = 0; b < 4; b++) {
            for (c = 0; c < 4 && b != a; c++) {
                if (c != a && c != b) {
                    r[term % 8] += fabs(S[0][a] * S[1][b] * S[2][c] * S[3][6 - a - b - c]);
                    term++;
                }
            }
        }
    }
    return ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
}

/* transfer.determinant_and_rounding with extra_pieces (rounding NULL: transfer.determinant) */
void chain_determinant_cut(const Chain *chain, size_t n, const double *w, const double *spin, int extra_pieces,
                           double *f, double *rounding)
{
    size_t i;
    for (i = 0; i < n; i++) {
        Basis Y;
        double log_scale, sign, S[4][4], d, terms, factor;
        if (chain_budget_spent(chain)) { /* the caller stops: no work after the budget */
            f[i] = 0.0;
            if (rounding != NULL) {
                rounding[i] = 0.0;
            }
            continue;
        }
        propagate(chain, w[i], spin[i], 1, extra_pieces, &Y, &log_scale, &sign, NULL);
        final_rows(chain, &Y, S);
        if (chain->isotropic) {
            d = S[0][0] * S[1][1] - S[0][1] * S[1][0];
            terms = fabs(S[0][0] * S[1][1]) + fabs(S[0][1] * S[1][0]);
        } else {
            terms = determinant_terms(S);
            d = lu_det(4, S);
        }
        if (log_scale > ROTOR_TRANSFER_LOG_SCALE_CLIP) { /* keep the factor finite; sign and zeros are unaffected */
            log_scale = ROTOR_TRANSFER_LOG_SCALE_CLIP;
        } else if (log_scale < -ROTOR_TRANSFER_LOG_SCALE_CLIP) {
            log_scale = -ROTOR_TRANSFER_LOG_SCALE_CLIP;
        }
        factor = exp(log_scale);
        f[i] = sign * d * factor;
        if (rounding != NULL) {
            rounding[i] = DBL_EPSILON * terms * factor;
        }
    }
}

/* transfer.determinant_and_rounding (rounding NULL: transfer.determinant) */
void chain_determinant_rounding(const Chain *chain, size_t n, const double *w, const double *spin, double *f,
                                double *rounding)
{
    chain_determinant_cut(chain, n, w, spin, 0, f, rounding);
}

/* transfer.determinant */
void chain_determinant(const Chain *chain, size_t n, const double *w, const double *spin, double *f)
{
    chain_determinant_cut(chain, n, w, spin, 0, f, NULL);
}

/* The right singular vector of the smallest singular value of the n x n matrix A (one-sided Jacobi). */
static void null_vector(int n, double A[4][4], double q[4])
{
    double V[4][4];
    int i, j, p, r, sweep, best = 0;
    double smallest = HUGE_VAL;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            V[i][j] = i == j ? 1.0 : 0.0;
        }
    }
    for (sweep = 0; sweep < JACOBI_SWEEPS; sweep++) {
        int rotated = 0;
        for (p = 0; p < n - 1; p++) {
            for (r = p + 1; r < n; r++) {
                double alpha = 0.0, beta = 0.0, gamma = 0.0, zeta, t, c, s;
                for (i = 0; i < n; i++) {
                    alpha += A[i][p] * A[i][p];
                    beta += A[i][r] * A[i][r];
                    gamma += A[i][p] * A[i][r];
                }
                if (gamma == 0.0 || fabs(gamma) <= 1e-15 * sqrt(alpha * beta)) {
                    continue;
                }
                rotated = 1;
                zeta = (beta - alpha) / (2.0 * gamma);
                t = (zeta >= 0.0 ? 1.0 : -1.0) / (fabs(zeta) + sqrt(1.0 + zeta * zeta));
                c = 1.0 / sqrt(1.0 + t * t);
                s = c * t;
                for (i = 0; i < n; i++) {
                    double ap = A[i][p], ar = A[i][r], vp = V[i][p], vr = V[i][r];
                    A[i][p] = c * ap - s * ar;
                    A[i][r] = s * ap + c * ar;
                    V[i][p] = c * vp - s * vr;
                    V[i][r] = s * vp + c * vr;
                }
            }
        }
        if (!rotated) {
            break;
        }
    }
    for (j = 0; j < n; j++) {
        double norm = 0.0;
        for (i = 0; i < n; i++) {
            norm += A[i][j] * A[i][j];
        }
        if (norm < smallest) {
            smallest = norm;
            best = j;
        }
    }
    for (i = 0; i < n; i++) {
        q[i] = V[i][best];
    }
}

static double quadratic_form(int n, double G[4][4], const double q[4])
{
    double s = 0.0;
    int i, j;
    for (i = 0; i < n; i++) {
        for (j = 0; j < n; j++) {
            s += q[i] * G[i][j] * q[j];
        }
    }
    return s;
}

/* transfer.mode_shape(chain, w, spin, 4).forward_fraction: the null vector q of the end rows mapped
 * back through every snapshot (_Trace.coefficients), sum |U_a|^2 / (sum |U_a|^2 + sum |U_b|^2). */
double chain_forward_fraction(const Chain *chain, double w, double spin)
{
    Basis Y;
    Gram g = {0, {{0.0}}, {{0.0}}};
    double log_scale, sign, S[4][4], q[4], ef, eb;
    propagate(chain, w, spin, ROTOR_DRIVELINE_DIRECTION_POINTS, 0, &Y, &log_scale, &sign, &g);
    final_rows(chain, &Y, S);
    null_vector(Y.cols, S, q);
    ef = quadratic_form(Y.cols, g.forward, q);
    eb = Y.rows == 8 ? quadratic_form(Y.cols, g.backward, q) : 0.0;
    if (chain->isotropic && w < 0.0) {
        double t = ef;
        ef = eb;
        eb = t;
    }
    return ef + eb > 0.0 ? ef / (ef + eb) : NAN;
}

/* ---- transfer.Chain ------------------------------------------------------------------------------ */

void chain_free(Chain *chain)
{
    if (chain != NULL) {
        free(chain->segments);
        free(chain->first);
        free(chain->points);
        free(chain);
    }
}

/* ShaftSegment's derived constants the transfer matrices use */
static void segment_constants(const RotorSegment *s, ChainSegment *out)
{
    double area = segment_area(s), second_moment = segment_second_moment(s);
    out->length = s->length;
    out->EI = s->youngs_modulus * second_moment;
    out->mass_per_length = s->density * area;
    out->rho_I = s->density * second_moment;
    out->shear_stiffness = segment_shear_stiffness(s);
    out->rotary_inertia = s->rotary_inertia;
    out->gyroscopic = s->gyroscopic;
    out->shear = s->shear;
}

/* transfer.Chain.build (with Driveline's node checks and the freedoms _grid counts) */
ErrorKind chain_new(const Driveline *driveline, Chain **out, char *error, size_t size)
{
    Chain *chain;
    int n_nodes, n_points, i, k, at;
    double L0 = 0.0, EI0;
    ErrorKind failed;
    *out = NULL;
    if (driveline->n_segments < 1 || driveline->segments == NULL) {
        ROTOR_ERROR(error, size, "segments: a driveline needs at least one shaft segment");
        return ERROR_VALUE;
    }
    if ((unsigned)driveline->left > END_CLAMPED || (unsigned)driveline->right > END_CLAMPED) {
        ROTOR_ERROR(error, size, "end condition is not one of: free, pinned, clamped");
        return ERROR_VALUE;
    }
    n_nodes = driveline->n_segments + 1;
    if ((failed = driveline_check_nodes(driveline, error, size)) != ERROR_NONE) {
        return failed;
    }
    for (i = 0; i < driveline->n_bearings; i++) {
        const RotorBearing *b = &driveline->bearings[i];
        if (b->kxy != 0.0 || b->kyx != 0.0) { /* Bearing._undamped_stiffness */
            ROTOR_ERROR(error, size,
                        "cross-coupled bearing stiffness (kxy, kyx) enters the damped analyses only, not the undamped "
                        "transfer matrices");
            return ERROR_VALUE;
        }
    }
    n_points = driveline->n_masses + driveline->n_bearings + driveline->n_hinges;
    chain = malloc(sizeof *chain);
    if (chain == NULL) {
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    chain->segments = malloc((size_t)driveline->n_segments * sizeof *chain->segments);
    chain->first = malloc((size_t)(n_nodes + 1) * sizeof *chain->first);
    chain->points = malloc((size_t)(n_points > 0 ? n_points : 1) * sizeof *chain->points);
    if (chain->segments == NULL || chain->first == NULL || chain->points == NULL) {
        chain_free(chain);
        ROTOR_ERROR(error, size, ROTOR_OUT_OF_MEMORY);
        return ERROR_VALUE;
    }
    chain->n_segments = driveline->n_segments;
    chain->stations = n_nodes + n_points;
    chain->budget = NULL;
    chain->left = driveline->left;
    chain->right = driveline->right;
    chain->isotropic = 1;
    chain->kappa = 0.0;
    for (k = 0; k < driveline->n_segments; k++) {
        ChainSegment *seg = &chain->segments[k];
        segment_constants(&driveline->segments[k], seg);
        L0 += seg->length;
        chain->kappa += seg->length * pow(seg->mass_per_length / seg->EI, 0.25); /* Driveline._kappa */
    }
    L0 = L0 / driveline->n_segments;
    EI0 = chain->segments[0].EI;
    chain->scale[0] = 1.0 / L0;
    chain->scale[1] = 1.0;
    chain->scale[2] = L0 / EI0;
    chain->scale[3] = L0 * L0 / EI0;
    for (i = 0; i < 4; i++) {
        for (k = 0; k < 4; k++) {
            chain->ratio[i][k] = chain->scale[i] / chain->scale[k];
        }
    }
    /* the point elements by node: masses, bearings, hinges, each in the order given */
    at = 0;
    chain->freedoms = 0;
    for (k = 0; k < n_nodes; k++) {
        int translation = 0, tilt = 0, hinge = 0;
        chain->first[k] = at;
        for (i = 0; i < driveline->n_masses; i++) {
            const RotorMass *m = &driveline->masses[i];
            if (m->node == k) {
                ChainPoint *p = &chain->points[at++];
                p->kind = POINT_MASS;
                p->p1 = m->mass;
                p->p2 = m->polar_inertia;
                p->p3 = m->diametral_inertia;
                translation |= m->mass > 0.0;
                tilt |= m->diametral_inertia > 0.0 || m->polar_inertia > 0.0;
            }
        }
        for (i = 0; i < driveline->n_bearings; i++) {
            const RotorBearing *b = &driveline->bearings[i];
            if (b->node == k) {
                ChainPoint *p = &chain->points[at++];
                p->kind = POINT_BEARING;
                p->p1 = 0.5 * (b->kxx + b->kyy);
                p->p2 = 0.5 * (b->kxx - b->kyy);
                p->p3 = 0.0;
                if (b->kyy != b->kxx) {
                    chain->isotropic = 0;
                }
            }
        }
        for (i = 0; i < driveline->n_hinges; i++) {
            const RotorHinge *h = &driveline->hinges[i];
            if (h->node == k) {
                ChainPoint *p = &chain->points[at++];
                p->kind = POINT_HINGE;
                p->p1 = h->bending_stiffness;
                p->p2 = p->p3 = 0.0;
                hinge = 1;
            }
        }
        chain->freedoms += translation + tilt + hinge; /* Driveline._grid: distinct freedoms per node */
    }
    chain->first[n_nodes] = at;
    *out = chain;
    return ERROR_NONE;
}

int chain_isotropic(const Chain *chain)
{
    return chain->isotropic;
}

double chain_kappa(const Chain *chain)
{
    return chain->kappa;
}

int chain_freedoms(const Chain *chain)
{
    return chain->freedoms;
}

void chain_set_budget(Chain *chain, Budget *budget)
{
    chain->budget = budget;
}

int chain_budget_spent(const Chain *chain)
{
    return chain->budget != NULL && chain->budget->spent;
}

int chain_stations(const Chain *chain)
{
    return chain->stations;
}

/* budget.Budget.charge: pays ``units``, or marks the budget spent (sticky) when they exceed what is left */
void budget_charge(Budget *budget, long long units)
{
    if (budget == NULL || budget->spent) {
        return;
    }
    if (units > budget->left) {
        budget->left = -1;
        budget->spent = 1;
        budget->spent_in = budget->stage;
        return;
    }
    budget->left -= units;
}
