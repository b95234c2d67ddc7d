/* Per-step cost of a native FMU from a C host (no Python in the process), for the benchmarks.
 *
 * Usage: native_step_timer LIBRARY 2|3 TOKEN STEP_SIZE STEPS ROUNDS "IN_VR..." "OUT_VR..." RESOURCES
 *        ["VR=VALUE..."]
 * Instantiates the FMU with its extracted RESOURCES folder (an absolute path: its shipped layouts),
 * initialises it at its start values (the optional Integer parameters set in initialisation mode),
 * then times ROUNDS rounds of STEPS steps, each one batched set of the Real inputs (their start
 * values), doStep and one batched get of the Real outputs; prints the best round's CPU nanoseconds per step.
 */
#define _POSIX_C_SOURCE 199309L
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

#define MAX_SIGNALS 128

static void logger2(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...)
{
    (void)environment;
    (void)name;
    (void)status;
    (void)category;
    (void)message;
}

static void logger3(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)environment;
    (void)status;
    (void)category;
    (void)message;
}

static int parse(const char *text, unsigned int vr[])
{
    int count = 0, used;
    while (count < MAX_SIGNALS && sscanf(text, "%u%n", &vr[count], &used) == 1) {
        text += used;
        count++;
    }
    return count;
}

/* "vr=value vr=value ...": Integer parameters. */
static int parse_integers(const char *text, unsigned int vr[], int value[])
{
    int count = 0, used;
    while (count < MAX_SIGNALS && sscanf(text, " %u=%d%n", &vr[count], &value[count], &used) == 2) {
        text += used;
        count++;
    }
    return count;
}

static void *symbol(void *library, const char *name)
{
    void *found = dlsym(library, name);
    if (found == NULL) {
        fprintf(stderr, "missing %s\n", name);
        exit(2);
    }
    return found;
}

#define LOAD(pointer, name) memcpy(&(pointer), &(void *){symbol(library, name)}, sizeof(void *))

static double seconds(void)
{
    struct timespec now;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &now);
    return (double)now.tv_sec + 1e-9 * (double)now.tv_nsec;
}

int main(int argc, char **argv)
{
    unsigned int in[MAX_SIGNALS], out[MAX_SIGNALS], integer_vr[MAX_SIGNALS];
    double values[MAX_SIGNALS], results[MAX_SIGNALS], h, t = 0.0, best = 1e300;
    int inputs, outputs, integers, integer[MAX_SIGNALS], steps, rounds, round, k, fmi3;
    void *library, *instance;
    char resources[4096];
    if (argc != 10 && argc != 11) {
        fprintf(stderr, "usage: native_step_timer LIBRARY 2|3 TOKEN STEP_SIZE STEPS ROUNDS IN_VRS OUT_VRS RESOURCES "
                        "[VR=VALUE...]\n");
        return 2;
    }
    fmi3 = argv[2][0] == '3';
    h = atof(argv[4]);
    steps = atoi(argv[5]);
    rounds = atoi(argv[6]);
    inputs = parse(argv[7], in);
    outputs = parse(argv[8], out);
    integers = argc == 11 ? parse_integers(argv[10], integer_vr, integer) : 0;
    snprintf(resources, sizeof resources, fmi3 ? "%s/" : "file://%s", argv[9]);
    library = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
    if (library == NULL || steps < 1 || rounds < 1) {
        fprintf(stderr, "cannot load %s\n", argv[1]);
        return 2;
    }
    if (fmi3) {
        fmi3InstantiateCoSimulationTYPE *instantiate;
        fmi3EnterInitializationModeTYPE *enter;
        fmi3ExitInitializationModeTYPE *leave;
        fmi3SetFloat64TYPE *set;
        fmi3SetInt32TYPE *set_integer;
        fmi3GetFloat64TYPE *get;
        fmi3DoStepTYPE *step;
        fmi3FreeInstanceTYPE *release;
        fmi3Boolean event, terminate, early;
        fmi3Float64 last;
        LOAD(instantiate, "fmi3InstantiateCoSimulation");
        LOAD(enter, "fmi3EnterInitializationMode");
        LOAD(leave, "fmi3ExitInitializationMode");
        LOAD(set, "fmi3SetFloat64");
        LOAD(set_integer, "fmi3SetInt32");
        LOAD(get, "fmi3GetFloat64");
        LOAD(step, "fmi3DoStep");
        LOAD(release, "fmi3FreeInstance");
        instance = instantiate("timer", argv[3], resources, 0, 0, 0, 0, NULL, 0, NULL, logger3, NULL);
        if (instance == NULL || enter(instance, 0, 0.0, 0.0, 0, 0.0) != fmi3OK ||
            set_integer(instance, integer_vr, (size_t)integers, integer, (size_t)integers) != fmi3OK ||
            leave(instance) != fmi3OK ||
            get(instance, in, (size_t)inputs, values, (size_t)inputs) != fmi3OK) {
            return 3;
        }
        for (round = 0; round < rounds; round++) {
            double start = seconds();
            for (k = 0; k < steps; k++) {
                set(instance, in, (size_t)inputs, values, (size_t)inputs);
                if (step(instance, t, h, 1, &event, &terminate, &early, &last) != fmi3OK) {
                    return 4;
                }
                get(instance, out, (size_t)outputs, results, (size_t)outputs);
                t += h;
            }
            double elapsed = seconds() - start;
            best = elapsed < best ? elapsed : best;
        }
        release(instance);
    } else {
        fmi2CallbackFunctions callbacks = {logger2, calloc, free, NULL, NULL};
        fmi2InstantiateTYPE *instantiate;
        fmi2SetupExperimentTYPE *setup;
        fmi2EnterInitializationModeTYPE *enter;
        fmi2ExitInitializationModeTYPE *leave;
        fmi2SetRealTYPE *set;
        fmi2SetIntegerTYPE *set_integer;
        fmi2GetRealTYPE *get;
        fmi2DoStepTYPE *step;
        fmi2FreeInstanceTYPE *release;
        LOAD(instantiate, "fmi2Instantiate");
        LOAD(setup, "fmi2SetupExperiment");
        LOAD(enter, "fmi2EnterInitializationMode");
        LOAD(leave, "fmi2ExitInitializationMode");
        LOAD(set, "fmi2SetReal");
        LOAD(set_integer, "fmi2SetInteger");
        LOAD(get, "fmi2GetReal");
        LOAD(step, "fmi2DoStep");
        LOAD(release, "fmi2FreeInstance");
        instance = instantiate("timer", fmi2CoSimulation, argv[3], resources, &callbacks, 0, 0);
        if (instance == NULL || setup(instance, 0, 0.0, 0.0, 0, 0.0) != fmi2OK || enter(instance) != fmi2OK ||
            set_integer(instance, integer_vr, (size_t)integers, integer) != fmi2OK || leave(instance) != fmi2OK || get(instance, in, (size_t)inputs, values) != fmi2OK) {
            return 3;
        }
        for (round = 0; round < rounds; round++) {
            double start = seconds();
            for (k = 0; k < steps; k++) {
                set(instance, in, (size_t)inputs, values);
                if (step(instance, t, h, 1) != fmi2OK) {
                    return 4;
                }
                get(instance, out, (size_t)outputs, results);
                t += h;
            }
            double elapsed = seconds() - start;
            best = elapsed < best ? elapsed : best;
        }
        release(instance);
    }
    dlclose(library);
    printf("%.1f\n", best / steps * 1e9);
    return 0;
}
