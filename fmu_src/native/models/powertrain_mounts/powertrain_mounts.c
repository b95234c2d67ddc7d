/* PowertrainMounts: a rigid powertrain on linear rubber mounts, small motion about its static equilibrium
 * (port of driveline/mounts/: layout.py, rigid_body.py, joints.py, exact_step.py, system.py, model.py).
 *
 * The layout is read with the shared layout reader (lib/toml.h: the file rules of
 * driveline/layout_files.py). The system (matrices, modes, input map, the weight's sag) is the model's
 * derived data, built when the parameters change; the propagator of a step size (Phi, Gamma0, Gamma1, one
 * exponential of the augmented matrix: Pade 13 with scaling and squaring, exact_step.squarings' count) is
 * built again only when the step size changes. The state (q, q') is the outputs x ... yaw_dot, Model Exchange's
 * continuous states (spec._states).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi/fmu_instance.h"
#include "mounts.h"

#define ERROR_SIZE FMU_MESSAGE_SIZE
#define AUGMENTED MOUNTS_AUGMENTED

/* ---- the system (rigid_body.py, joints.py, system.py) --------------------------------------------- */

/* The loads in the order of the input map (spec.INPUTS) are the inputs whose rates the spec declares, in that
 * order: model_input_derivatives[k].input, its rate .target. The states (x ... yaw, then their velocities) and
 * their derivatives: model_states, model_state_derivatives (the accelerations from the seventh on). */
#define N_INPUTS MODEL_INPUT_DERIVATIVE_COUNT
#define STATE_VARIABLES model_states
#define ACCELERATION_VARIABLES (model_state_derivatives + 6)
static const int STATIC_VARIABLES[6] = {V_x_static,    V_y_static,     V_z_static,
                                        V_roll_static, V_pitch_static, V_yaw_static};
static const char *const COORDINATES[6] = {"x", "y", "z", "roll", "pitch", "yaw"};

typedef struct {
    double h, phi[12][12], gamma0[12][6], gamma1[12][6];
} Propagator;

typedef struct {
    int held;
    int parameter_count, parameter[MODEL_VARIABLE_COUNT]; /* the Real parameters it was built for */
    double parameters[MODEL_VARIABLE_COUNT];               /* and their values */
    char *layout_name;                      /* owned */
    Layout layout;
    double mass[6][6], stiffness[6][6], damping[6][6], a[12][12], b[12][6], inputs[6][N_INPUTS];
    double maps[MOUNTS_LAYOUT_MAX_MOUNTS][3][6]; /* each mount's A T(p) */
    double frequencies[6], shares[6][6], damping_ratios[6], roll_axis[3], motor_axis[3], weight_sag[6];
    int dominant[6];
    int has_propagator;
    Propagator propagator;
    Halfshaft shafts[2];
    char failure[ERROR_SIZE];
} System;

static void free_system(void *derived)
{
    System *system = derived;
    if (system != NULL) {
        free(system->layout_name);
        free(system);
    }
}

