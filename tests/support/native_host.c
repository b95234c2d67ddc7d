/* A minimal co-simulation host with no Python in the process, for the native FMUs' tests.
 *
 * Usage: native_host LIBRARY FMI_VERSION(2|3) TOKEN SCENARIO [RESOURCES [OUTPUTS]]
 *
 * RESOURCES is the FMU's resources folder (handed over as a file URI in FMI 2.0, a path in 3.0;
 * "-" for none); OUTPUTS, a file the host writes the outputs it got to, one row per time, every
 * number with 17 significant digits (the reference of a run on another platform).
 * SCENARIO is a text file: "inputs N vr...", "outputs M vr...", "parameters P (vr value)...",
 * "integers Q (vr value)...", "booleans B (vr 0|1)...", "strings S (vr text)..." (parameters set in
 * initialisation mode; a text has no blanks; each is read back), "tolerance x", "limits M (floor weight)..."
 * (each output's scale floor and its tolerance as a multiple of x), "steps K h",
 * then K + 1 rows "t u_1..u_N y_1..y_M": the inputs at t_k and the outputs a reference FMU gave at
 * t_k (row 0: after initialisation). The host loads the FMU's shared library (dlopen; LoadLibrary in
 * its Windows build), runs two instances
 * side by side (the second must repeat the first bit for bit), stores, serializes and restores
 * the FMU state half way and replays the second half (bit for bit again), then sets the first
 * input to NaN (or steps by 0 if there is no input) and expects a refused step (Discard, a logged
 * reason, outputs unchanged) that ends fmusim's retry loop (retry_until_stopped) at once, logged once.
 * Before that it asks the second instance for the directional derivatives of the outputs with respect to
 * the inputs (a seed of ones): finite numbers, or Error with one logged reason from an FMU without them.
 * It prints the largest deviation from the reference, relative to each output's largest magnitude (at
 * least its floor) and divided by its weight, and exits 0 when every check held and that deviation is at
 * most the tolerance.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2FunctionTypes.h"
#include "fmi3FunctionTypes.h"

#define MAX_SIGNALS 512 /* PowertrainMounts: 323 Real outputs with the Maxwell branches' states and rates */
#define MAX_TEXT 4096

typedef struct {
    int inputs, outputs, steps, parameters, integers, booleans, strings;
    unsigned int input_vr[MAX_SIGNALS], output_vr[MAX_SIGNALS], parameter_vr[MAX_SIGNALS], integer_vr[MAX_SIGNALS],
        boolean_vr[MAX_SIGNALS], string_vr[MAX_SIGNALS];
    double parameter[MAX_SIGNALS];
    int integer[MAX_SIGNALS], boolean[MAX_SIGNALS];
    char *string[MAX_SIGNALS];
    double step_size, tolerance;
    double floor[MAX_SIGNALS], weight[MAX_SIGNALS]; /* each output's scale floor, its tolerance's multiple */
    double *time, *input, *expected; /* rows of the scenario */
} Scenario;

static int messages_logged = 0;
static const char *resources = NULL; /* the FMU's resources folder, if given */

static int fail(const char *what)
{
    fprintf(stderr, "native_host: %s\n", what);
    return 1;
}

/* ---- loading: dlopen, or LoadLibrary on Windows, behind open_library/symbol/close_library ------- */

#ifdef _WIN32
#include <windows.h>

static HMODULE library;

static int open_library(const char *path)
{
    library = LoadLibraryA(path);
    return library != NULL;
}

static const char *library_error(void)
{
    static char text[64];
    sprintf(text, "LoadLibrary failed (error %lu)", (unsigned long)GetLastError());
    return text;
}

static int symbol(const char *name, void *function_pointer)
{
    FARPROC found = GetProcAddress(library, name);
    memcpy(function_pointer, &found, sizeof found);
    return found != NULL;
}

static void close_library(void)
{
    FreeLibrary(library);
}
#else
#include <dlfcn.h>

static void *library;

static int open_library(const char *path)
{
    library = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    return library != NULL;
}

static const char *library_error(void)
{
    return dlerror();
}

