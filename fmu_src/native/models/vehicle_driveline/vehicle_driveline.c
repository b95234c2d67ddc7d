/* VehicleDriveline: a front-wheel-drive car between the motor and the road without the joints (port of
 * driveline/vehicle/dynamics.py and model.py).
 *
 * (V1)-(V9) are the labels of docs/vehicle_driveline.md. The state (dynamics.py's tuple, in its
 * order) is the model's internal state; every expression keeps the Python core's order of
 * operations, and where Python's float division or math.ceil raises, the step is refused with
 * Python's words.
 */
#include <math.h>
#include <stdio.h>

#include "driveline_constants.h"
#include "fmi/fmu_instance.h"

#define STATE (data->internal) /* dynamics.py's state tuple, VEHICLE_DYNAMICS_STATE_SIZE numbers */

enum { CASE, DIFF, PHI_WHEEL_LEFT, WHEEL_LEFT, PHI_WHEEL_RIGHT, WHEEL_RIGHT, SPEED, TRAVEL, SLIP_LEFT, SLIP_RIGHT };

static const char ZERO_DIVISION[] = "float division by zero"; /* ZeroDivisionError */

/* The joints' inputs at the communication point (dynamics.Joints). */
typedef struct {
    double T_in_left, T_in_right, phi_out_left, phi_out_right, omega_out_left, omega_out_right;
} Joints;

/* Python's float division: where it raises, the first failure is kept and the result is 0 (the
 * evaluation's results are then discarded). */
static double divide(Failure *failure, double a, double b)
{
    if (b != 0.0) {
        return a / b;
    }
    if (failure->kind == ERROR_NONE) {
        *failure = FAILURE(ERROR_ZERO_DIVISION, ZERO_DIVISION);
    }
    return 0.0;
}

/* VehicleDrivelineModel._joints: in the drive's sense (the right joint's frame turns the other way) */
static Joints joints_of(const ModelData *data)
{
    Joints joints = {VALUE(T_in_left), -VALUE(T_in_right), VALUE(phi_out_left), -VALUE(phi_out_right),
                     VALUE(omega_out_left), -VALUE(omega_out_right)};
    return joints;
}

/* (V1) case_inertia */
static double case_inertia(const ModelData *data)
{
    return VALUE(ratio) * VALUE(ratio) * VALUE(J_motor) + VALUE(J_diff) + 2.0 * VALUE(J_side);
}

/* (V7) equivalent_mass */
static double equivalent_mass(const ModelData *data, Failure *failure)
{
    return VALUE(m_vehicle) + divide(failure, 2.0 * VALUE(J_wheel), VALUE(r_wheel) * VALUE(r_wheel));
}

/* wheel_load */
static double wheel_load(const ModelData *data)
{
    return VALUE(m_vehicle) * VEHICLE_DYNAMICS_GRAVITY * cos(VALUE(grade)) * VALUE(front_share) / 2.0;
}

/* (V5) tyre_force */
static double tyre_force(const ModelData *data, Failure *failure, double slip, double mu)
{
    double limit = mu * wheel_load(data);
    return limit * tanh(divide(failure, VALUE(C_slip) * slip, limit));
}

/* (V3) halfshaft_torques */
static void halfshaft_torques(const ModelData *data, const double *state, const Joints *joints, double elapsed,
                              double *left, double *right)
{
    double twist_left = joints->phi_out_left + joints->omega_out_left * elapsed - state[PHI_WHEEL_LEFT];
    double twist_right = joints->phi_out_right + joints->omega_out_right * elapsed - state[PHI_WHEEL_RIGHT];
    *left = VALUE(k_left) * twist_left + VALUE(c_left) * (joints->omega_out_left - state[WHEEL_LEFT]);
    *right = VALUE(k_right) * twist_right + VALUE(c_right) * (joints->omega_out_right - state[WHEEL_RIGHT]);
}

