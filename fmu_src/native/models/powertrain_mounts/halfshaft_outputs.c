/* PowertrainMounts' halfshaft outputs (driveline/mounts/model.py: the halfshafts of extra_parameter_errors,
 * _show_halfshafts, _limit_error) and their rows of the Jacobian, over halfshaft.c's geometry. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fmi/fmu_instance.h"
#include "mounts.h"

const char *const mounts_sides[2] = {"left", "right"};
/* the first of each side's geometry outputs, the rest following in the order of HALFSHAFT_VALUES */
static const int GEOMETRY_VARIABLES[2] = {V_beta_left, V_beta_right};

void halfshafts_place(Halfshaft shafts[2], const ModelData *data, const double *centres, const double *frames,
                      const double gravity[3])
{
    static const int design[2][4] = {{V_l_left, V_beta_design_left, V_psi_design_left, V_plunge_design_left},
                                     {V_l_right, V_beta_design_right, V_psi_design_right, V_plunge_design_right}};
    const double *value = data->real_value;
    int side;
    for (side = 0; side < 2; side++) {
        halfshaft_place(&shafts[side], frames + 9 * side, centres + 3 * side, gravity, value[design[side][0]],
                        value[design[side][1]], value[design[side][2]], value[design[side][3]]);
    }
}

/* the motion shown: the states and the accelerations' outputs; 0 where one is not finite */
static int motion_of(const ModelData *data, double q[6], double velocity[6], double acceleration[6])
{
    int i, finite = 1;
    for (i = 0; i < 6; i++) {
        q[i] = data->real_value[model_states[i]];
        velocity[i] = data->real_value[model_states[6 + i]];
        acceleration[i] = data->real_value[model_state_derivatives[6 + i]];
        finite = finite && isfinite(q[i]) && isfinite(velocity[i]) && isfinite(acceleration[i]);
    }
    return finite;
}

Failure halfshafts_show(const Halfshaft shafts[2], ModelData *data, char *failure)
{
    double q[6], velocity[6], acceleration[6], values[HALFSHAFT_VALUES], reach;
    int side, i, finite = motion_of(data, q, velocity, acceleration);
    for (side = 0; side < 2; side++) {
        const Halfshaft *shaft = &shafts[side];
        if (!data->int_value[V_housing_motion]) {
            memcpy(values, shaft->design, sizeof values);
        } else if (!finite) {
            for (i = 0; i < HALFSHAFT_VALUES; i++) {
                values[i] = NAN;
            }
        } else if (!halfshaft_geometry(shaft, q, velocity, acceleration, values, NULL, &reach)) {
            char distance[40], length[40];
            python_format_g(reach, 6, distance, sizeof distance);
            python_format_g(shaft->length, 6, length, sizeof length);
            snprintf(failure, FMU_MESSAGE_SIZE, "the %s joint: the wheel centre lies %s m from the housing's axis, "
                     "beyond the halfshaft's length %s m", mounts_sides[side], distance, length);
            return FAILURE(ERROR_VALUE, failure);
        }
        for (i = 0; i < HALFSHAFT_VALUES; i++) {
            data->real_value[GEOMETRY_VARIABLES[side] + i] = values[i];
        }
    }
    return NO_FAILURE;
}

Failure halfshafts_limits(const ModelData *data, char *failure)
{
    static const int limits[2][3] = {{V_beta_max_left, V_plunge_min_left, V_plunge_max_left},
                                     {V_beta_max_right, V_plunge_min_right, V_plunge_max_right}};
    const double *value = data->real_value;
    char shown[40], bound[40];
    int side;
    for (side = 0; side < 2; side++) {
        double beta = value[GEOMETRY_VARIABLES[side]], plunge = value[GEOMETRY_VARIABLES[side] + 6];
        double low = value[limits[side][1]], high = value[limits[side][2]], limit = value[limits[side][0]];
        if (beta > limit) { /* in display units as Variable.shown: factor * value + offset */
            python_format_g(180.0 / FMU_PI * beta + 0.0, 6, shown, sizeof shown);
            python_format_g(180.0 / FMU_PI * limit + 0.0, 6, bound, sizeof bound);
            snprintf(failure, FMU_MESSAGE_SIZE, "the %s joint's bend at the start, %s deg, exceeds beta_max_%s = %s deg",
                     mounts_sides[side], shown, mounts_sides[side], bound);
            return FAILURE(ERROR_VALUE, failure);
        }
        if (!(low <= plunge && plunge <= high)) {
            python_format_g(1e3 * plunge + 0.0, 6, shown, sizeof shown);
            python_format_g(1e3 * (plunge < low ? low : high) + 0.0, 6, bound, sizeof bound);
            snprintf(failure, FMU_MESSAGE_SIZE, "the %s joint's plunge at the start, %s mm, lies beyond plunge_%s_%s = "
                     "%s mm (the joint's stroke)", mounts_sides[side], shown, plunge < low ? "min" : "max", mounts_sides[side],
                     bound);
            return FAILURE(ERROR_VALUE, failure);
        }
    }
    return NO_FAILURE;
}

Failure halfshafts_partials(const Halfshaft shafts[2], const ModelData *data, double partial[])
{
    double q[6], velocity[6], acceleration[6], values[HALFSHAFT_VALUES], found[HALFSHAFT_VALUES][HALFSHAFT_MOTION];
    double reach;
    int side, i, j, c;
    if (!data->int_value[V_housing_motion] || !motion_of(data, q, velocity, acceleration)) {
        return NO_FAILURE;
    }
    for (side = 0; side < 2; side++) {
        if (!halfshaft_geometry(&shafts[side], q, velocity, acceleration, values, found, &reach)) {
            return FAILURE(ERROR_VALUE, "the wheel centre lies beyond the halfshaft's reach");
        }
        for (j = 0; j < HALFSHAFT_VALUES; j++) {
            double *row = partial + model_jacobian_rows[GEOMETRY_VARIABLES[side] + j] * MODEL_COLUMN_COUNT;
            for (c = 0; c < MODEL_COLUMN_COUNT; c++) { /* through q'' */
                double sum = 0.0;
                for (i = 0; i < 6; i++) {
                    sum += found[j][12 + i] *
                           partial[model_jacobian_rows[model_state_derivatives[6 + i]] * MODEL_COLUMN_COUNT + c];
                }
                row[c] = sum;
            }
            for (i = 0; i < 12; i++) { /* and by the displacements and velocities directly */
                row[model_jacobian_columns[model_states[i]]] += found[j][i];
            }
        }
    }
    return NO_FAILURE;
}