static int symbol(const char *name, void *function_pointer)
{
    void *found = dlsym(library, name);
    memcpy(function_pointer, &found, sizeof found); /* object to function pointer, as POSIX allows */
    return found != NULL;
}

static void close_library(void)
{
    dlclose(library);
}
#endif

static int load(const char *name, void *function_pointer)
{
    if (!symbol(name, function_pointer)) {
        fprintf(stderr, "native_host: missing symbol %s\n", name);
        return 0;
    }
    return 1;
}

/* ---- the two FMI versions behind one small interface ------------------------------------------ */

typedef struct {
    void *(*instantiate)(const char *name, const char *token);
    int (*initialize)(void *instance);
    int (*set)(void *instance, const unsigned int vr[], size_t n, const double values[]);
    int (*set_integer)(void *instance, const unsigned int vr[], size_t n, const int values[]);
    int (*set_boolean)(void *instance, const unsigned int vr[], size_t n, const int values[]);
    /* sets the strings and reads them back: 1 when they arrived as set */
    int (*set_string)(void *instance, const unsigned int vr[], size_t n, char *const values[]);
    int (*get)(void *instance, const unsigned int vr[], size_t n, double values[]);
    int (*step)(void *instance, double time, double step_size);
    int (*store)(void *instance, void **state);          /* get, serialize, deserialize: the copy */
    int (*restore)(void *instance, void *state);
    void (*release)(void *instance, void **state);
    void (*finish)(void *instance);
    int (*stops)(void *instance); /* after a Discard: the FMU asks the master to stop */
    /* the FMI status of the directional derivative of ``n`` unknowns by ``m`` knowns */
    int (*derivative)(void *instance, const unsigned int unknowns[], size_t n, const unsigned int knowns[], size_t m,
                      const double seed[], double sensitivity[]);
} Host;

/* FMI 2.0 */
static struct {
    fmi2InstantiateTYPE *Instantiate;
    fmi2FreeInstanceTYPE *FreeInstance;
    fmi2SetupExperimentTYPE *SetupExperiment;
    fmi2EnterInitializationModeTYPE *EnterInitializationMode;
    fmi2ExitInitializationModeTYPE *ExitInitializationMode;
    fmi2SetRealTYPE *SetReal;
    fmi2SetIntegerTYPE *SetInteger;
    fmi2SetBooleanTYPE *SetBoolean;
    fmi2SetStringTYPE *SetString;
    fmi2GetStringTYPE *GetString;
    fmi2GetRealTYPE *GetReal;
    fmi2GetDirectionalDerivativeTYPE *GetDirectionalDerivative;
    fmi2DoStepTYPE *DoStep;
    fmi2GetBooleanStatusTYPE *GetBooleanStatus;
    fmi2TerminateTYPE *Terminate;
    fmi2GetFMUstateTYPE *GetFMUstate;
    fmi2SetFMUstateTYPE *SetFMUstate;
    fmi2FreeFMUstateTYPE *FreeFMUstate;
    fmi2SerializedFMUstateSizeTYPE *SerializedFMUstateSize;
    fmi2SerializeFMUstateTYPE *SerializeFMUstate;
    fmi2DeSerializeFMUstateTYPE *DeSerializeFMUstate;
} f2;

static void logger2(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status, fmi2String category,
                    fmi2String message, ...)
{
    char text[1024];
    va_list arguments;
    (void)environment;
    va_start(arguments, message);
    vsnprintf(text, sizeof text, message, arguments);
    va_end(arguments);
    messages_logged++;
    fprintf(stderr, "[%s %d %s] %s\n", name, (int)status, category, text);
}

static const fmi2CallbackFunctions callbacks2 = {logger2, calloc, free, NULL, NULL};