static double norm3(const double v[3])
{
    return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

static void cross(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* rigid_body.point_map of the mount, turned into its axes: A T(p) (3 x 6) */
static void mount_map(const Mount *m, const double centre[3], double out[3][6])
{
    double r[3] = {m->position[0] - centre[0], m->position[1] - centre[1], m->position[2] - centre[2]};
    double t[3][6] = {{1, 0, 0, 0, r[2], -r[1]}, {0, 1, 0, -r[2], 0, r[0]}, {0, 0, 1, r[1], -r[0], 0}};
    dense_multiply(&m->axes[0][0], &t[0][0], &out[0][0], 3, 3, 6);
}

/* joints.joint_frame: columns X', Y', Z'; 0 with the message (also for a length that overflows) */
static int joint_frame(const double shaft[3], const double bend[3], const char *side, double frame[3][3], char *error)
{
    double length = norm3(shaft), bend_length = norm3(bend), z[3], x[3], y[3], along, sine, shown;
    char text[40];
    int k;
    if (isinf(length) || isinf(bend_length)) {
        snprintf(error, ERROR_SIZE, "the %s direction of the %s joint is too long (its length overflows)",
                 isinf(length) ? "halfshaft" : "bend-plane", side);
        return 0;
    }
    if (!(length >= MOUNTS_JOINTS_MIN_DIRECTION)) {
        python_format_g(length, 3, text, sizeof text);
        snprintf(error, ERROR_SIZE, "the halfshaft direction of the %s joint has no length (%s)", side, text);
        return 0;
    }
    for (k = 0; k < 3; k++) {
        z[k] = shaft[k] / length;
    }
    along = bend[0] * z[0] + bend[1] * z[1] + bend[2] * z[2];
    for (k = 0; k < 3; k++) {
        x[k] = bend[k] - along * z[k];
    }
    sine = norm3(x);
    shown = fmax(bend_length, 1.0);
    if (!(sine >= MOUNTS_JOINTS_MIN_DIRECTION * shown)) {
        snprintf(error, ERROR_SIZE,
                 "the bend-plane direction of the %s joint is parallel to its halfshaft direction or zero: it must "
                 "point across the shaft", side);
        return 0;
    }
    for (k = 0; k < 3; k++) {
        x[k] /= sine;
    }
    cross(z, x, y);
    for (k = 0; k < 3; k++) {
        frame[k][0] = x[k], frame[k][1] = y[k], frame[k][2] = z[k];
    }
    return 1;
}

/* RigidBody.of */
static void matrices(System *s)
{
    const Layout *l = &s->layout;
    int i, j, k, n;
    memset(s->mass, 0, sizeof s->mass);
    memset(s->stiffness, 0, sizeof s->stiffness);
    memset(s->damping, 0, sizeof s->damping);
    for (i = 0; i < 3; i++) {
        s->mass[i][i] = l->mass;
        for (j = 0; j < 3; j++) {
            s->mass[3 + i][3 + j] = l->inertia[i][j];
        }
    }
    for (n = 0; n < l->count; n++) {
        double (*map)[6] = s->maps[n];
        mount_map(&l->mounts[n], l->centre, map);
        for (i = 0; i < 6; i++) {
            for (j = 0; j < 6; j++) {
                for (k = 0; k < 3; k++) {
                    s->stiffness[i][j] += map[k][i] * l->mounts[n].stiffness[k] * map[k][j];
                    s->damping[i][j] += map[k][i] * l->mounts[n].damping[k] * map[k][j];
                }
            }
        }
    }
}

/* rigid_body.modes: K phi = w^2 M phi through M = L L^T (Cholesky) and Jacobi on L^-1 K L^-T; the damping
 * ratios of the modal strain energy, phi^T (2 pi f C) phi / (2 phi^T K phi) */
static void modes(System *s)
{
    double l[6][6] = {{0}}, c[36], vectors[36], shapes[6][6], momenta[6], w2[6];
    int order[6], i, j, k;
    for (j = 0; j < 6; j++) {
        for (i = j; i < 6; i++) {
            double sum = s->mass[i][j];
            for (k = 0; k < j; k++) {
                sum -= l[i][k] * l[j][k];
            }
            l[i][j] = i == j ? sqrt(sum) : sum / l[j][j];
        }
    }
    for (j = 0; j < 6; j++) { /* c = L^-1 K L^-T, column by column of L^-1 K, then rows */
        double column[6];
        for (i = 0; i < 6; i++) {
            double sum = s->stiffness[i][j];
            for (k = 0; k < i; k++) {
                sum -= l[i][k] * column[k];
            }
            column[i] = sum / l[i][i];
        }
        for (i = 0; i < 6; i++) {
            c[i * 6 + j] = column[i];
        }
    }
    for (i = 0; i < 6; i++) {
        double row[6];
        for (j = 0; j < 6; j++) {
            double sum = c[i * 6 + j];
            for (k = 0; k < j; k++) {
                sum -= l[j][k] * row[k];
            }
            row[j] = sum / l[j][j];
        }
        for (j = 0; j < 6; j++) {
            c[i * 6 + j] = row[j];
        }
    }
    for (i = 0; i < 6; i++) {
        for (j = 0; j < i; j++) {
            c[i * 6 + j] = c[j * 6 + i] = 0.5 * (c[i * 6 + j] + c[j * 6 + i]);
        }
    }
    dense_symmetric_eigen(c, vectors, 6);
    for (i = 0; i < 6; i++) {
        order[i] = i;
        w2[i] = c[i * 7];
    }
    for (i = 1; i < 6; i++) { /* ascending eigenvalues */
        for (j = i; j > 0 && w2[order[j]] < w2[order[j - 1]]; j--) {
            k = order[j], order[j] = order[j - 1], order[j - 1] = k;
        }
    }
    for (j = 0; j < 6; j++) { /* shape j = L^-T v */
        for (i = 5; i >= 0; i--) {
            double sum = vectors[i * 6 + order[j]];
            for (k = i + 1; k < 6; k++) {
                sum -= l[k][i] * shapes[k][j];
            }
            shapes[i][j] = sum / l[i][i];
        }
    }
    for (j = 0; j < 6; j++) {
        double total = 0.0, storage = 0.0, loss = 0.0;
        s->frequencies[j] = sqrt(fmax(w2[order[j]], 0.0)) / (2.0 * FMU_PI);
        for (i = 0; i < 6; i++) {
            double stiff = 0.0, damp = 0.0;
            for (k = 0; k < 6; k++) {
                stiff += s->stiffness[i][k] * shapes[k][j];
                damp += 2.0 * FMU_PI * s->frequencies[j] * s->damping[i][k] * shapes[k][j];
            }
            storage += shapes[i][j] * stiff;
            loss += shapes[i][j] * damp;
        }
        s->damping_ratios[j] = storage > 0.0 ? loss / (2.0 * storage) : 0.0;
        for (i = 0; i < 6; i++) {
            momenta[i] = 0.0;
            for (k = 0; k < 6; k++) {
                momenta[i] += s->mass[i][k] * shapes[k][j];
            }
            total += shapes[i][j] * momenta[i];
        }
        s->dominant[j] = 0;
        for (i = 0; i < 6; i++) {
            s->shares[j][i] = shapes[i][j] * momenta[i] / total;
            if (s->shares[j][i] > s->shares[j][s->dominant[j]]) {
                s->dominant[j] = i;
            }
        }
    }
}

/* exact_step.state_matrices and system.input_map */
static int state_and_inputs(System *s, double centres[2][3], double frames[2][3][3])
{
    double inverse[6][6], identity[6][6] = {{0}}, product[6][6], mass[6][6];
    int i, j, side, k;
    memcpy(mass, s->mass, sizeof mass);
    for (i = 0; i < 6; i++) {
        identity[i][i] = 1.0;
    }
    memcpy(inverse, identity, sizeof inverse);
    if (!dense_solve(&mass[0][0], &inverse[0][0], 6, 6)) {
        return 0;
    }
    memset(s->a, 0, sizeof s->a);
    memset(s->b, 0, sizeof s->b);
    for (i = 0; i < 6; i++) {
        s->a[i][6 + i] = 1.0;
    }
    dense_multiply(&inverse[0][0], &s->stiffness[0][0], &product[0][0], 6, 6, 6);
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            s->a[6 + i][j] = -product[i][j];
            s->b[6 + i][j] = inverse[i][j];
        }
    }
    dense_multiply(&inverse[0][0], &s->damping[0][0], &product[0][0], 6, 6, 6);
    for (i = 0; i < 6; i++) {
        for (j = 0; j < 6; j++) {
            s->a[6 + i][6 + j] = -product[i][j];
        }
    }
    memset(s->inputs, 0, sizeof s->inputs);
    for (i = 0; i < 6; i++) {
        s->inputs[i][i] = 1.0;
    }
    for (side = 0; side < 2; side++) {
        double r[3];
        for (i = 0; i < 3; i++) {
            r[i] = centres[side][i] - s->layout.centre[i];
        }
        for (k = 0; k < 6; k++) { /* joints.housing_load of unit reaction k, then RigidBody.load */
            double force[3] = {0, 0, 0}, moment[3] = {0, 0, 0}, arm[3];
            int column = 6 + 6 * side + k;
            for (i = 0; i < 3; i++) {
                (k < 3 ? force : moment)[i] = -frames[side][i][k % 3];
            }
            cross(r, force, arm);
            for (i = 0; i < 3; i++) {
                s->inputs[i][column] = force[i];
                s->inputs[3 + i][column] = arm[i] + moment[i];
            }
        }
    }
    for (i = 0; i < 3; i++) {
        s->inputs[3 + i][N_INPUTS - 1] = -s->motor_axis[i];
    }
    return 1;
}

