/* Shaft segment elements (driveline/rotor/elements.py): the section's constants, the finite element
 * (fe_matrices) and the Krylov functions of the transfer matrices (seed Eqs. 16-23), shared by the
 * transfer-matrix (transfer.c) and finite-element (fem.c) models; the elements' own checks, which the
 * layout loader (layout.c) applies. */
#include "elements.h"

#include <math.h>
#include <stdio.h>


double segment_area(const RotorSegment *s)
{
    return FMU_PI / 4.0 * (pow(s->outer_diameter, 2.0) - pow(s->inner_diameter, 2.0));
}

double segment_second_moment(const RotorSegment *s)
{
    return FMU_PI / 64.0 * (pow(s->outer_diameter, 4.0) - pow(s->inner_diameter, 4.0));
}

double segment_shear_coefficient(const RotorSegment *s)
{
    double nu = s->poisson_ratio;
    double m2 = pow(s->inner_diameter / s->outer_diameter, 2.0);
    double r12 = pow(1.0 + m2, 2.0);
    return 6.0 * (1.0 + nu) * r12 / ((7.0 + 6.0 * nu) * r12 + (20.0 + 12.0 * nu) * m2);
}

double segment_shear_stiffness(const RotorSegment *s)
{
    return segment_shear_coefficient(s) * s->youngs_modulus / (2.0 * (1.0 + s->poisson_ratio)) * segment_area(s);
}

/* elements._symmetric_element times ``scale`` */
static void symmetric_element(double scale, double d11, double d12, double d13, double d14, double d22, double d23,
                              double d24, double out[16])
{
    const double entries[16] = {d11, d12, d13, d14, d12, d22, d23, d24, d13, d23, d11, -d12, d14, d24, -d12, d22};
    for (int i = 0; i < 16; i++) {
        out[i] = scale * entries[i];
    }
}

void segment_fe_element(const RotorSegment *s, double h, double k[16], double m[16], double g[16])
{
    double I = segment_second_moment(s);
    double EI = s->youngs_modulus * I;
    double rhoA = s->density * segment_area(s);
    double rhoI = s->density * I;
    double phi = s->shear ? 12.0 * EI / (segment_shear_stiffness(s) * h * h) : 0.0;
    double mt[16], mr[16];
    if (phi == 0.0) {
        double kh = EI / pow(h, 3.0), mh = rhoA * h / 420, rh = rhoI / (30 * h);
        const double ke[16] = {12, 6 * h, -12, 6 * h, 6 * h, 4 * h * h, -6 * h, 2 * h * h,
                               -12, -6 * h, 12, -6 * h, 6 * h, 2 * h * h, -6 * h, 4 * h * h};
        const double me[16] = {156, 22 * h, 54, -13 * h, 22 * h, 4 * h * h, 13 * h, -3 * h * h,
                               54, 13 * h, 156, -22 * h, -13 * h, -3 * h * h, -22 * h, 4 * h * h};
        const double re[16] = {36, 3 * h, -36, 3 * h, 3 * h, 4 * h * h, -3 * h, -h * h,
                               -36, -3 * h, 36, -3 * h, 3 * h, -h * h, -3 * h, 4 * h * h};
        for (int i = 0; i < 16; i++) {
            k[i] = kh * ke[i];
            mt[i] = mh * me[i];
            mr[i] = rh * re[i];
        }
    } else { /* elements._shear_element */
        double p2 = phi * phi;
        symmetric_element(EI / ((1 + phi) * pow(h, 3.0)), 12, 6 * h, -12, 6 * h, (4 + phi) * h * h, -6 * h,
                          (2 - phi) * h * h, k);
        symmetric_element(rhoA * h / pow(1 + phi, 2.0), 13.0 / 35 + 7 * phi / 10 + p2 / 3,
                          (11.0 / 210 + 11 * phi / 120 + p2 / 24) * h, 9.0 / 70 + 3 * phi / 10 + p2 / 6,
                          -(13.0 / 420 + 3 * phi / 40 + p2 / 24) * h, (1.0 / 105 + phi / 60 + p2 / 120) * h * h,
                          (13.0 / 420 + 3 * phi / 40 + p2 / 24) * h, -(1.0 / 140 + phi / 60 + p2 / 120) * h * h, mt);
        symmetric_element(rhoI / (pow(1 + phi, 2.0) * h), 6.0 / 5, (1.0 / 10 - phi / 2) * h, -6.0 / 5,
                          (1.0 / 10 - phi / 2) * h, (2.0 / 15 + phi / 6 + p2 / 3) * h * h, -(1.0 / 10 - phi / 2) * h,
                          (-1.0 / 30 - phi / 6 + p2 / 6) * h * h, mr);
    }
    for (int i = 0; i < 16; i++) {
        m[i] = s->rotary_inertia ? mt[i] + mr[i] : mt[i];
        g[i] = s->gyroscopic ? 2.0 * mr[i] : 0.0;
    }
}

/* ---- the Krylov functions of the transfer matrices -------------------------------------------- */