/* (V8) road_load */
static double road_load(const ModelData *data, Failure *failure, double v)
{
    double weight = VALUE(m_vehicle) * VEHICLE_DYNAMICS_GRAVITY;
    double rolling = VALUE(f_roll) * weight * cos(VALUE(grade)) * tanh(divide(failure, v, VALUE(v_low)));
    double drag = 0.5 * VALUE(rho_air) * VALUE(c_drag) * VALUE(A_front) * v * fabs(v);
    return rolling + drag + weight * sin(VALUE(grade));
}

/* (V1)-(V9) rates */
static void rates(const ModelData *data, Failure *failure, const double *state, const Joints *joints,
                  double elapsed, double *rate)
{
    double T_left, T_right, v = state[SPEED], slip_speed;
    double F_left = tyre_force(data, failure, state[SLIP_LEFT], VALUE(mu_road_left));
    double F_right = tyre_force(data, failure, state[SLIP_RIGHT], VALUE(mu_road_right));
    halfshaft_torques(data, state, joints, elapsed, &T_left, &T_right);
    slip_speed = fabs(v) + VALUE(v_low);
    rate[CASE] = divide(failure, VALUE(ratio) * VALUE(T_motor) - joints->T_in_left - joints->T_in_right,
                        case_inertia(data));
    rate[DIFF] = divide(failure, joints->T_in_right - joints->T_in_left, 2.0 * VALUE(J_side));
    rate[PHI_WHEEL_LEFT] = state[WHEEL_LEFT];
    rate[WHEEL_LEFT] = divide(failure, T_left - VALUE(r_wheel) * F_left, VALUE(J_wheel));
    rate[PHI_WHEEL_RIGHT] = state[WHEEL_RIGHT];
    rate[WHEEL_RIGHT] = divide(failure, T_right - VALUE(r_wheel) * F_right, VALUE(J_wheel));
    rate[SPEED] = divide(failure, F_left + F_right - road_load(data, failure, v), equivalent_mass(data, failure));
    rate[TRAVEL] = v;
    rate[SLIP_LEFT] = divide(failure, VALUE(r_wheel) * state[WHEEL_LEFT] - v - slip_speed * state[SLIP_LEFT],
                             VALUE(sigma_slip));
    rate[SLIP_RIGHT] = divide(failure, VALUE(r_wheel) * state[WHEEL_RIGHT] - v - slip_speed * state[SLIP_RIGHT],
                              VALUE(sigma_slip));
}

/* rate_bound */
static double rate_bound(const ModelData *data, Failure *failure, double v)
{
    double J = VALUE(J_wheel), r = VALUE(r_wheel), mass;
    double tyre = sqrt(divide(failure, VALUE(C_slip) * r * r, J * VALUE(sigma_slip)));
    double slip_decay = divide(failure, fabs(v) + VALUE(v_low), VALUE(sigma_slip));
    double left = sqrt(divide(failure, VALUE(k_left), J)) + divide(failure, VALUE(c_left), J);
    double right = sqrt(divide(failure, VALUE(k_right), J)) + divide(failure, VALUE(c_right), J);
    double wheel = right > left ? right : left; /* Python's max: the second only if greater */
    double car;
    mass = equivalent_mass(data, failure);
    car = sqrt(divide(failure, 2.0 * VALUE(C_slip), VALUE(sigma_slip) * mass)) +
          divide(failure, VALUE(f_roll) * VALUE(m_vehicle) * VEHICLE_DYNAMICS_GRAVITY, VALUE(v_low) * mass) +
          divide(failure, VALUE(rho_air) * VALUE(c_drag) * VALUE(A_front) * fabs(v), mass);
    return wheel + tyre + slip_decay + car;
}