/* RigidBody.static_displacement: K^-1 load */
static int static_displacement(const System *s, const double load[6], double out[6])
{
    double k[6][6];
    memcpy(k, s->stiffness, sizeof k);
    memcpy(out, load, 6 * sizeof *out);
    return dense_solve(&k[0][0], out, 6, 1);
}

/* rigid_body.torque_roll_axis */
static void torque_roll_axis(System *s)
{
    double j[3][3], axis[3], length;
    int i;
    memcpy(j, s->layout.inertia, sizeof j);
    memcpy(axis, s->motor_axis, sizeof axis);
    dense_solve(&j[0][0], axis, 3, 1);
    length = norm3(axis);
    for (i = 0; i < 3; i++) {
        axis[i] /= length;
    }
    length = axis[0] * s->motor_axis[0] + axis[1] * s->motor_axis[1] + axis[2] * s->motor_axis[2] >= 0.0 ? 1.0 : -1.0;
    for (i = 0; i < 3; i++) {
        s->roll_axis[i] = length * axis[i];
    }
}

/* rigid_body.unrestrained_error; 0 with the message */
static int restrained(const System *s, char *error)
{
    char lowest[40], highest[40], ratio[40];
    if (s->frequencies[0] >= MOUNTS_RIGID_BODY_MIN_FREQUENCY_RATIO * s->frequencies[5]) {
        return 1;
    }
    python_format_g(s->frequencies[0], 3, lowest, sizeof lowest);
    python_format_g(s->frequencies[5], 6, highest, sizeof highest);
    python_format_g(MOUNTS_RIGID_BODY_MIN_FREQUENCY_RATIO, 6, ratio, sizeof ratio);
    snprintf(error, ERROR_SIZE, "the mounts leave a rigid-body motion unrestrained (mode 1, mostly %s, at %s Hz, "
             "below %s of the highest mode, %s Hz): add a mount or move one off the line or plane of the others",
             COORDINATES[s->dominant[0]], lowest, ratio, highest);
    return 0;
}