static void *instantiate2(const char *name, const char *token)
{
    char uri[4096 + 16] = "file://";
    size_t at = strlen(uri), i;
    if (resources != NULL && resources[0] != '/') { /* a Windows path, C:/...: file:///C:/... */
        uri[at++] = '/';
    }
    for (i = 0; resources != NULL && resources[i] != '\0' && at + 4 < sizeof uri; i++) {
        if (resources[i] == '%' || resources[i] == ' ') { /* the characters a URI must escape here */
            at += (size_t)sprintf(uri + at, "%%%02X", (unsigned)(unsigned char)resources[i]);
        } else {
            uri[at++] = resources[i];
        }
    }
    uri[at] = '\0';
    return f2.Instantiate(name, fmi2CoSimulation, token, resources != NULL ? uri : "", &callbacks2, fmi2False,
                          fmi2True);
}

static int initialize2(void *instance)
{
    return f2.SetupExperiment(instance, fmi2False, 0.0, 0.0, fmi2False, 0.0) == fmi2OK &&
           f2.EnterInitializationMode(instance) == fmi2OK;
}

static int set2(void *instance, const unsigned int vr[], size_t n, const double values[])
{
    return f2.SetReal(instance, vr, n, values) == fmi2OK;
}

static int set_integer2(void *instance, const unsigned int vr[], size_t n, const int values[])
{
    return f2.SetInteger(instance, vr, n, values) == fmi2OK;
}

static int set_boolean2(void *instance, const unsigned int vr[], size_t n, const int values[])
{
    return f2.SetBoolean(instance, vr, n, values) == fmi2OK;
}

static int set_string2(void *instance, const unsigned int vr[], size_t n, char *const values[])
{
    fmi2String read[MAX_SIGNALS];
    size_t i;
    if (f2.SetString(instance, vr, n, (const fmi2String *)values) != fmi2OK ||
        f2.GetString(instance, vr, n, read) != fmi2OK) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        if (read[i] == NULL || read[i] == values[i] || strcmp(read[i], values[i]) != 0) { /* a copy, equal */
            return 0;
        }
    }
    return 1;
}

static int get2(void *instance, const unsigned int vr[], size_t n, double values[])
{
    return f2.GetReal(instance, vr, n, values) == fmi2OK;
}

static int step2(void *instance, double time, double step_size)
{
    return (int)f2.DoStep(instance, time, step_size, fmi2True);
}

static int store2(void *instance, void **copy)
{
    fmi2FMUstate state = NULL;
    size_t size = 0;
    fmi2Byte *bytes;
    int ok = f2.GetFMUstate(instance, &state) == fmi2OK && f2.SerializedFMUstateSize(instance, state, &size) == fmi2OK;
    bytes = ok ? malloc(size) : NULL;
    ok = bytes != NULL && f2.SerializeFMUstate(instance, state, bytes, size) == fmi2OK &&
         f2.DeSerializeFMUstate(instance, bytes, size, copy) == fmi2OK;
    free(bytes);
    f2.FreeFMUstate(instance, &state);
    return ok;
}

static int restore2(void *instance, void *state)
{
    return f2.SetFMUstate(instance, state) == fmi2OK;
}

static void release2(void *instance, void **state)
{
    f2.FreeFMUstate(instance, state);
}

static void finish2(void *instance)
{
    f2.Terminate(instance);
    f2.FreeInstance(instance);
}

static int exit_initialization2(void *instance)
{
    return f2.ExitInitializationMode(instance) == fmi2OK;
}

static int stops2(void *instance)
{
    fmi2Boolean terminated = fmi2False;
    return f2.GetBooleanStatus(instance, fmi2Terminated, &terminated) == fmi2OK && terminated;
}

static int derivative2(void *instance, const unsigned int unknowns[], size_t n, const unsigned int knowns[], size_t m,
                       const double seed[], double sensitivity[])
{
    return (int)f2.GetDirectionalDerivative(instance, unknowns, n, knowns, m, seed, sensitivity);
}

