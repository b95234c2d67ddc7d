/* PowertrainMounts: a rigid powertrain on rubber mounts, small motion about its static equilibrium
 * (port of driveline/mounts/: rigid_body.py, joints.py, system.py, model.py; the library of mounts.h the rest).
 *
 * The layout is read with the shared layout reader (lib/toml.h: the file rules of
 * driveline/layout_files.py). The system (matrices, modes, input map, the weight's sag) is the model's
 * derived data, built when the parameters change; the propagator of a step size (Phi, Gamma0, Gamma1, one
 * exponential of the augmented matrix: Pade 13 with scaling and squaring, exact_step.squarings' count) is
 * built again only when the step size changes; progressive mounts step by the implicit scheme
 * (implicit_step.c). The state (q, q', z): q and q' the outputs x ... yaw_dot, Model Exchange's continuous states
 * (spec._states), z the Maxwell branches' forces: co-simulation's internal state (data->internal, one slot a
 * branch), shown in the outputs of their slots (mount, axis, branch), Model Exchange's states after the motion's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi/fmu_instance.h"
#include "mounts.h"

#define ERROR_SIZE FMU_MESSAGE_SIZE
#define MAX_STATE MOUNTS_MAX_STATE
#define MAPS(s) ((const double(*)[3][6])(s)->maps)

/* ---- the system (rigid_body.py, joints.py, system.py) --------------------------------------------- */

/* The loads in the order of the input map (spec.INPUTS) are the inputs whose rates the spec declares, in that
 * order: model_input_derivatives[k].input, its rate .target. The states (x ... yaw, then their velocities) and
 * their derivatives: model_states, model_state_derivatives (the accelerations from the seventh on). */
#define N_INPUTS MODEL_INPUT_DERIVATIVE_COUNT
#define STATE_VARIABLES model_states
#define ACCELERATION_VARIABLES (model_state_derivatives + 6)
/* The Maxwell branches' slots (spec.BRANCH_FORCES) and their rates, the states and derivatives after the motion's */
#define BRANCH_VARIABLES (model_states + 12)
#define BRANCH_RATE_VARIABLES (model_state_derivatives + 12)
#define BRANCH_SLOTS (MODEL_STATE_COUNT - 12)
static const int STATIC_VARIABLES[6] = {V_x_static,    V_y_static,     V_z_static,
                                        V_roll_static, V_pitch_static, V_yaw_static};
static const char *const COORDINATES[6] = {"x", "y", "z", "roll", "pitch", "yaw"};