/* ---- building the system (MountSystem.build, model.extra_parameter_errors) -------------------------- */

static void vector_of(const ModelData *data, const int variables[3], double out[3])
{
    int k;
    for (k = 0; k < 3; k++) {
        out[k] = data->real_value[variables[k]];
    }
}

static const LayoutNames NAMES = {"layout file", "layout"};

/* MountSystem.build with its placement; 0 with the message */
static int build(System *s, const ModelData *data, char *error)
{
    static const int centres[2][3] = {{V_x_joint_left, V_y_joint_left, V_z_joint_left},
                                      {V_x_joint_right, V_y_joint_right, V_z_joint_right}};
    static const int shafts[2][3] = {{V_shaft_x_left, V_shaft_y_left, V_shaft_z_left},
                                     {V_shaft_x_right, V_shaft_y_right, V_shaft_z_right}};
    static const int bends[2][3] = {{V_bend_x_left, V_bend_y_left, V_bend_z_left},
                                    {V_bend_x_right, V_bend_y_right, V_bend_z_right}};
    static const int motor[3] = {V_motor_axis_x, V_motor_axis_y, V_motor_axis_z};
    double centre[2][3], shaft[3], bend[3], frames[2][3][3], axis[3], length, gravity[6] = {0};
    int side, k;
    for (side = 0; side < 2; side++) {
        vector_of(data, centres[side], centre[side]);
        vector_of(data, shafts[side], shaft);
        vector_of(data, bends[side], bend);
        if (!joint_frame(shaft, bend, mounts_sides[side], frames[side], error)) {
            return 0;
        }
    }
    vector_of(data, motor, axis);
    length = norm3(axis);
    if (isinf(length)) {
        snprintf(error, ERROR_SIZE, "the motor axis (motor_axis_x, motor_axis_y, motor_axis_z) is too long (its "
                 "length overflows)");
        return 0;
    }
    if (!(length > 0.0)) {
        snprintf(error, ERROR_SIZE, "the motor axis (motor_axis_x, motor_axis_y, motor_axis_z) has no length");
        return 0;
    }
    for (k = 0; k < 3; k++) {
        s->motor_axis[k] = axis[k] / length;
    }
    if (layout_file_load(data->string_value[V_layout], data->cache->resources, &NAMES, loads_layout, &s->layout,
                         error, ERROR_SIZE) != ERROR_NONE) {
        return 0;
    }
    matrices(s);
    modes(s);
    if (!restrained(s, error)) {
        return 0;
    }
    gravity[2] = -s->layout.mass * VALUE(g);
    if (!state_and_inputs(s, centre, frames) || !static_displacement(s, gravity, s->weight_sag)) {
        snprintf(error, ERROR_SIZE, "Singular matrix");
        return 0;
    }
    torque_roll_axis(s);
    halfshafts_place(s->shafts, data, &centre[0][0], &frames[0][0][0], s->layout.centre);
    return 1;
}