static int load2(Host *host)
{
    static const Host fmi2 = {instantiate2, initialize2, set2, set_integer2, set_boolean2, set_string2, get2, step2,
                              store2, restore2, release2, finish2, stops2, derivative2};
    *host = fmi2;
    return load("fmi2Instantiate", &f2.Instantiate) && load("fmi2FreeInstance", &f2.FreeInstance) &&
           load("fmi2SetupExperiment", &f2.SetupExperiment) &&
           load("fmi2EnterInitializationMode", &f2.EnterInitializationMode) &&
           load("fmi2ExitInitializationMode", &f2.ExitInitializationMode) && load("fmi2SetReal", &f2.SetReal) &&
           load("fmi2SetInteger", &f2.SetInteger) && load("fmi2SetBoolean", &f2.SetBoolean) &&
           load("fmi2SetString", &f2.SetString) && load("fmi2GetString", &f2.GetString) &&
           load("fmi2GetReal", &f2.GetReal) && load("fmi2GetDirectionalDerivative", &f2.GetDirectionalDerivative) &&
           load("fmi2DoStep", &f2.DoStep) && load("fmi2Terminate", &f2.Terminate) &&
           load("fmi2GetBooleanStatus", &f2.GetBooleanStatus) &&
           load("fmi2GetFMUstate", &f2.GetFMUstate) && load("fmi2SetFMUstate", &f2.SetFMUstate) &&
           load("fmi2FreeFMUstate", &f2.FreeFMUstate) &&
           load("fmi2SerializedFMUstateSize", &f2.SerializedFMUstateSize) &&
           load("fmi2SerializeFMUstate", &f2.SerializeFMUstate) &&
           load("fmi2DeSerializeFMUstate", &f2.DeSerializeFMUstate);
}

/* FMI 3.0 */
static struct {
    fmi3InstantiateCoSimulationTYPE *InstantiateCoSimulation;
    fmi3FreeInstanceTYPE *FreeInstance;
    fmi3EnterInitializationModeTYPE *EnterInitializationMode;
    fmi3ExitInitializationModeTYPE *ExitInitializationMode;
    fmi3SetFloat64TYPE *SetFloat64;
    fmi3SetInt32TYPE *SetInt32;
    fmi3SetBooleanTYPE *SetBoolean;
    fmi3SetStringTYPE *SetString;
    fmi3GetStringTYPE *GetString;
    fmi3GetFloat64TYPE *GetFloat64;
    fmi3GetDirectionalDerivativeTYPE *GetDirectionalDerivative;
    fmi3DoStepTYPE *DoStep;
    fmi3TerminateTYPE *Terminate;
    fmi3GetFMUStateTYPE *GetFMUState;
    fmi3SetFMUStateTYPE *SetFMUState;
    fmi3FreeFMUStateTYPE *FreeFMUState;
    fmi3SerializedFMUStateSizeTYPE *SerializedFMUStateSize;
    fmi3SerializeFMUStateTYPE *SerializeFMUState;
    fmi3DeserializeFMUStateTYPE *DeserializeFMUState;
} f3;

static void logger3(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)environment;
    messages_logged++;
    fprintf(stderr, "[%d %s] %s\n", (int)status, category, message);
}

static void *instantiate3(const char *name, const char *token)
{
    return f3.InstantiateCoSimulation(name, token, resources, fmi3False, fmi3True, fmi3False, fmi3False, NULL, 0, NULL,
                                      logger3, NULL);
}

static int initialize3(void *instance)
{
    return f3.EnterInitializationMode(instance, fmi3False, 0.0, 0.0, fmi3False, 0.0) == fmi3OK;
}

static int set3(void *instance, const unsigned int vr[], size_t n, const double values[])
{
    return f3.SetFloat64(instance, vr, n, values, n) == fmi3OK;
}

static int set_integer3(void *instance, const unsigned int vr[], size_t n, const int values[])
{
    return f3.SetInt32(instance, vr, n, values, n) == fmi3OK;
}

static int set_boolean3(void *instance, const unsigned int vr[], size_t n, const int values[])
{
    fmi3Boolean truth[MAX_SIGNALS];
    size_t i;
    for (i = 0; i < n; i++) {
        truth[i] = values[i] != 0;
    }
    return f3.SetBoolean(instance, vr, n, truth, n) == fmi3OK;
}

