/* No-physics twin of a native model, the floor of the native FMUs for the step-cost benchmark.
 *
 * Built with the model's generated variable table, so it has the same variables, range checks
 * and FMI traffic; every Real output takes the first Real input's value (the time if there is
 * none), as the Python twins of benchmarks/minimal_models.py do.
 */
#include "fmi/fmu_instance.h"

static Failure copy_first_input(ModelData *data, double time)
{
    double value = time;
    int i, found = 0;
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (!found && model_variables[i].causality == CAUSALITY_INPUT && model_variables[i].type == VAR_REAL) {
            value = data->real_value[i];
            found = 1;
        }
    }
    for (i = 0; i < MODEL_VARIABLE_COUNT; i++) {
        if (model_variables[i].causality == CAUSALITY_OUTPUT && model_variables[i].type == VAR_REAL) {
            data->real_value[i] = value;
        }
    }
    return NO_FAILURE;
}

const ModelHooks model_hooks = {.at_time = copy_first_input};