static int built_for(const System *s, const ModelData *data)
{
    int i;
    if (!s->held || strcmp(s->layout_name, data->string_value[V_layout]) != 0) {
        return 0;
    }
    for (i = 0; i < s->parameter_count; i++) {
        if (!(s->parameters[i] == data->real_value[s->parameter[i]])) {
            return 0;
        }
    }
    return 1;
}

/* Keeps the Real parameters' values ``s`` was built for */
static void keep_parameters(System *s, const ModelData *data)
{
    int i;
    s->parameter_count = 0;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].causality == CAUSALITY_PARAMETER && model_variables[i].type == VAR_REAL) {
            s->parameter[s->parameter_count] = i;
            s->parameters[s->parameter_count++] = data->real_value[i];
        }
    }
}

/* PowertrainMountsModel.extra_parameter_errors */
static void extra_parameter_errors(const ModelData *data, Messages *out)
{
    ModelCache *cache = data->cache;
    System *s = cache->derived, *built;
    char error[ERROR_SIZE] = "";
    size_t length = strlen(data->string_value[V_layout]);
    if (s != NULL && built_for(s, data)) {
        return;
    }
    built = calloc(1, sizeof *built);
    if (built == NULL || (built->layout_name = malloc(length + 1)) == NULL) {
        free(built);
        messages_add(out, "powertrain: out of memory", (const char *)NULL);
        return;
    }
    if (!build(built, data, error)) {
        free_system(built);
        messages_add(out, "powertrain: ", error, (const char *)NULL);
        return;
    }
    memcpy(built->layout_name, data->string_value[V_layout], length + 1);
    keep_parameters(built, data);
    built->held = 1;
    free_system(s);
    cache->derived = built;
}

/* ---- the exact step (exact_step.py) ----------------------------------------------------------------- */

/* exact_step.augmented: Z h (24 x 24) */
static void augmented(const System *s, double h, double *z)
{
    int i, j;
    memset(z, 0, AUGMENTED * AUGMENTED * sizeof *z);
    for (i = 0; i < 12; i++) {
        for (j = 0; j < 12; j++) {
            z[i * AUGMENTED + j] = s->a[i][j] * h;
        }
        for (j = 0; j < 6; j++) {
            z[i * AUGMENTED + 12 + j] = s->b[i][j] * h;
        }
    }
    for (i = 0; i < 6; i++) {
        z[(12 + i) * AUGMENTED + 18 + i] = h;
    }
}