static int set_string3(void *instance, const unsigned int vr[], size_t n, char *const values[])
{
    fmi3String read[MAX_SIGNALS];
    size_t i;
    if (f3.SetString(instance, vr, n, (const fmi3String *)values, n) != fmi3OK ||
        f3.GetString(instance, vr, n, read, n) != fmi3OK) {
        return 0;
    }
    for (i = 0; i < n; i++) {
        if (read[i] == NULL || read[i] == values[i] || strcmp(read[i], values[i]) != 0) { /* a copy, equal */
            return 0;
        }
    }
    return 1;
}

static int get3(void *instance, const unsigned int vr[], size_t n, double values[])
{
    return f3.GetFloat64(instance, vr, n, values, n) == fmi3OK;
}

static int stop_requested = 0; /* terminateSimulation of the last fmi3DoStep */

static int step3(void *instance, double time, double step_size)
{
    fmi3Boolean event, terminate, early;
    fmi3Float64 last;
    int status = (int)f3.DoStep(instance, time, step_size, fmi3True, &event, &terminate, &early, &last);
    stop_requested = terminate;
    if ((terminate && status != fmi3Discard) || (status == fmi3Discard && last != time)) {
        return -1;
    }
    return status;
}

static int stops3(void *instance)
{
    (void)instance;
    return stop_requested;
}

static int store3(void *instance, void **copy)
{
    fmi3FMUState state = NULL;
    size_t size = 0;
    fmi3Byte *bytes;
    int ok = f3.GetFMUState(instance, &state) == fmi3OK && f3.SerializedFMUStateSize(instance, state, &size) == fmi3OK;
    bytes = ok ? malloc(size) : NULL;
    ok = bytes != NULL && f3.SerializeFMUState(instance, state, bytes, size) == fmi3OK &&
         f3.DeserializeFMUState(instance, bytes, size, copy) == fmi3OK;
    free(bytes);
    f3.FreeFMUState(instance, &state);
    return ok;
}

static int restore3(void *instance, void *state)
{
    return f3.SetFMUState(instance, state) == fmi3OK;
}

static void release3(void *instance, void **state)
{
    f3.FreeFMUState(instance, state);
}

static void finish3(void *instance)
{
    f3.Terminate(instance);
    f3.FreeInstance(instance);
}

static int exit_initialization3(void *instance)
{
    return f3.ExitInitializationMode(instance) == fmi3OK;
}

static int derivative3(void *instance, const unsigned int unknowns[], size_t n, const unsigned int knowns[], size_t m,
                       const double seed[], double sensitivity[])
{
    return (int)f3.GetDirectionalDerivative(instance, unknowns, n, knowns, m, seed, m, sensitivity, n);
}

static int load3(Host *host)
{
    static const Host fmi3 = {instantiate3, initialize3, set3, set_integer3, set_boolean3, set_string3, get3, step3,
                              store3, restore3, release3, finish3, stops3, derivative3};
    *host = fmi3;
    return load("fmi3InstantiateCoSimulation", &f3.InstantiateCoSimulation) &&
           load("fmi3FreeInstance", &f3.FreeInstance) &&
           load("fmi3EnterInitializationMode", &f3.EnterInitializationMode) &&
           load("fmi3ExitInitializationMode", &f3.ExitInitializationMode) && load("fmi3SetFloat64", &f3.SetFloat64) &&
           load("fmi3SetInt32", &f3.SetInt32) && load("fmi3SetBoolean", &f3.SetBoolean) &&
           load("fmi3SetString", &f3.SetString) && load("fmi3GetString", &f3.GetString) &&
           load("fmi3GetFloat64", &f3.GetFloat64) && load("fmi3DoStep", &f3.DoStep) &&
           load("fmi3GetDirectionalDerivative", &f3.GetDirectionalDerivative) &&
           load("fmi3Terminate", &f3.Terminate) && load("fmi3GetFMUState", &f3.GetFMUState) &&
           load("fmi3SetFMUState", &f3.SetFMUState) && load("fmi3FreeFMUState", &f3.FreeFMUState) &&
           load("fmi3SerializedFMUStateSize", &f3.SerializedFMUStateSize) &&
           load("fmi3SerializeFMUState", &f3.SerializeFMUState) &&
           load("fmi3DeserializeFMUState", &f3.DeserializeFMUState);
}

