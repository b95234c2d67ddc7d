/* SpeedSource: shaft speed ramp plus sine, exact in time (port of driveline/source/model.py). */
#include <math.h>

#include "fmi/fmu_instance.h"


/* omega_out(t) = omega_out_start + ramp_rate t + a sin(w t), alpha_out = d(omega_out)/dt, phi_out its exact
 * integral. */
static Failure evaluate(ModelData *data, double t)
{
    double w = 2.0 * FMU_PI * VALUE(sine_frequency), a = VALUE(sine_amplitude);
    if (isinf(w * t)) {
        return FAILURE(ERROR_VALUE, "math domain error"); /* what Python's math.sin says of an infinite angle */
    }
    VALUE(omega_out) = VALUE(omega_out_start) + VALUE(ramp_rate) * t + a * sin(w * t);
    VALUE(alpha_out) = VALUE(ramp_rate) + a * w * cos(w * t);
    VALUE(phi_out) = VALUE(phi_out_start) + VALUE(omega_out_start) * t + 0.5 * VALUE(ramp_rate) * t * t +
                 (w > 0.0 ? a * (1.0 - cos(w * t)) / w : 0.0);
    return NO_FAILURE;
}

const ModelHooks model_hooks = {.at_time = evaluate, .evaluate = evaluate, .jacobian = jacobian_of_time_alone};