/* exact_step.squarings: -1 where the norm is not finite (no count of squarings scales it) */
static int squarings(const double *z)
{
    double norm = 0.0;
    int i, j;
    for (j = 0; j < AUGMENTED; j++) {
        double sum = 0.0;
        for (i = 0; i < AUGMENTED; i++) {
            sum += fabs(z[i * AUGMENTED + j]);
        }
        norm = fmax(norm, sum);
    }
    if (!isfinite(norm)) {
        return -1;
    }
    /* a finite norm needs at most log2(DBL_MAX / THETA_13) + 1 = 1022 squarings: an int holds the count */
    return norm > MOUNTS_EXACT_STEP_THETA_13 ? (int)fmax(0.0, ceil(log2(norm / MOUNTS_EXACT_STEP_THETA_13))) : 0;
}

/* exact_step.work_error and Propagator.build; 0 with the message in s->failure */
static int propagator(System *s, double h)
{
    double *z = malloc(2 * AUGMENTED * AUGMENTED * sizeof *z), *e;
    char step[40];
    int count, i, j;
    if (z == NULL) {
        snprintf(s->failure, ERROR_SIZE, "out of memory");
        return 0;
    }
    e = z + AUGMENTED * AUGMENTED;
    augmented(s, h, z);
    count = squarings(z);
    python_float_repr(h, step, sizeof step);
    if (count < 0) {
        snprintf(s->failure, ERROR_SIZE, "a step of %s s overflows the matrix exponential's norm: take shorter steps",
                 step);
        free(z);
        return 0;
    }
    if (count > MOUNTS_EXACT_STEP_MAX_SQUARINGS) {
        snprintf(s->failure, ERROR_SIZE, "a step of %s s would take %d squarings of the matrix exponential, more than "
                 "the %d accepted: take shorter steps", step, count, MOUNTS_EXACT_STEP_MAX_SQUARINGS);
        free(z);
        return 0;
    }
    if (!dense_exponential(z, count, e)) {
        snprintf(s->failure, ERROR_SIZE, "out of memory");
        free(z);
        return 0;
    }
    for (i = 0; i < 12; i++) {
        for (j = 0; j < 12; j++) {
            s->propagator.phi[i][j] = e[i * AUGMENTED + j];
        }
        for (j = 0; j < 6; j++) {
            s->propagator.gamma0[i][j] = e[i * AUGMENTED + 12 + j];
            s->propagator.gamma1[i][j] = e[i * AUGMENTED + 18 + j];
        }
    }
    s->propagator.h = h;
    s->has_propagator = 1;
    free(z);
    return 1;
}

/* ---- per step (model.py) ---------------------------------------------------------------------------- */

/* G u of the loads (``rates`` 0) or of their rates (1) */
static void generalised(const System *s, const ModelData *data, int rates, double out[6])
{
    double u[N_INPUTS];
    int i, k;
    for (k = 0; k < N_INPUTS; k++) {
        const InputDerivative *load = &model_input_derivatives[k];
        u[k] = data->real_value[rates ? load->target : load->input];
    }
    for (i = 0; i < 6; i++) {
        out[i] = 0.0;
        for (k = 0; k < N_INPUTS; k++) {
            out[i] += s->inputs[i][k] * u[k];
        }
    }
}

/* PowertrainMountsModel._show: motion and mount forces of ``state`` under ``force`` */
static void show(const System *s, ModelData *data, const double state[12], const double force[6])
{
    double q[6];
    int i, k, n;
    for (i = 0; i < 12; i++) {
        data->real_value[STATE_VARIABLES[i]] = state[i];
    }
    for (i = 0; i < 6; i++) { /* (A s + B f)[6:] */
        double sum = 0.0;
        for (k = 0; k < 12; k++) {
            sum += s->a[6 + i][k] * state[k];
        }
        for (k = 0; k < 6; k++) {
            sum += s->b[6 + i][k] * force[k];
        }
        data->real_value[ACCELERATION_VARIABLES[i]] = sum;
        q[i] = s->weight_sag[i] + state[i];
    }
    for (n = 0; n < MOUNTS_LAYOUT_MAX_MOUNTS; n++) { /* RigidBody.mount_forces */
        double local[3] = {0, 0, 0};
        int first = V_F_x_mount1 + 3 * n;
        if (n < s->layout.count) {
            const Mount *m = &s->layout.mounts[n];
            const double(*map)[6] = s->maps[n];
            for (k = 0; k < 3; k++) {
                double moved = 0.0, speed = 0.0;
                for (i = 0; i < 6; i++) {
                    moved += map[k][i] * q[i];
                    speed += map[k][i] * state[6 + i];
                }
                local[k] = m->stiffness[k] * moved + m->damping[k] * speed;
            }
            for (i = 0; i < 3; i++) {
                data->real_value[first + i] = -(m->axes[0][i] * local[0] + m->axes[1][i] * local[1] +
                                                 m->axes[2][i] * local[2]);
            }
        } else {
            for (i = 0; i < 3; i++) {
                data->real_value[first + i] = 0.0;
            }
        }
    }
}