/* elements._sinh_minus_x_over_x3 */
static double sinh_minus_x_over_x3(double x)
{
    double x2;
    if (x >= ROTOR_ELEMENTS_SERIES_LIMIT) {
        return (sinh(x) - x) / pow(x, 3.0);
    }
    x2 = x * x;
    return 1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (1.0 / 5040.0 + x2 / 362880.0));
}

/* elements._x_minus_sin_over_x3 */
static double x_minus_sin_over_x3(double y)
{
    double y2;
    if (y >= ROTOR_ELEMENTS_SERIES_LIMIT) {
        return (y - sin(y)) / pow(y, 3.0);
    }
    y2 = y * y;
    return 1.0 / 6.0 - y2 * (1.0 / 120.0 - y2 * (1.0 / 5040.0 - y2 / 362880.0));
}

/* elements._cosh_minus_1_over_x2 */
static double cosh_minus_1_over_x2(double x)
{
    double h = 0.5 * x;
    double r = h == 0.0 ? 1.0 : sinh(h) / h;
    return 0.5 * r * r;
}

/* elements._1_minus_cos_over_y2 (numpy.sinc of y / (2 pi)) */
static double one_minus_cos_over_y2(double y)
{
    double t = y / (2.0 * FMU_PI);
    double u = FMU_PI * (t == 0.0 ? 1.0e-20 : t);
    double r = sin(u) / u;
    return 0.5 * r * r;
}

void element_betas(double a, double b, double *b1sq, double *b2sq)
{
    double r = sqrt(0.25 * a * a + b);
    double big2 = a >= 0.0 ? r + 0.5 * a : r - 0.5 * a;
    double small2 = big2 > 0.0 ? b / big2 : 0.0;
    *b1sq = a >= 0.0 ? small2 : big2;
    *b2sq = a >= 0.0 ? big2 : small2;
}

void element_krylov(double a, double b, double z, double C[4])
{
    double b1sq, b2sq, x, y, s, w1, w2, b_over_s, g1, g2, h1, h2, z2, z3;
    element_betas(a, b, &b1sq, &b2sq);
    x = sqrt(fabs(b1sq)) * z;
    y = sqrt(b2sq) * z;
    s = b1sq + b2sq;
    w1 = s > 0.0 ? b1sq / s : 0.5;
    w2 = s > 0.0 ? b2sq / s : 0.5;
    b_over_s = s > 0.0 ? b / s : 0.0;
    if (b1sq < 0.0) { /* a shear beam above its cut-off: trigonometric in |beta1| */
        g1 = x_minus_sin_over_x3(x);
        h1 = one_minus_cos_over_y2(x);
    } else {
        g1 = sinh_minus_x_over_x3(x);
        h1 = cosh_minus_1_over_x2(x);
    }
    g2 = x_minus_sin_over_x3(y);
    h2 = one_minus_cos_over_y2(y);
    z2 = z * z;
    z3 = pow(z, 3.0);
    C[0] = 1.0 + b_over_s * z2 * (h1 - h2);
    C[1] = z + b_over_s * z3 * (g1 - g2);
    C[2] = z2 * (w1 * h1 + w2 * h2);
    C[3] = z3 * (w1 * g1 + w2 * g2);
}

void beam_field_matrix(double z, double EI, double c, double a, double b, double H[4][4])
{
    double C[4], C1a, C0a, phi[4][4];
    int i, j;
    element_krylov(a, b, z, C);
    C1a = C[1] - a * C[3];
    C0a = C[0] - a * C[2];
    for (j = 0; j < 4; j++) {
        phi[0][j] = C[j];
    }
    phi[1][0] = b * C[3]; phi[1][1] = C[0]; phi[1][2] = C1a; phi[1][3] = C[2];
    phi[2][0] = b * C[2]; phi[2][1] = b * C[3]; phi[2][2] = C0a; phi[2][3] = C1a;
    phi[3][0] = b * C1a; phi[3][1] = b * C[2]; phi[3][2] = b * C[3] - a * C1a; phi[3][3] = C0a;
    for (j = 0; j < 4; j++) { /* s = S d */
        H[0][j] = phi[0][j];
        H[1][j] = phi[1][j];
        H[2][j] = EI * phi[2][j];
        H[3][j] = EI * phi[3][j] + c * phi[1][j];
    }
    for (i = 0; i < 4; i++) { /* ... times S^-1 */
        H[i][1] -= c / EI * H[i][3];
        H[i][2] /= EI;
        H[i][3] /= EI;
    }
}

/* ---- the elements' checks (their __post_init__) ------------------------------------------------ */

/* The message ``name`` ``rule``, got repr(value); ERROR_VALUE (Python's ValueError) */
static ErrorKind refused(const char *name, const char *rule, double value, char *error, size_t size)
{
    char shown[40];
    python_float_repr(value, shown, sizeof shown);
    if (error != NULL && size > 0) {
        snprintf(error, size, "%s%s, got %s", name, rule, shown);
    }
    return ERROR_VALUE;
}

/* elements._positive */
static ErrorKind element_positive(const char *name, double value, char *error, size_t size)
{
    return isfinite(value) && value > 0.0 ? ERROR_NONE : refused(name, " must be a finite number > 0", value, error,
                                                                   size);
}