/* ---- scenario ------------------------------------------------------------------------------------ */

static int read_scenario(const char *path, Scenario *s)
{
    FILE *file = fopen(path, "r");
    int ok, k, i, limits = 0;
    if (file == NULL) {
        return 0;
    }
    ok = fscanf(file, " inputs %d", &s->inputs) == 1 && s->inputs >= 0 && s->inputs <= MAX_SIGNALS;
    for (i = 0; ok && i < s->inputs; i++) {
        ok = fscanf(file, "%u", &s->input_vr[i]) == 1;
    }
    ok = ok && fscanf(file, " outputs %d", &s->outputs) == 1 && s->outputs > 0 && s->outputs <= MAX_SIGNALS;
    for (i = 0; ok && i < s->outputs; i++) {
        ok = fscanf(file, "%u", &s->output_vr[i]) == 1;
    }
    ok = ok && fscanf(file, " parameters %d", &s->parameters) == 1 && s->parameters >= 0 && s->parameters <= MAX_SIGNALS;
    for (i = 0; ok && i < s->parameters; i++) {
        ok = fscanf(file, "%u %lf", &s->parameter_vr[i], &s->parameter[i]) == 2;
    }
    ok = ok && fscanf(file, " integers %d", &s->integers) == 1 && s->integers >= 0 && s->integers <= MAX_SIGNALS;
    for (i = 0; ok && i < s->integers; i++) {
        ok = fscanf(file, "%u %d", &s->integer_vr[i], &s->integer[i]) == 2;
    }
    ok = ok && fscanf(file, " booleans %d", &s->booleans) == 1 && s->booleans >= 0 && s->booleans <= MAX_SIGNALS;
    for (i = 0; ok && i < s->booleans; i++) {
        ok = fscanf(file, "%u %d", &s->boolean_vr[i], &s->boolean[i]) == 2;
    }
    ok = ok && fscanf(file, " strings %d", &s->strings) == 1 && s->strings >= 0 && s->strings <= MAX_SIGNALS;
    for (i = 0; ok && i < s->strings; i++) {
        s->string[i] = malloc(MAX_TEXT);
        ok = s->string[i] != NULL && fscanf(file, "%u %4095s", &s->string_vr[i], s->string[i]) == 2;
    }
    ok = ok && fscanf(file, " tolerance %lf", &s->tolerance) == 1;
    ok = ok && fscanf(file, " limits %d", &limits) == 1 && limits == s->outputs;
    for (i = 0; ok && i < s->outputs; i++) {
        ok = fscanf(file, "%lf %lf", &s->floor[i], &s->weight[i]) == 2 && s->floor[i] >= 0.0 && s->weight[i] > 0.0;
    }
    ok = ok && fscanf(file, " steps %d %lf", &s->steps, &s->step_size) == 2 && s->steps > 1 && s->steps < 1000000;
    if (ok) {
        s->time = malloc(sizeof(double) * (size_t)(s->steps + 1));
        s->input = malloc(sizeof(double) * (size_t)(s->steps + 1) * (size_t)(s->inputs + 1));
        s->expected = malloc(sizeof(double) * (size_t)(s->steps + 1) * (size_t)s->outputs);
        ok = s->time != NULL && s->input != NULL && s->expected != NULL;
    }
    for (k = 0; ok && k <= s->steps; k++) {
        ok = fscanf(file, "%lf", &s->time[k]) == 1;
        for (i = 0; ok && i < s->inputs; i++) {
            ok = fscanf(file, "%lf", &s->input[k * s->inputs + i]) == 1;
        }
        for (i = 0; ok && i < s->outputs; i++) {
            ok = fscanf(file, "%lf", &s->expected[k * s->outputs + i]) == 1;
        }
    }
    fclose(file);
    return ok;
}

/* fmusim's loop on a discarded step (its FMI 2.0 co-simulation; fmpy's simulate_fmu alike): unless
 * the FMU asks to stop, the step is tried again at the same time. The attempts until the FMU took
 * the step or asked to stop (at most ``limit``: a master without a limit would never end). */