/* PowertrainMountsModel._show_analysis */
static Failure show_analysis(System *s, ModelData *data)
{
    double load[6] = {0}, sag[6];
    int i, j;
    load[2] = -s->layout.mass * VALUE(g);
    for (i = 0; i < 3; i++) {
        load[3 + i] = -VALUE(T_mean) * s->motor_axis[i];
    }
    if (!static_displacement(s, load, sag)) {
        return FAILURE(ERROR_VALUE, "Singular matrix");
    }
    data->real_value[V_wind_up] = 0.0;
    for (i = 0; i < 6; i++) {
        data->real_value[STATIC_VARIABLES[i]] = sag[i];
    }
    for (i = 0; i < 3; i++) { /* MountSystem.wind_up */
        data->real_value[V_wind_up] -= (sag[3 + i] - s->weight_sag[3 + i]) * s->motor_axis[i];
    }
    for (j = 0; j < 6; j++) {
        data->real_value[V_f_mode_1 + j] = s->frequencies[j];
        data->real_value[V_zeta_mode_1 + j] = s->damping_ratios[j];
        data->int_value[V_mode_1_coordinate + 2 * j] = s->dominant[j] + 1;
        data->real_value[V_mode_1_share + 2 * j] = s->shares[j][s->dominant[j]];
        for (i = 0; i < 6; i++) {
            data->real_value[V_share_1_x + 6 * j + i] = s->shares[j][i];
        }
    }
    for (i = 0; i < 3; i++) {
        data->real_value[V_torque_roll_axis_x + i] = s->roll_axis[i];
    }
    data->int_value[V_mount_count] = s->layout.count;
    return NO_FAILURE;
}