ErrorKind element_non_negative(const char *name, double value, char *error, size_t size)
{
    return isfinite(value) && value >= 0.0 ? ERROR_NONE : refused(name, " must be a finite number >= 0", value, error,
                                                                    size);
}

ErrorKind segment_check(const RotorSegment *s, char *error, size_t size)
{
    ErrorKind failed;
    if ((failed = element_positive("length", s->length, error, size)) != ERROR_NONE ||
        (failed = element_positive("outer_diameter", s->outer_diameter, error, size)) != ERROR_NONE ||
        (failed = element_non_negative("inner_diameter", s->inner_diameter, error, size)) != ERROR_NONE) {
        return failed;
    }
    if (s->inner_diameter >= s->outer_diameter) {
        char inner[40], outer[40];
        python_float_repr(s->inner_diameter, inner, sizeof inner);
        python_float_repr(s->outer_diameter, outer, sizeof outer);
        if (error != NULL && size > 0) {
            snprintf(error, size, "inner_diameter (%s) must be smaller than outer_diameter (%s)", inner, outer);
        }
        return ERROR_VALUE;
    }
    if ((failed = element_positive("youngs_modulus", s->youngs_modulus, error, size)) != ERROR_NONE ||
        (failed = element_positive("density", s->density, error, size)) != ERROR_NONE) {
        return failed;
    }
    if (!(-1.0 < s->poisson_ratio && s->poisson_ratio < 0.5)) {
        return refused("poisson_ratio", " must lie in (-1, 0.5)", s->poisson_ratio, error, size);
    }
    return ERROR_NONE;
}

/* element_non_negative of ``count`` values in turn: the first refusal's kind, or ERROR_NONE */
static ErrorKind all_non_negative(const char *const names[], const double values[], int count, char *error,
                                  size_t size)
{
    ErrorKind failed = ERROR_NONE;
    for (int i = 0; i < count && failed == ERROR_NONE; i++) {
        failed = element_non_negative(names[i], values[i], error, size);
    }
    return failed;
}

ErrorKind mass_check(const RotorMass *m, char *error, size_t size)
{
    static const char *const names[] = {"mass", "polar_inertia", "diametral_inertia"};
    const double values[] = {m->mass, m->polar_inertia, m->diametral_inertia};
    return all_non_negative(names, values, 3, error, size);
}

ErrorKind bearing_check(const RotorBearing *b, char *error, size_t size)
{
    static const char *const names[] = {"kxx", "kyy", "cxx", "cyy"}, *const cross[] = {"kxy", "kyx", "cxy", "cyx"};
    const double values[] = {b->kxx, b->kyy, b->cxx, b->cyy}, coupling[] = {b->kxy, b->kyx, b->cxy, b->cyx};
    ErrorKind failed = all_non_negative(names, values, 4, error, size);
    for (int k = 0; k < 4 && failed == ERROR_NONE; k++) {
        if (!isfinite(coupling[k])) {
            failed = refused(cross[k], " must be a finite number", coupling[k], error, size);
        }
    }
    return failed;
}

ErrorKind unbalance_check(const RotorUnbalance *u, char *error, size_t size)
{
    static const char *const names[] = {"position", "amount"};
    const double values[] = {u->position, u->amount};
    ErrorKind failed = all_non_negative(names, values, 2, error, size);
    if (failed == ERROR_NONE && !isfinite(u->phase)) {
        failed = refused("phase", " must be a finite angle in rad", u->phase, error, size);
    }
    return failed;
}

/* Driveline.__post_init__'s check of a point element's node (``inner``: a hinge's) */
static ErrorKind check_node(const char *kind, int i, int node, int n_nodes, int inner, char *error, size_t size)
{
    if (node < 0 || node >= n_nodes) {
        if (error != NULL && size > 0) {
            snprintf(error, size, "%s[%d].node = %d is out of range: nodes are 0..%d", kind, i, node, n_nodes - 1);
        }
        return ERROR_VALUE;
    }
    if (inner && (node == 0 || node == n_nodes - 1)) {
        if (error != NULL && size > 0) {
            snprintf(error, size, "%s[%d].node = %d: a hinge must sit at an inner node (1..%d), not at an end", kind,
                     i, node, n_nodes - 2);
        }
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

ErrorKind driveline_check_nodes(const Driveline *d, char *error, size_t size)
{
    int n_nodes = d->n_segments + 1, i;
    ErrorKind failed = ERROR_NONE;
    for (i = 0; i < d->n_masses && failed == ERROR_NONE; i++) {
        failed = check_node("masses", i, d->masses[i].node, n_nodes, 0, error, size);
    }
    for (i = 0; i < d->n_bearings && failed == ERROR_NONE; i++) {
        failed = check_node("bearings", i, d->bearings[i].node, n_nodes, 0, error, size);
    }
    for (i = 0; i < d->n_hinges && failed == ERROR_NONE; i++) {
        failed = check_node("joints", i, d->hinges[i].node, n_nodes, 1, error, size);
    }
    return failed;
}
