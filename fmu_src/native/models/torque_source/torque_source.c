/* TorqueSource: a torque ramp to a level, then held, exact in time (port of driveline/torque/model.py). */
#include "fmi/fmu_instance.h"

/* ramp_share: 0 before t_ramp, 1 from t_ramp + ramp_time on, linear between */
static double ramp_share(double t, double t_ramp, double ramp_time)
{
    if (t < t_ramp) {
        return 0.0;
    }
    if (t >= t_ramp + ramp_time) {
        return 1.0;
    }
    return (t - t_ramp) / ramp_time;
}

static Failure evaluate(ModelData *data, double t)
{
    double share = ramp_share(t, VALUE(t_ramp), VALUE(ramp_time));
    VALUE(T_motor) = VALUE(T_start) + (VALUE(T_level) - VALUE(T_start)) * share;
    return NO_FAILURE;
}

const ModelHooks model_hooks = {.at_time = evaluate, .evaluate = evaluate, .jacobian = jacobian_of_time_alone};