typedef struct {
    int held;
    int parameter_count, parameter[MODEL_VARIABLE_COUNT]; /* the Real parameters it was built for */
    double parameters[MODEL_VARIABLE_COUNT];               /* and their values */
    char *layout_name;                      /* owned */
    Layout layout;
    double mass[6][6], stiffness[6][6], damping[6][6], a[MAX_STATE][MAX_STATE], b[MAX_STATE][6];
    double inputs[6][N_INPUTS];
    double maps[MOUNTS_LAYOUT_MAX_MOUNTS][3][6]; /* each mount's A T(p) */
    double frequencies[6], shares[6][6], damping_ratios[6], roll_axis[3], motor_axis[3], weight_sag[6];
    double weight[6], operating[6]; /* the weight's generalised force; Q under it and -T_mean (the static sag) */
    int dominant[6];
    int progressive, size; /* a mount's characteristic is nonlinear; the state's length, 12 and the branches */
    Branches branches;
    int idle[BRANCH_SLOTS], idle_count; /* the branch slots no branch takes */
    int has_propagator, has_matrices;
    Propagator propagator;
    StepMatrices matrices; /* of the last step size, progressive mounts' */
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

/* K phi = w^2 M phi through M = L L^T (Cholesky) and Jacobi on L^-1 K L^-T (scipy.linalg.eigh's part): the
 * eigenvalues ascending, the mass-normalised shapes in the columns */
static void eigen(double mass[6][6], double stiffness[6][6], double values[6], double shapes[6][6])
{
    double l[6][6] = {{0}}, c[36], vectors[36], w2[6];
    int order[6], i, j, k;
    for (j = 0; j < 6; j++) {
        for (i = j; i < 6; i++) {
            double sum = mass[i][j];
            for (k = 0; k < j; k++) {
                sum -= l[i][k] * l[j][k];
            }
            l[i][j] = i == j ? sqrt(sum) : sum / l[j][j];
        }
    }
    for (j = 0; j < 6; j++) { /* c = L^-1 K L^-T, column by column of L^-1 K, then rows */
        double column[6];
        for (i = 0; i < 6; i++) {
            double sum = stiffness[i][j];
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
        values[j] = w2[order[j]];
        for (i = 5; i >= 0; i--) {
            double sum = vectors[i * 6 + order[j]];
            for (k = i + 1; k < 6; k++) {
                sum -= l[k][i] * shapes[k][j];
            }
            shapes[i][j] = sum / l[i][i];
        }
    }
}

/* phi_j^T a phi_j */
static double modal(double a[6][6], double shapes[6][6], int j)
{
    double total = 0.0;
    int i, k;
    for (i = 0; i < 6; i++) {
        double row = 0.0;
        for (k = 0; k < 6; k++) {
            row += a[i][k] * shapes[k][j];
        }
        total += shapes[i][j] * row;
    }
    return total;
}

/* Mode j's fixed point (K + K_s(f_j)) phi_j = (2 pi f_j)^2 M phi_j, the branches' storage at its own frequency
 * (rigid_body.modes), from ``frequency``: the frequency, its shape into column j of ``shapes``, the branches'
 * stiffness there into ``storage`` (K + K_s), ``loss``, ``slope`` */
static double fixed_point(System *s, double stiffness[6][6], int j, double frequency,
                          double shapes[6][6], double storage[6][6], double loss[6][6], double slope[6][6])
{
    double values[6], vectors[6][6] = {{0}};
    int iteration, i, k;
    for (iteration = 0; iteration < MOUNTS_RIGID_BODY_MAX_FREQUENCY_ITERATIONS; iteration++) {
        double previous = frequency;
        forces_branch_stiffness(&s->branches, frequency, storage, loss, slope);
        for (i = 0; i < 6; i++) {
            for (k = 0; k < 6; k++) {
                storage[i][k] = stiffness[i][k] + storage[i][k];
            }
        }
        eigen(s->mass, storage, values, vectors);
        frequency = sqrt(fmax(values[j], 0.0)) / (2.0 * FMU_PI);
        if (fabs(frequency - previous) <= MOUNTS_RIGID_BODY_FREQUENCY_TOLERANCE * frequency) {
            break;
        }
    }
    for (i = 0; i < 6; i++) {
        shapes[i][j] = vectors[i][j];
    }
    forces_branch_stiffness(&s->branches, frequency, storage, loss, slope);
    for (i = 0; i < 6; i++) {
        for (k = 0; k < 6; k++) {
            storage[i][k] = stiffness[i][k] + storage[i][k];
        }
    }
    return frequency;
}

/* rigid_body.modes about an operating point of tangent stiffness ``stiffness``, with the Maxwell branches
 * (``with_branches``): the damping ratios of the modal strain energy, phi^T K_l phi / (2 phi^T K_s phi -
 * phi^T w dK_s/dw phi), K_l = 2 pi f C + the branches' loss stiffness */
static void modes(System *s, double stiffness[6][6], int with_branches)
{
    double shapes[6][6], momenta[6], w2[6], storage[6][6], loss[6][6], slope[6][6];
    int i, j, k;
    eigen(s->mass, stiffness, w2, shapes);
    for (j = 0; j < 6; j++) {
        s->frequencies[j] = sqrt(fmax(w2[j], 0.0)) / (2.0 * FMU_PI);
    }
    for (j = 0; j < 6; j++) {
        double total = 0.0, energy;
        memcpy(storage, stiffness, sizeof storage);
        memset(loss, 0, sizeof loss);
        memset(slope, 0, sizeof slope);
        if (with_branches) {
            s->frequencies[j] = fixed_point(s, stiffness, j, s->frequencies[j], shapes, storage, loss, slope);
        }
        for (i = 0; i < 6; i++) {
            for (k = 0; k < 6; k++) {
                loss[i][k] = loss[i][k] + 2.0 * FMU_PI * s->frequencies[j] * s->damping[i][k];
            }
        }
        energy = 2.0 * modal(storage, shapes, j) - modal(slope, shapes, j);
        s->damping_ratios[j] = energy > 0.0 ? modal(loss, shapes, j) / energy : 0.0;
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

/* exact_step.state_matrices (with the branches) and system.input_map */
/* The slots no branch of ``s->branches`` takes, in s->idle */
static void idle_slots(System *s)
{
    int taken[BRANCH_SLOTS] = {0}, k;
    for (k = 0; k < s->branches.count; k++) {
        taken[s->branches.slots[k]] = 1;
    }
    s->idle_count = 0;
    for (k = 0; k < BRANCH_SLOTS; k++) {
        if (!taken[k]) {
            s->idle[s->idle_count++] = k;
        }
    }
}

static int state_and_inputs(System *s, double centres[2][3], double frames[2][3][3])
{
    int i, side, k;
    if (!exact_state_matrices(s->mass, s->stiffness, s->damping, &s->branches, s->a, s->b)) {
        return 0;
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

/* system._equilibrium: Q under the generalised ``load`` (the weight's included), K^-1 load for linear mounts
 * (as ever), else Newton's root of the characteristics; ERROR_NONE or the failure with its message */
static ErrorKind equilibrium(const System *s, const double load[6], double out[6], const char **message)
{
    if (!s->progressive) {
        *message = "Singular matrix";
        return static_displacement(s, load, out) ? ERROR_NONE : ERROR_VALUE;
    }
    return forces_equilibrium(&s->layout, (const double(*)[3][6])s->maps, load, s->stiffness, out, message);
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

/* MountSystem.build past the unrestrained check: the weight's equilibrium, the operating point under the
 * weight and -T_mean about the motor axis (the static sag), the branches' rates there, the state matrices and
 * input map, the modes about the operating point; 0 with the message */
static int operating_point(System *s, const ModelData *data, double centres[2][3], double frames[2][3][3], char *error)
{
    double load[6] = {0}, tangent[6][6];
    const char *message = NULL;
    ErrorKind failed;
    int i, n;
    s->progressive = 0;
    for (n = 0; n < s->layout.count; n++) {
        s->progressive |= mount_progressive(&s->layout.mounts[n]);
    }
    memset(s->weight, 0, sizeof s->weight);
    s->weight[2] = -s->layout.mass * VALUE(g);
    for (i = 0; i < 6; i++) {
        load[i] = s->weight[i] + (i < 3 ? 0.0 : -VALUE(T_mean) * s->motor_axis[i - 3]);
    }
    if ((failed = equilibrium(s, load, s->operating, &message)) != ERROR_NONE ||
        (failed = equilibrium(s, s->weight, s->weight_sag, &message)) != ERROR_NONE) {
        snprintf(error, ERROR_SIZE, "%s", message);
        return 0;
    }
    s->size = 12 + forces_branch_map(&s->layout, (const double(*)[3][6])s->maps, s->operating, &s->branches);
    idle_slots(s);
    if (!state_and_inputs(s, centres, frames)) {
        snprintf(error, ERROR_SIZE, "Singular matrix");
        return 0;
    }
    if (s->progressive) {
        forces_tangent_stiffness(&s->layout, (const double(*)[3][6])s->maps, s->operating, tangent);
    } else {
        memcpy(tangent, s->stiffness, sizeof tangent);
    }
    modes(s, tangent, s->branches.count > 0);
    torque_roll_axis(s);
    return 1;
}

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
    double centre[2][3], shaft[3], bend[3], frames[2][3][3], axis[3], length;
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
    modes(s, s->stiffness, 0);
    if (!restrained(s, error)) {
        return 0;
    }
    halfshafts_place(s->shafts, data, &centre[0][0], &frames[0][0][0], s->layout.centre);
    return operating_point(s, data, centre, frames, error);
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

/* MountSystem.accelerations: q'' at ``state`` under the generalised ``force``, the mounts' elastic forces along
 * their axes ``springs`` (progressive mounts') */
static void accelerations(const System *s, const double *state, const double force[6], const double springs[][3],
                          double out[6])
{
    int i, k;
    if (!s->progressive) {
        for (i = 0; i < 6; i++) { /* (A s + B f)[6:12] */
            double sum = 0.0;
            for (k = 0; k < s->size; k++) {
                sum += s->a[6 + i][k] * state[k];
            }
            for (k = 0; k < 6; k++) {
                sum += s->b[6 + i][k] * force[k];
            }
            out[i] = sum;
        }
        return;
    }
    {
        double elastic[6], total[6];
        forces_generalised(&s->layout, MAPS(s), springs, elastic);
        for (i = 0; i < 6; i++) {
            double viscous = 0.0, branches = 0.0;
            for (k = 0; k < 6; k++) {
                viscous += s->damping[i][k] * state[6 + k];
            }
            for (k = 0; k < s->branches.count; k++) {
                branches += s->branches.rows[k][i] * state[12 + k];
            }
            total[i] = force[i] + s->weight[i] - elastic[i] - viscous - branches;
        }
        for (i = 0; i < 6; i++) { /* M^-1 total: B's rows are M^-1 */
            out[i] = 0.0;
            for (k = 0; k < 6; k++) {
                out[i] += s->b[6 + i][k] * total[k];
            }
        }
    }
}

/* PowertrainMountsModel._show: motion and mount forces of ``state`` (q, q', z) under ``force``; the branch
 * forces into the internal state. Each mount's elastic force and speed along its axes (R q' of its branches,
 * whose rows are the mount's) are computed once, for the accelerations, branch rates and mount forces. */
static void show(const System *s, ModelData *data, const double *state, const double force[6])
{
    double q[6], acceleration[6], springs[MOUNTS_LAYOUT_MAX_MOUNTS][3], speeds[3 * MOUNTS_LAYOUT_MAX_MOUNTS];
    int i, k, n, first_branch = 0;
    for (i = 0; i < 6; i++) {
        q[i] = s->weight_sag[i] + state[i];
    }
    for (n = 0; n < s->layout.count; n++) {
        forces_elastic(&s->layout, MAPS(s), n, q, springs[n]);
        for (k = 0; k < 3; k++) {
            double speed = 0.0;
            for (i = 0; i < 6; i++) {
                speed += s->maps[n][k][i] * state[6 + i];
            }
            speeds[3 * n + k] = speed;
        }
    }
    accelerations(s, state, force, (const double(*)[3])springs, acceleration);
    for (i = 0; i < 12; i++) {
        data->real_value[STATE_VARIABLES[i]] = state[i];
    }
    for (i = 0; i < 6; i++) {
        data->real_value[ACCELERATION_VARIABLES[i]] = acceleration[i];
    }
    memcpy(data->internal, state + 12, s->branches.count * sizeof *state);
    memset(data->internal + s->branches.count, 0, (FMU_INTERNAL_SLOTS - s->branches.count) * sizeof *state);
    for (k = 0; k < s->idle_count; k++) {
        data->real_value[BRANCH_VARIABLES[s->idle[k]]] = data->real_value[BRANCH_RATE_VARIABLES[s->idle[k]]] = 0.0;
    }
    for (k = 0; k < s->branches.count; k++) { /* MountSystem.derivatives: z' = g (R q') - z / tau, slot (3 n + axis) */
        int slot = s->branches.slots[k];
        data->real_value[BRANCH_VARIABLES[slot]] = state[12 + k];
        data->real_value[BRANCH_RATE_VARIABLES[slot]] =
            s->branches.gains[k] * speeds[slot / MOUNTS_RUBBER_BRANCHES] - state[12 + k] / s->branches.times[k];
    }
    for (n = 0; n < MOUNTS_LAYOUT_MAX_MOUNTS; n++) { /* MountSystem.mount_forces */
        double local[3] = {0, 0, 0};
        int first = V_F_x_mount1 + 3 * n;
        if (n < s->layout.count) {
            const Mount *m = &s->layout.mounts[n];
            for (k = 0; k < 3; k++) {
                double branches = 0.0;
                int j;
                for (j = 0; j < m->branch_count; j++) {
                    branches += state[12 + first_branch + k * m->branch_count + j];
                }
                local[k] = springs[n][k] + m->damping[k] * speeds[3 * n + k] + branches;
            }
            first_branch += 3 * m->branch_count;
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
    int i, j;
    data->real_value[V_wind_up] = 0.0;
    for (i = 0; i < 6; i++) {
        data->real_value[STATIC_VARIABLES[i]] = s->operating[i];
    }
    for (i = 0; i < 3; i++) { /* MountSystem.wind_up */
        data->real_value[V_wind_up] -= (s->operating[3 + i] - s->weight_sag[3 + i]) * s->motor_axis[i];
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
    double force[6], load[6], state[MAX_STATE] = {0};
    const char *message = NULL;
    ErrorKind failed;
    Failure failure;
    int i;
    if (s == NULL) { /* the parameter check builds it before every initialisation */
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    generalised(s, data, 0, force);
    if (s->progressive) { /* the equilibrium under the weight and the start inputs, from the weight's */
        for (i = 0; i < 6; i++) {
            load[i] = s->weight[i] + force[i];
        }
        if ((failed = equilibrium(s, load, state, &message)) != ERROR_NONE) {
            return FAILURE(failed, message);
        }
        for (i = 0; i < 6; i++) {
            state[i] -= s->weight_sag[i];
        }
    } else if (!static_displacement(s, force, state)) {
        return FAILURE(ERROR_VALUE, "Singular matrix");
    }
    show(s, data, state, force);
    failure = halfshafts_show(s->shafts, data, s->failure);
    if (failure.kind == ERROR_NONE) {
        failure = halfshafts_limits(data, s->failure);
    }
    return failure.kind == ERROR_NONE ? show_analysis(s, data) : failure;
}

/* The state (q, q', z) of the outputs and the internal state */
static void current_state(const System *s, const ModelData *data, double *state)
{
    int i;
    for (i = 0; i < 12; i++) {
        state[i] = data->real_value[STATE_VARIABLES[i]];
    }
    for (i = 0; i < s->branches.count; i++) {
        state[12 + i] = data->internal[i];
    }
}

static Failure advance(ModelData *data, double current_time UNUSED, double step_size)
{
    System *s = data->cache->derived;
    double held[6], rates[6], state[MAX_STATE], next[MAX_STATE], force[6];
    int i;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    generalised(s, data, 0, held);
    generalised(s, data, 1, rates);
    current_state(s, data, state);
    if (s->progressive) {
        const char *message = NULL;
        StepSystem step = {&s->layout, MAPS(s), (const double(*)[6])s->mass, (const double(*)[6])s->damping,
                           &s->branches, s->weight, s->weight_sag};
        ErrorKind failed;
        if (!s->has_matrices || s->matrices.h != step_size) {
            implicit_matrices(&step, step_size, &s->matrices);
            s->has_matrices = 1;
        }
        failed = implicit_step(&step, &s->matrices, state, held, rates, next, &message);
        if (failed != ERROR_NONE) {
            return FAILURE(failed, message);
        }
    } else {
        if ((!s->has_propagator || s->propagator.h != step_size) &&
            !exact_propagator((const double(*)[MAX_STATE])s->a, (const double(*)[6])s->b, s->size, step_size,
                              &s->propagator, s->failure, ERROR_SIZE)) {
            return FAILURE(ERROR_VALUE, s->failure);
        }
        s->has_propagator = 1;
        exact_step(&s->propagator, state, held, rates, next);
    }
    for (i = 0; i < 6; i++) {
        force[i] = held[i] + rates[i] * step_size;
    }
    show(s, data, next, force);
    return halfshafts_show(s->shafts, data, s->failure);
}

/* Model Exchange (PowertrainMountsModel.evaluate): the derivatives, accelerations and mount forces at the
 * solver's state (q, q', z) under the inputs now, M q'' + C q' + K q + R^T z = G u (the characteristics' forces
 * for progressive mounts), z' = g (R q') - z / tau; the branches' forces are the states of their slots (those of
 * mounts without rubber idle: shown 0, their rates 0); the static sag and modal table stay as the initialisation
 * left them (functions of the parameters alone). */
static Failure evaluate(ModelData *data, double time UNUSED)
{
    System *s = data->cache->derived;
    double force[6], state[MAX_STATE] = {0};
    int i;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    generalised(s, data, 0, force);
    for (i = 0; i < 12; i++) {
        state[i] = data->real_value[STATE_VARIABLES[i]];
    }
    for (i = 0; i < s->branches.count; i++) {
        state[12 + i] = data->real_value[BRANCH_VARIABLES[s->branches.slots[i]]];
    }
    show(s, data, state, force);
    return halfshafts_show(s->shafts, data, s->failure);
}

/* Directional derivatives (MountSystem.derivative_jacobian): linear mounts' partials are constant, progressive
 * ones' take the tangent rates F'(d) at the state's deflections. The accelerations (A s + B G u)[6:]
 * (-M^-1 K_t(Q) for the displacements) by the states and the loads (their rates: none, as in evaluate), the
 * branches' rates A[12:] by the velocities and their own force, each mount's force by the motion and its
 * branches (show's mount forces); the states' own rows and der(<state>)'s are the layer's. */
static Failure jacobian(const ModelData *data, double partial[])
{
    const System *s = data->cache->derived;
    double tangent[6][6], rates[MOUNTS_LAYOUT_MAX_MOUNTS][3], q[6];
    int i, j, k, n;
    if (s == NULL) {
        return FAILURE(ERROR_RUNTIME, "the powertrain was not built");
    }
    for (i = 0; i < 6; i++) {
        q[i] = s->weight_sag[i] + data->real_value[STATE_VARIABLES[i]];
    }
    if (s->progressive) {
        forces_tangent_stiffness(&s->layout, MAPS(s), q, tangent);
    }
    for (n = 0; n < s->layout.count; n++) {
        for (k = 0; k < 3; k++) {
            double d = 0.0;
            for (j = 0; j < 6; j++) {
                d += s->maps[n][k][j] * q[j];
            }
            rates[n][k] = s->progressive ? characteristic_tangent(&s->layout.mounts[n], k, d)
                                         : s->layout.mounts[n].stiffness[k];
        }
    }
    for (i = 0; i < 6; i++) {
        double *row = partial + model_jacobian_rows[ACCELERATION_VARIABLES[i]] * MODEL_COLUMN_COUNT;
        for (k = 0; k < 12; k++) {
            double value = s->a[6 + i][k];
            if (s->progressive && k < 6) {
                value = 0.0;
                for (j = 0; j < 6; j++) {
                    value -= s->b[6 + i][j] * tangent[j][k];
                }
            }
            row[model_jacobian_columns[STATE_VARIABLES[k]]] = value;
        }
        for (k = 0; k < s->branches.count; k++) {
            row[model_jacobian_columns[BRANCH_VARIABLES[s->branches.slots[k]]]] = s->a[6 + i][12 + k];
        }
        for (k = 0; k < N_INPUTS; k++) {
            double sum = 0.0;
            for (j = 0; j < 6; j++) {
                sum += s->b[6 + i][j] * s->inputs[j][k];
            }
            row[model_jacobian_columns[model_input_derivatives[k].input]] = sum;
        }
    }
    for (k = 0; k < s->branches.count; k++) {
        double *row = partial + model_jacobian_rows[BRANCH_RATE_VARIABLES[s->branches.slots[k]]] * MODEL_COLUMN_COUNT;
        for (j = 0; j < 6; j++) {
            row[model_jacobian_columns[STATE_VARIABLES[6 + j]]] = s->a[12 + k][6 + j];
        }
        row[model_jacobian_columns[BRANCH_VARIABLES[s->branches.slots[k]]]] = s->a[12 + k][12 + k];
    }
    for (n = 0; n < s->layout.count; n++) {
        const Mount *m = &s->layout.mounts[n];
        for (i = 0; i < 3; i++) {
            double *row = partial + model_jacobian_rows[V_F_x_mount1 + 3 * n + i] * MODEL_COLUMN_COUNT;
            for (j = 0; j < 6; j++) {
                double moved = 0.0, speed = 0.0;
                for (k = 0; k < 3; k++) {
                    moved -= m->axes[k][i] * rates[n][k] * s->maps[n][k][j];
                    speed -= m->axes[k][i] * m->damping[k] * s->maps[n][k][j];
                }
                row[model_jacobian_columns[STATE_VARIABLES[j]]] = moved;
                row[model_jacobian_columns[STATE_VARIABLES[6 + j]]] = speed;
            }
            for (k = 0; k < 3 * m->branch_count; k++) { /* its branches, along axis k / branch_count */
                int slot = 3 * n * MOUNTS_RUBBER_BRANCHES + k;
                row[model_jacobian_columns[BRANCH_VARIABLES[slot]]] = -m->axes[k / m->branch_count][i];
            }
        }
    }
    return halfshafts_partials(s->shafts, data, partial); /* after the accelerations' rows, which it reads */
}

const ModelHooks model_hooks = {.start = start, .advance = advance, .evaluate = evaluate,
                                .extra_parameter_errors = extra_parameter_errors, .free_derived = free_system,
                                .jacobian = jacobian};