static int retry_until_stopped(const Host *host, void *instance, double time, double step_size, int limit)
{
    int attempts = 0, status;
    do {
        status = host->step(instance, time, step_size);
        attempts++;
    } while (status == 2 && !host->stops(instance) && attempts < limit);
    return status == 2 ? attempts : -1;
}

/* Steps rows first..last-1 on both instances; the second must agree bit for bit. Records the
 * outputs of instance a into ``outputs`` (row k + 1 after step k). */
static int run(const Host *host, const Scenario *s, void *a, void *b, int first, int last, double *outputs)
{
    double values[MAX_SIGNALS], twin[MAX_SIGNALS];
    int k;
    for (k = first; k < last; k++) {
        const double *u = &s->input[k * s->inputs];
        if (!host->set(a, s->input_vr, (size_t)s->inputs, u) || !host->set(b, s->input_vr, (size_t)s->inputs, u) ||
            host->step(a, s->time[k], s->step_size) != 0 || host->step(b, s->time[k], s->step_size) != 0 ||
            !host->get(a, s->output_vr, (size_t)s->outputs, values) ||
            !host->get(b, s->output_vr, (size_t)s->outputs, twin)) {
            return fail("a set, step or get failed");
        }
        if (memcmp(values, twin, sizeof(double) * (size_t)s->outputs) != 0) {
            return fail("two instances with the same inputs differ");
        }
        memcpy(&outputs[(k + 1) * s->outputs], values, sizeof(double) * (size_t)s->outputs);
    }
    return 0;
}

/* The outputs of every row, "%.17g" (round-trips every double). */
static int write_outputs(const char *path, const Scenario *s, const double *outputs)
{
    FILE *file = fopen(path, "w");
    int k, i, ok = file != NULL;
    for (k = 0; ok && k <= s->steps; k++) {
        for (i = 0; ok && i < s->outputs; i++) {
            ok = fprintf(file, i + 1 < s->outputs ? "%.17g " : "%.17g\n", outputs[k * s->outputs + i]) > 0;
        }
    }
    return file != NULL && fclose(file) == 0 && ok;
}