/* substeps: the fewest internal steps with rate_bound * h_int <= RATE_STEP */
static Failure substeps(const ModelData *data, double v, double step_size, long *count)
{
    Failure failure = NO_FAILURE;
    double bound = rate_bound(data, &failure, v), steps;
    if (failure.kind != ERROR_NONE) {
        return failure;
    }
    steps = ceil(step_size * bound / VEHICLE_DYNAMICS_RATE_STEP);
    if (isnan(steps)) {
        return FAILURE(ERROR_VALUE, "cannot convert float NaN to integer");
    }
    if (isinf(steps)) {
        return FAILURE(ERROR_OVERFLOW, "cannot convert float infinity to integer");
    }
    if (!(steps <= VEHICLE_DYNAMICS_MAX_SUBSTEPS)) {
        return FAILURE(ERROR_VALUE, TOO_LONG);
    }
    *count = steps >= 1.0 ? (long)steps : 1;
    return NO_FAILURE;
}

static void moved(const double *state, const double *slope, double h, double *out)
{
    int i;
    for (i = 0; i < VEHICLE_DYNAMICS_STATE_SIZE; i++) {
        out[i] = state[i] + h * slope[i];
    }
}

/* advance of dynamics.py: classical Runge-Kutta in equal internal steps, the inputs held */
static Failure integrate(ModelData *data, const Joints *joints, double step_size)
{
    double k1[VEHICLE_DYNAMICS_STATE_SIZE], k2[VEHICLE_DYNAMICS_STATE_SIZE], k3[VEHICLE_DYNAMICS_STATE_SIZE];
    double k4[VEHICLE_DYNAMICS_STATE_SIZE], trial[VEHICLE_DYNAMICS_STATE_SIZE], h, t;
    long count = 1, n;
    int i;
    Failure failure = substeps(data, STATE[SPEED], step_size, &count);
    if (failure.kind != ERROR_NONE) {
        return failure;
    }
    h = step_size / (double)count;
    for (n = 0; n < count; n++) {
        t = (double)n * h;
        rates(data, &failure, STATE, joints, t, k1);
        moved(STATE, k1, 0.5 * h, trial);
        rates(data, &failure, trial, joints, t + 0.5 * h, k2);
        moved(STATE, k2, 0.5 * h, trial);
        rates(data, &failure, trial, joints, t + 0.5 * h, k3);
        moved(STATE, k3, h, trial);
        rates(data, &failure, trial, joints, t + h, k4);
        if (failure.kind != ERROR_NONE) {
            return failure;
        }
        for (i = 0; i < VEHICLE_DYNAMICS_STATE_SIZE; i++) {
            STATE[i] = STATE[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
    }
    return NO_FAILURE;
}

/* (V9) the inertia of the rotating parts' angular momentum at the case's speed (reaction_torque) */
static double momentum_inertia(const ModelData *data)
{
    return VALUE(ratio) * VALUE(J_motor) + VALUE(J_diff) + 2.0 * VALUE(J_side);
}

/* (V9) reaction_torque */
static double reaction_torque(const ModelData *data, const Joints *joints, double case_acceleration)
{
    return -(joints->T_in_left + joints->T_in_right) - momentum_inertia(data) * case_acceleration;
}

/* VehicleDrivelineModel._evaluate: outputs at the state reached ``elapsed`` after the inputs' time */
static Failure evaluate(ModelData *data, const Joints *joints, double elapsed)
{
    double rate[VEHICLE_DYNAMICS_STATE_SIZE], left, right;
    Failure failure = NO_FAILURE;
    rates(data, &failure, STATE, joints, elapsed, rate);
    VALUE(omega_in_left) = STATE[CASE] + STATE[DIFF];
    VALUE(omega_in_right) = -(STATE[CASE] - STATE[DIFF]);
    VALUE(alpha_in_left) = rate[CASE] + rate[DIFF];
    VALUE(alpha_in_right) = -(rate[CASE] - rate[DIFF]);
    halfshaft_torques(data, STATE, joints, elapsed, &left, &right);
    VALUE(T_load_left) = left;
    VALUE(T_load_right) = -right;
    VALUE(T_reaction) = reaction_torque(data, joints, rate[CASE]);
    VALUE(omega_motor) = VALUE(ratio) * STATE[CASE];
    VALUE(omega_wheel_left) = STATE[WHEEL_LEFT];
    VALUE(omega_wheel_right) = STATE[WHEEL_RIGHT];
    VALUE(slip_left) = STATE[SLIP_LEFT];
    VALUE(slip_right) = STATE[SLIP_RIGHT];
    VALUE(F_x_left) = tyre_force(data, &failure, STATE[SLIP_LEFT], VALUE(mu_road_left));
    VALUE(F_x_right) = tyre_force(data, &failure, STATE[SLIP_RIGHT], VALUE(mu_road_right));
    VALUE(v_x) = STATE[SPEED];
    VALUE(a_x) = rate[SPEED];
    VALUE(x) = STATE[TRAVEL];
    VALUE(phi_wheel_left) = STATE[PHI_WHEEL_LEFT];
    VALUE(phi_wheel_right) = STATE[PHI_WHEEL_RIGHT];
    VALUE(alpha_wheel_left) = rate[WHEEL_LEFT];
    VALUE(alpha_wheel_right) = rate[WHEEL_RIGHT];
    VALUE(slip_dot_left) = rate[SLIP_LEFT];
    VALUE(slip_dot_right) = rate[SLIP_RIGHT];
    return failure;
}

static void reset_internal(ModelData *data)
{
    int i;
    for (i = 0; i < VEHICLE_DYNAMICS_STATE_SIZE; i++) {
        STATE[i] = 0.0;
    }
}

/* start_state: rolling at v_start without slip, each wheel at its joint's output angle */
static Failure start(ModelData *data, double UNUSED start_time)
{
    Joints joints = joints_of(data);
    Failure failure = NO_FAILURE;
    double omega = divide(&failure, VALUE(v_start), VALUE(r_wheel));
    double state[VEHICLE_DYNAMICS_STATE_SIZE] = {0.0};
    int i;
    state[CASE] = omega;
    state[PHI_WHEEL_LEFT] = joints.phi_out_left;
    state[WHEEL_LEFT] = omega;
    state[PHI_WHEEL_RIGHT] = joints.phi_out_right;
    state[WHEEL_RIGHT] = omega;
    state[SPEED] = VALUE(v_start);
    if (failure.kind != ERROR_NONE) {
        return failure;
    }
    for (i = 0; i < VEHICLE_DYNAMICS_STATE_SIZE; i++) {
        STATE[i] = state[i];
    }
    return evaluate(data, &joints, 0.0);
}

static Failure advance(ModelData *data, double UNUSED current_time, double step_size)
{
    Joints joints = joints_of(data);
    Failure failure = integrate(data, &joints, step_size);
    return failure.kind != ERROR_NONE ? failure : evaluate(data, &joints, step_size);
}

/* internal_modes, one side: a side gear against its halfshaft; without stiffness no oscillation */
static void internal_mode(const ModelData *data, double k, double c, double *omega, double *zeta)
{
    *omega = sqrt(k / VALUE(J_side));
    *zeta = k > 0.0 ? c / (2.0 * sqrt(k * VALUE(J_side))) : HUGE_VAL;
}

/* jacobi_step_limit (``jacobi``: omega h <= min(JACOBI_OMEGA_STEP, JACOBI_DAMPING_STEP zeta)) or
 * divergence_step_limit (omega h <= DIVERGENCE_OMEGA_STEP): the shorter side's; inf without stiffness */
static double step_limit(const ModelData *data, int jacobi)
{
    double omega[2], zeta[2], limit = HUGE_VAL, side_limit, damped;
    int i;
    internal_mode(data, VALUE(k_left), VALUE(c_left), &omega[0], &zeta[0]);
    internal_mode(data, VALUE(k_right), VALUE(c_right), &omega[1], &zeta[1]);
    for (i = 0; i < 2; i++) {
        if (omega[i] > 0.0) {
            damped = VEHICLE_DYNAMICS_JACOBI_DAMPING_STEP * zeta[i];
            side_limit = jacobi ? fmin(VEHICLE_DYNAMICS_JACOBI_OMEGA_STEP, damped)
                                : VEHICLE_DYNAMICS_DIVERGENCE_OMEGA_STEP;
            side_limit = side_limit / omega[i];
            limit = side_limit < limit ? side_limit : limit;
        }
    }
    return limit;
}

/* modes_text's four numbers (39 characters at most) and its words, never cut (gcc's -Wformat-truncation) */
#define MODES_TEXT_SIZE 256

/* modes_text, in ``text`` (MODES_TEXT_SIZE characters) */
static void modes_text(const ModelData *data, char *text, size_t size)
{
    char shown[4][40];
    double omega, zeta;
    internal_mode(data, VALUE(k_left), VALUE(c_left), &omega, &zeta);
    python_format_g(omega, 4, shown[0], sizeof shown[0]);
    python_format_g(zeta, 3, shown[1], sizeof shown[1]);
    internal_mode(data, VALUE(k_right), VALUE(c_right), &omega, &zeta);
    python_format_g(omega, 4, shown[2], sizeof shown[2]);
    python_format_g(zeta, 3, shown[3], sizeof shown[3]);
    snprintf(text, size, "left %s rad/s, damping ratio %s; right %s rad/s, damping ratio %s", shown[0], shown[1],
             shown[2], shown[3]);
}

/* step_limit_notice: a step above the Jacobi limit */
static void step_notice(const ModelData *data, double step_size, Messages *out)
{
    char modes[MODES_TEXT_SIZE], limit[40], omega_step[40], damping_step[40], divergence[40], divergence_step[40];
    double jacobi = step_limit(data, 1);
    if (!(step_size > jacobi)) {
        return;
    }
    modes_text(data, modes, sizeof modes);
    python_format_g(jacobi, 3, limit, sizeof limit);
    python_float_repr(VEHICLE_DYNAMICS_JACOBI_OMEGA_STEP, omega_step, sizeof omega_step);
    python_float_repr(VEHICLE_DYNAMICS_JACOBI_DAMPING_STEP, damping_step, sizeof damping_step);
    python_format_g(step_limit(data, 0), 3, divergence, sizeof divergence);
    python_float_repr(VEHICLE_DYNAMICS_DIVERGENCE_OMEGA_STEP, divergence_step, sizeof divergence_step);
    messages_add(out, "communication steps above ", limit, " s let the differential's internal mode (", modes,
                 ") diverge in a Jacobi master, the joints' torques one step late (omega h <= min(", omega_step, ", ",
                 damping_step, " zeta)); a Gauss-Seidel master stepping the drive before its joints may hold longer, "
                 "never beyond ", divergence, " s (omega h = ", divergence_step, ")", (const char *)NULL);
}

/* step_limit_errors: a step at which the coupled drive diverges in any master's order */
static void step_size_errors(const ModelData *data, double step_size, Messages *out)
{
    char modes[MODES_TEXT_SIZE], step[40], limit[40], divergence_step[40], jacobi[40];
    double longest = step_limit(data, 0);
    if (!(step_size > longest)) {
        return;
    }
    modes_text(data, modes, sizeof modes);
    python_float_repr(step_size, step, sizeof step);
    python_format_g(longest, 3, limit, sizeof limit);
    python_float_repr(VEHICLE_DYNAMICS_DIVERGENCE_OMEGA_STEP, divergence_step, sizeof divergence_step);
    python_format_g(step_limit(data, 1), 3, jacobi, sizeof jacobi);
    messages_add(out, "communication step ", step, " s is above ", limit, " s, where the differential's internal "
                 "mode (", modes, ") diverges coupled to the joints in any master's order (omega h > ",
                 divergence_step, "; a Jacobi master needs ", jacobi, " s or less): take a shorter step",
                 (const char *)NULL);
}

/* Model Exchange: the state from the spec's states, the solver's (the side gears' speeds give the case's
 * and the differential's), the outputs and the derivatives at the inputs of this instant */
static Failure evaluate_now(ModelData *data, double UNUSED time)
{
    Joints joints = joints_of(data);
    STATE[CASE] = (VALUE(omega_in_left) - VALUE(omega_in_right)) / 2.0;
    STATE[DIFF] = (VALUE(omega_in_left) + VALUE(omega_in_right)) / 2.0;
    STATE[PHI_WHEEL_LEFT] = VALUE(phi_wheel_left);
    STATE[WHEEL_LEFT] = VALUE(omega_wheel_left);
    STATE[PHI_WHEEL_RIGHT] = VALUE(phi_wheel_right);
    STATE[WHEEL_RIGHT] = VALUE(omega_wheel_right);
    STATE[SPEED] = VALUE(v_x);
    STATE[TRAVEL] = VALUE(x);
    STATE[SLIP_LEFT] = VALUE(slip_left);
    STATE[SLIP_RIGHT] = VALUE(slip_right);
    return evaluate(data, &joints, 0.0);
}

/* (V5) differentiated: dF_x / d slip = C_slip / cosh^2(C_slip slip / (mu F_z)), smooth, falling to 0 where
 * the force saturates */
static double tyre_slope(const ModelData *data, double slip, double mu)
{
    double growth = cosh(VALUE(C_slip) * slip / (mu * wheel_load(data)));
    return VALUE(C_slip) / (growth * growth);
}

/* (V8) differentiated: rolling resistance's f_roll m g cos(grade) / (v_low cosh^2(v / v_low)) and the drag's
 * rho_air c_drag A_front |v| (v |v| has the slope 2 |v|: continuous, no kink); the grade's term is constant */
static double road_load_slope(const ModelData *data, double v)
{
    double growth = cosh(v / VALUE(v_low));
    return VALUE(f_roll) * VALUE(m_vehicle) * VEHICLE_DYNAMICS_GRAVITY * cos(VALUE(grade)) /
               (VALUE(v_low) * growth * growth) +
           VALUE(rho_air) * VALUE(c_drag) * VALUE(A_front) * fabs(v);
}

/* One side's places in the Jacobian: the rows of its outputs, the columns of its joint's inputs and its
 * states, and the sign of its joint's frame in the drive's sense (joints_of: +1 left, -1 right). */
typedef struct {
    int T_load, alpha_wheel, F_x, slip_dot;
    int phi_out, omega_out, phi_wheel, omega_wheel, slip;
    double frame;
} Side;

static const Side LEFT = {ROW_T_load_left, ROW_alpha_wheel_left, ROW_F_x_left, ROW_slip_dot_left,
                          COLUMN_phi_out_left, COLUMN_omega_out_left, COLUMN_phi_wheel_left, COLUMN_omega_wheel_left,
                          COLUMN_slip_left, 1.0};
static const Side RIGHT = {ROW_T_load_right, ROW_alpha_wheel_right, ROW_F_x_right, ROW_slip_dot_right,
                           COLUMN_phi_out_right, COLUMN_omega_out_right, COLUMN_phi_wheel_right,
                           COLUMN_omega_wheel_right, COLUMN_slip_right, -1.0};

#define AT(row, column) (partial[(row) * MODEL_COLUMN_COUNT + (column)])

/* A side's halfshaft (V3, T_load in its joint's frame: frame times the drive's), wheel (V4), tyre (V5) and
 * slip (V6; d|v|/dv = sign_v) rows, with its tyre's share of a_x (V7: ``mass`` the equivalent mass) */
static void side_partials(const ModelData *data, double partial[], const Side *side, double k, double c, double mu,
                          double slip, double sign_v, double mass)
{
    double J = VALUE(J_wheel), r = VALUE(r_wheel), sigma = VALUE(sigma_slip);
    double slope = tyre_slope(data, slip, mu);
    AT(side->T_load, side->phi_out) = k;
    AT(side->T_load, side->phi_wheel) = -side->frame * k;
    AT(side->T_load, side->omega_out) = c;
    AT(side->T_load, side->omega_wheel) = -side->frame * c;
    AT(side->alpha_wheel, side->phi_out) = side->frame * k / J;
    AT(side->alpha_wheel, side->phi_wheel) = -k / J;
    AT(side->alpha_wheel, side->omega_out) = side->frame * c / J;
    AT(side->alpha_wheel, side->omega_wheel) = -c / J;
    AT(side->alpha_wheel, side->slip) = -r * slope / J;
    AT(side->F_x, side->slip) = slope;
    AT(ROW_a_x, side->slip) = slope / mass;
    AT(side->slip_dot, side->omega_wheel) = r / sigma;
    AT(side->slip_dot, COLUMN_v_x) = (-1.0 - sign_v * slip) / sigma;
    AT(side->slip_dot, side->slip) = -(fabs(VALUE(v_x)) + VALUE(v_low)) / sigma;
}

/* The exact partial derivatives of the outputs with respect to the inputs and the states, (V1)-(V9)
 * differentiated at the point evaluate_now has just evaluated (no internal step: the state is the solver's).
 * The case's and the differential's accelerations (V1, V2) and T_reaction (V9) are linear in the torques,
 * omega_motor in the side gears' speeds (case = (omega_in_left - omega_in_right) / 2), the halfshafts (V3) in
 * the angles and speeds; the tyre forces (V5) and the rolling resistance (V8) are smooth (tanh), the drag
 * v |v| has the continuous slope 2 |v|. The one kink is the slip speed |v| + v_low of (V6) at v_x = 0, where
 * the derivative with respect to v_x is the one for a growing v_x (d|v|/dv = 1). */
static Failure jacobian(const ModelData *data, double partial[])
{
    Failure failure = NO_FAILURE;
    double v = VALUE(v_x), sign_v = v >= 0.0 ? 1.0 : -1.0, mass = equivalent_mass(data, &failure);
    double case_inertia_inverse = 1.0 / case_inertia(data), diff_inverse = 1.0 / (2.0 * VALUE(J_side));
    double case_motor = VALUE(ratio) * case_inertia_inverse, momentum = momentum_inertia(data);
    PARTIAL(alpha_in_left, T_motor) = case_motor;
    PARTIAL(alpha_in_left, T_in_left) = -case_inertia_inverse - diff_inverse;
    PARTIAL(alpha_in_left, T_in_right) = case_inertia_inverse - diff_inverse;
    PARTIAL(alpha_in_right, T_motor) = -case_motor;
    PARTIAL(alpha_in_right, T_in_left) = case_inertia_inverse - diff_inverse;
    PARTIAL(alpha_in_right, T_in_right) = -case_inertia_inverse - diff_inverse;
    PARTIAL(T_reaction, T_motor) = -momentum * case_motor;
    PARTIAL(T_reaction, T_in_left) = -1.0 + momentum * case_inertia_inverse;
    PARTIAL(T_reaction, T_in_right) = 1.0 - momentum * case_inertia_inverse;
    PARTIAL(omega_motor, omega_in_left) = 0.5 * VALUE(ratio);
    PARTIAL(omega_motor, omega_in_right) = -0.5 * VALUE(ratio);
    side_partials(data, partial, &LEFT, VALUE(k_left), VALUE(c_left), VALUE(mu_road_left), VALUE(slip_left), sign_v,
                  mass);
    side_partials(data, partial, &RIGHT, VALUE(k_right), VALUE(c_right), VALUE(mu_road_right), VALUE(slip_right),
                  sign_v, mass);
    PARTIAL(a_x, v_x) = -road_load_slope(data, v) / mass;
    return failure;
}

const ModelHooks model_hooks = {
    .reset_internal = reset_internal, .start = start, .advance = advance, .evaluate = evaluate_now,
    .step_size_errors = step_size_errors, .step_notice = step_notice, .jacobian = jacobian};