static Failure start(ModelData *data, double start_time UNUSED)
{
    System *s = data->cache->derived;
    double force[6], state[12] = {0};
    Failure failure;
    if (s == NULL) { /* the parameter check builds it before every initialisation */
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    generalised(s, data, 0, force);
    if (!static_displacement(s, force, state)) {
        return FAILURE(ERROR_VALUE, "Singular matrix");
    }
    show(s, data, state, force);
    failure = halfshafts_show(s->shafts, data, s->failure);
    if (failure.kind == ERROR_NONE) {
        failure = halfshafts_limits(data, s->failure);
    }
    return failure.kind == ERROR_NONE ? show_analysis(s, data) : failure;
}

static Failure advance(ModelData *data, double current_time UNUSED, double step_size)
{
    System *s = data->cache->derived;
    double held[6], rates[6], state[12], next[12], force[6];
    int i, k;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    if ((!s->has_propagator || s->propagator.h != step_size) && !propagator(s, step_size)) {
        return FAILURE(ERROR_VALUE, s->failure);
    }
    generalised(s, data, 0, held);
    generalised(s, data, 1, rates);
    for (i = 0; i < 12; i++) {
        state[i] = data->real_value[STATE_VARIABLES[i]];
    }
    for (i = 0; i < 12; i++) { /* Propagator.step */
        double sum = 0.0, loads = 0.0;
        for (k = 0; k < 12; k++) {
            sum += s->propagator.phi[i][k] * state[k];
        }
        for (k = 0; k < 6; k++) {
            loads += s->propagator.gamma0[i][k] * held[k] + s->propagator.gamma1[i][k] * rates[k];
        }
        next[i] = sum + loads;
    }
    for (i = 0; i < 6; i++) {
        force[i] = held[i] + rates[i] * step_size;
    }
    show(s, data, next, force);
    return halfshafts_show(s->shafts, data, s->failure);
}

/* Model Exchange: the accelerations (the velocities' derivatives) and mount forces at the solver's state
 * (q, q') under the inputs now, M q'' + C q' + K q = G u; the static sag and modal table stay as the
 * initialisation left them (functions of the parameters alone). */
static Failure evaluate(ModelData *data, double time UNUSED)
{
    System *s = data->cache->derived;
    double force[6], state[12];
    int i;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    generalised(s, data, 0, force);
    for (i = 0; i < 12; i++) {
        state[i] = data->real_value[STATE_VARIABLES[i]];
    }
    show(s, data, state, force);
    return halfshafts_show(s->shafts, data, s->failure);
}

/* The halfshafts' rows (halfshaft_outputs.c) from the accelerations' partials: A's rows and B G */
static Failure halfshaft_partials(const System *s, const ModelData *data, double partial[])
{
    double state[12], force[6], acceleration[6], loads[6][N_INPUTS];
    int i, j, k;
    generalised(s, data, 0, force);
    for (i = 0; i < 12; i++) {
        state[i] = data->real_value[STATE_VARIABLES[i]];
    }
    for (i = 0; i < 6; i++) {
        double sum = 0.0;
        for (k = 0; k < 12; k++) {
            sum += s->a[6 + i][k] * state[k];
        }
        for (k = 0; k < 6; k++) {
            sum += s->b[6 + i][k] * force[k];
        }
        acceleration[i] = sum;
        for (k = 0; k < N_INPUTS; k++) {
            loads[i][k] = 0.0;
            for (j = 0; j < 6; j++) {
                loads[i][k] += s->b[6 + i][j] * s->inputs[j][k];
            }
        }
    }
    return halfshafts_partials(s->shafts, data, acceleration, &s->a[6][0], &loads[0][0], partial);
}

/* Directional derivatives: the model is linear, its partials constant. The accelerations (A s + B G u)[6:]
 * by the states and the loads (their rates: none, as in evaluate), each mount's force by the states
 * (show's mount forces); the states' own rows and der(<state>)'s are the layer's. */
static Failure jacobian(const ModelData *data, double partial[])
{
    const System *s = data->cache->derived;
    int i, j, k, n;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    for (i = 0; i < 6; i++) {
        double *row = partial + model_jacobian_rows[ACCELERATION_VARIABLES[i]] * MODEL_COLUMN_COUNT;
        for (k = 0; k < 12; k++) {
            row[model_jacobian_columns[STATE_VARIABLES[k]]] = s->a[6 + i][k];
        }
        for (k = 0; k < N_INPUTS; k++) {
            double sum = 0.0;
            for (j = 0; j < 6; j++) {
                sum += s->b[6 + i][j] * s->inputs[j][k];
            }
            row[model_jacobian_columns[model_input_derivatives[k].input]] = sum;
        }
    }
    for (n = 0; n < s->layout.count; n++) {
        const Mount *m = &s->layout.mounts[n];
        for (i = 0; i < 3; i++) {
            double *row = partial + model_jacobian_rows[V_F_x_mount1 + 3 * n + i] * MODEL_COLUMN_COUNT;
            for (j = 0; j < 6; j++) {
                double moved = 0.0, speed = 0.0;
                for (k = 0; k < 3; k++) {
                    moved -= m->axes[k][i] * m->stiffness[k] * s->maps[n][k][j];
                    speed -= m->axes[k][i] * m->damping[k] * s->maps[n][k][j];
                }
                row[model_jacobian_columns[STATE_VARIABLES[j]]] = moved;
                row[model_jacobian_columns[STATE_VARIABLES[6 + j]]] = speed;
            }
        }
    }
    return halfshaft_partials(s, data, partial);
}

const ModelHooks model_hooks = {.start = start, .advance = advance, .evaluate = evaluate,
                                .extra_parameter_errors = extra_parameter_errors, .free_derived = free_system,
                                .jacobian = jacobian};