int main(int argc, char **argv)
{
    Scenario s;
    Host host;
    void *a, *b, *state = NULL;
    double *outputs, *replay, deviation = 0.0, before[MAX_SIGNALS], after[MAX_SIGNALS], bad = NAN;
    double seed[MAX_SIGNALS], sensitivity[MAX_SIGNALS];
    int half, i, k, failed = 0, logged, status;
    memset(&s, 0, sizeof s);
    if (argc < 5 || argc > 7 || (strcmp(argv[2], "2") != 0 && strcmp(argv[2], "3") != 0)) {
        return fail("usage: native_host LIBRARY 2|3 TOKEN SCENARIO [RESOURCES [OUTPUTS]]");
    }
    resources = argc >= 6 && strcmp(argv[5], "-") != 0 ? argv[5] : NULL;
    if (!read_scenario(argv[4], &s)) {
        for (i = 0; i < MAX_SIGNALS; i++) {
            free(s.string[i]);
        }
        return fail("unreadable scenario");
    }
    if (!open_library(argv[1])) {
        return fail(library_error());
    }
    if (!(argv[2][0] == '2' ? load2(&host) : load3(&host))) {
        return fail("incomplete FMI library");
    }
    outputs = calloc((size_t)(s.steps + 1) * (size_t)s.outputs, sizeof(double));
    replay = calloc((size_t)(s.steps + 1) * (size_t)s.outputs, sizeof(double));
    a = host.instantiate("a", argv[3]);
    b = host.instantiate("b", argv[3]);
    if (outputs == NULL || replay == NULL || a == NULL || b == NULL || !host.initialize(a) || !host.initialize(b) ||
        !host.set(a, s.input_vr, (size_t)s.inputs, s.input) || !host.set(b, s.input_vr, (size_t)s.inputs, s.input) ||
        !host.set(a, s.parameter_vr, (size_t)s.parameters, s.parameter) ||
        !host.set(b, s.parameter_vr, (size_t)s.parameters, s.parameter) ||
        !host.set_integer(a, s.integer_vr, (size_t)s.integers, s.integer) ||
        !host.set_integer(b, s.integer_vr, (size_t)s.integers, s.integer) ||
        !host.set_boolean(a, s.boolean_vr, (size_t)s.booleans, s.boolean) ||
        !host.set_boolean(b, s.boolean_vr, (size_t)s.booleans, s.boolean) ||
        !host.set_string(a, s.string_vr, (size_t)s.strings, s.string) ||
        !host.set_string(b, s.string_vr, (size_t)s.strings, s.string) ||
        !(argv[2][0] == '2' ? exit_initialization2(a) && exit_initialization2(b)
                            : exit_initialization3(a) && exit_initialization3(b)) ||
        !host.get(a, s.output_vr, (size_t)s.outputs, outputs)) {
        return fail("instantiation or initialisation failed");
    }
    half = s.steps / 2;
    failed = run(&host, &s, a, b, 0, half, outputs) || !host.store(a, &state) ||
             run(&host, &s, a, b, half, s.steps, outputs);
    /* the state stored half way, restored, replays the second half bit for bit */
    failed = failed || !host.restore(a, state) || !host.restore(b, state) ||
             run(&host, &s, a, b, half, s.steps, replay);
    for (k = half + 1; !failed && k <= s.steps; k++) {
        failed = memcmp(&outputs[k * s.outputs], &replay[k * s.outputs], sizeof(double) * (size_t)s.outputs) != 0;
    }
    for (i = 0; !failed && i < s.outputs; i++) { /* deviation relative to each output's largest magnitude */
        double largest = s.floor[i], worst = 0.0;
        for (k = 0; k <= s.steps; k++) {
            largest = fmax(largest, fabs(s.expected[k * s.outputs + i]));
            worst = fmax(worst, fabs(outputs[k * s.outputs + i] - s.expected[k * s.outputs + i]));
        }
        deviation = fmax(deviation, (largest > 0.0 ? worst / largest : worst) / s.weight[i]);
    }
    /* the directional derivatives on b: finite, or refused (Error) with one reason logged */
    for (i = 0; i < s.inputs; i++) {
        seed[i] = 1.0;
    }
    logged = messages_logged;
    status = failed ? 0 : host.derivative(b, s.output_vr, (size_t)s.outputs, s.input_vr, (size_t)s.inputs, seed,
                                          sensitivity);
    for (i = 0; !failed && status == 0 && i < s.outputs; i++) {
        failed = !isfinite(sensitivity[i]);
    }
    failed = failed || !(status == 0 || (status == 3 && messages_logged == logged + 1));
    /* a refused step (a NaN input, or a zero step size where there is no input): Discard, a reason
     * logged, nothing changed */
    logged = messages_logged;
    if (!failed) {
        failed = !host.get(a, s.output_vr, (size_t)s.outputs, before) || !host.set(a, s.input_vr, s.inputs > 0, &bad) ||
                 retry_until_stopped(&host, a, s.time[s.steps], s.inputs > 0 ? s.step_size : 0.0, 1000) != 1 ||
                 messages_logged != logged + 1 ||
                 !host.get(a, s.output_vr, (size_t)s.outputs, after) ||
                 memcmp(before, after, sizeof(double) * (size_t)s.outputs) != 0;
    }
    if (!failed && argc == 7) {
        failed = !write_outputs(argv[6], &s, outputs);
    }
    host.release(a, &state);
    host.finish(a);
    host.finish(b);
    close_library();
    free(outputs);
    free(replay);
    free(s.time);
    free(s.input);
    free(s.expected);
    for (i = 0; i < MAX_SIGNALS; i++) {
        free(s.string[i]);
    }
    printf("steps %d, outputs %d, largest relative deviation %.3g, checks %s\n", s.steps, s.outputs, deviation,
           failed ? "failed" : "passed");
    return failed || !(deviation <= s.tolerance);
}
