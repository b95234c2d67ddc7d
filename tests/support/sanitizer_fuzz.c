/* A host linked with one native FMU's sources built under AddressSanitizer and UndefinedBehaviorSanitizer
 * (tests/native/test_native_sanitizers.py): call sequences over every FMI function of the Model Exchange
 * and co-simulation interfaces, in every state, with hostile values, derivatives and saved states
 * (corrupted, their checksum remade).
 *
 * Usage: sanitizer_fuzz MODE SEED CASES RESOURCES
 *   MODE "sequences": each case a fresh instance of a random interface and CALLS random calls of any
 *        function with random, often hostile, arguments;
 *   MODE "states": every function in every state of both interfaces' state machines (Instantiated,
 *        Initialization Mode, Event Mode, Continuous-Time Mode, Step Mode, Terminated, Error), each on a
 *        fresh instance driven there, with the start values' arguments (SEED and CASES unused);
 *   MODE "targets": a fuzz target for each entry point the layer added or hardened (TARGETS: the Model
 *        Exchange functions, the directional and adjoint derivatives, DoStep, the saved states): CASES cases
 *        each, a fresh instance driven into a random state of its interface's state machine, then TARGET_CALLS
 *        calls, every other one the target's, with hostile arguments; a target the standard forbids in the
 *        state its calls' statuses left the instance in must be refused with Error. A line "target NAME
 *        cases N" for each;
 *   MODE "instantiate": CASES instantiations and frees.
 * It exits 1 naming the first broken promise: a status outside OK, Warning, Discard and Error; an output,
 * state derivative, state or sensitivity got with OK or Warning that is not finite; a function the standard
 * forbids in a state that is not refused with Error. A sanitizer's report ends it too (built with
 * -fno-sanitize-recover). Its last line: "calls N cases M".
 *
 * Compiled with -DFMI_VERSION=2 or 3 and the FMU's sources; it reads the generated variable table
 * (model_variables.h) through fmi/fmu_instance.h. */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi/fmu_instance.h"

#if FMI_VERSION == 2
#include "fmi2Functions.h"
typedef fmi2Component Handle;
typedef fmi2Boolean Truth;
typedef fmi2Status Result;
typedef fmi2FMUstate Saved;
#define F(name) fmi2##name
#define GET_STATE fmi2GetFMUstate
#define SET_STATE fmi2SetFMUstate
#define FREE_STATE fmi2FreeFMUstate
#define STATE_SIZE fmi2SerializedFMUstateSize
#define SERIALIZE fmi2SerializeFMUstate
#define DESERIALIZE fmi2DeSerializeFMUstate
#else
#include "fmi3Functions.h"
typedef fmi3Instance Handle;
typedef fmi3Boolean Truth;
typedef fmi3Status Result;
typedef fmi3FMUState Saved;
#define F(name) fmi3##name
#define GET_STATE fmi3GetFMUState
#define SET_STATE fmi3SetFMUState
#define FREE_STATE fmi3FreeFMUState
#define STATE_SIZE fmi3SerializedFMUStateSize
#define SERIALIZE fmi3SerializeFMUState
#define DESERIALIZE fmi3DeserializeFMUState
#endif

#define CALLS 40
#define MAX_REFS 4
#define SLOTS (MODEL_STATE_COUNT > 0 ? MODEL_STATE_COUNT : 1)
#define ROWS (MODEL_VARIABLE_COUNT + MODEL_STATE_COUNT + 2)
#define KEPT 3
#if MODEL_STATE_COUNT > 0
#define STATE_VARIABLE(k) model_states[(k) % MODEL_STATE_COUNT]
#else
#define STATE_VARIABLE(k) ((int)(k) - 1) /* no state: never asked */
#endif

typedef enum { S_INSTANTIATED, S_INITIALIZATION, S_EVENT, S_CONTINUOUS, S_STEP, S_TERMINATED, S_ERROR, S_COUNT } Where;
static const char *const WHERE[S_COUNT] = {"Instantiated", "InitializationMode", "EventMode", "ContinuousTimeMode",
                                           "StepMode", "Terminated", "Error"};

typedef enum {
    A_ENTER_INIT, A_EXIT_INIT, A_TERMINATE, A_RESET, A_DO_STEP, A_SET_TIME, A_SET_STATES, A_GET_STATES,
    A_GET_DERIVATIVES, A_GET_NOMINALS, A_GET_INDICATORS, A_ENTER_EVENT, A_ENTER_CONTINUOUS, A_DISCRETE,
    A_COMPLETED, A_DIRECTIONAL, A_ADJOINT, A_GET_REAL, A_SET_REAL, A_GET_INTEGER, A_SET_INTEGER, A_GET_BOOLEAN,
    A_SET_BOOLEAN, A_GET_STRING, A_SET_STRING, A_GET_STATE, A_SET_STATE, A_FREE_STATE, A_SAVED_BYTES,
    A_DEBUG_LOGGING, A_COUNT
} Action;
static const char *const ACTION[A_COUNT] = {
    "EnterInitializationMode", "ExitInitializationMode", "Terminate", "Reset", "DoStep", "SetTime",
    "SetContinuousStates", "GetContinuousStates", "GetDerivatives", "GetNominalsOfContinuousStates",
    "GetEventIndicators", "EnterEventMode", "EnterContinuousTimeMode", "NewDiscreteStates",
    "CompletedIntegratorStep", "GetDirectionalDerivative", "GetAdjointDerivative", "GetReal", "SetReal",
    "GetInteger", "SetInteger", "GetBoolean", "SetBoolean", "GetString", "SetString", "GetFMUState",
    "SetFMUState", "FreeFMUState", "SerializeFMUState", "SetDebugLogging"};

typedef struct {
    Handle c;
    int model_exchange;
    double time;
    Saved kept[KEPT];
    int hostile; /* random arguments, often hostile; 0: the start values' */
} Host;

static uint64_t rng_state = 88172645463325252ull;
static unsigned long calls_made, cases_made;

static uint64_t next(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return rng_state;
}

static int below(int n)
{
    return n > 0 ? (int)(next() % (uint64_t)n) : 0;
}

static void broken(const char *function, const char *what)
{
    printf("broken promise in case %lu after %lu calls: %s %s\n", cases_made, calls_made, function, what);
    exit(1);
}

static int checked(int status, Action action)
{
    calls_made++;
    if (status < 0 || status > 3) {
        broken(ACTION[action], "returned a status outside OK, Warning, Discard and Error");
    }
    return status;
}

/* values got with OK or Warning that must be finite */
static void finite_with(int status, Action action, const double values[], size_t n)
{
    size_t i;
    for (i = 0; status <= 1 && i < n; i++) {
        if (!isfinite(values[i])) {
            broken(ACTION[action], "gave a value that is not finite with OK");
        }
    }
}

static void logger_message(const char *message)
{
    (void)message; /* the messages are the FMUs' tests' business; the fuzzer reads statuses and values */
}

#if FMI_VERSION == 2
static void logger(fmi2ComponentEnvironment environment, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    (void)environment, (void)name, (void)status, (void)category;
    logger_message(message);
}
static const fmi2CallbackFunctions callbacks = {logger, calloc, free, NULL, NULL};
#else
static void logger(fmi3InstanceEnvironment environment, fmi3Status status, fmi3String category, fmi3String message)
{
    (void)environment, (void)status, (void)category;
    logger_message(message);
}
#endif

/* ---- arguments ------------------------------------------------------------------------------ */

static double a_real(const Host *host, int variable)
{
    static const double pool[] = {0.0, -0.0, 1.0, -1.0, 1e-300, 1e300, -1e300, DBL_MAX, 5e-324, 1e8, -3.5, 0.25};
    double start = variable >= 0 && variable < MODEL_VARIABLE_COUNT ? model_variables[variable].start : 0.0;
    int pick = below(16);
    if (!host->hostile || pick < 4) {
        return start;
    }
    if (pick < 7) {
        return start * (1.0 + (below(2001) - 1000) * 1e-4) + (below(3) - 1) * 1e-3;
    }
    if (pick == 7) {
        return NAN;
    }
    if (pick == 8) {
        return below(2) ? INFINITY : -INFINITY;
    }
    return pool[below((int)(sizeof pool / sizeof pool[0]))];
}

static int32_t an_integer(const Host *host, int variable)
{
    static const int32_t pool[] = {0, 1, -1, 2, 7, 2147483647, -2147483647 - 1};
    if ((!host->hostile || below(2)) && variable >= 0 && variable < MODEL_VARIABLE_COUNT) {
        return (int32_t)model_variables[variable].start;
    }
    return pool[below((int)(sizeof pool / sizeof pool[0]))];
}

static const char *a_string(const Host *host, int variable)
{
    static char long_text[5000];
    static const char *const pool[] = {"", "1,2", "x", "\xff\xfe", "../../etc/passwd", "0", "1,2,3,6", "1,x"};
    const char *start = variable >= 0 && variable < MODEL_VARIABLE_COUNT ? model_variables[variable].start_string : NULL;
    if (long_text[0] == '\0') {
        memset(long_text, '1', sizeof long_text - 1);
    }
    if ((!host->hostile || below(3) == 0) && start != NULL) {
        return start;
    }
    return below(12) == 0 ? long_text : pool[below((int)(sizeof pool / sizeof pool[0]))];
}

/* A value reference of ``type`` (-1: any); hostile, sometimes another or none of the model's. */
static int a_reference(const Host *host, int type)
{
    int i, v;
    if (host->hostile && below(8) == 0) {
        return below(4) == 0 ? 0x7FFFFFFF : MODEL_VARIABLE_COUNT + below(MODEL_STATE_COUNT + 3);
    }
    for (i = 0; i < 64; i++) {
        v = below(MODEL_VARIABLE_COUNT);
        if (type < 0 || (int)model_variables[v].type == type) {
            return v;
        }
    }
    return below(MODEL_VARIABLE_COUNT);
}

/* ``n`` value references of ``type`` (-1: any) into ``refs``; the start values' calls name one. */
static size_t references(const Host *host, unsigned int refs[], int type)
{
    size_t n = host->hostile ? (size_t)below(MAX_REFS + 1) : 1, i;
    for (i = 0; i < n; i++) {
        refs[i] = (unsigned int)a_reference(host, type);
    }
    return n;
}

/* A count of states: the model's, or (hostile) one off. */
static size_t a_count(const Host *host)
{
    if (host->hostile && below(10) == 0) {
        return MODEL_STATE_COUNT > 0 && below(2) ? MODEL_STATE_COUNT - 1 : MODEL_STATE_COUNT + 1;
    }
    return MODEL_STATE_COUNT;
}

/* the Jacobian's unknowns (Real outputs, der(<state>)) and knowns (Real inputs, states) */
static size_t jacobian_references(const Host *host, unsigned int refs[], int unknowns)
{
    unsigned int all[ROWS];
    size_t count = 0, n, i;
    int v, k;
    for (v = 0; v < MODEL_VARIABLE_COUNT; v++) {
        if ((unknowns ? model_jacobian_rows[v] : model_jacobian_columns[v]) >= 0 &&
            !(unknowns && model_jacobian_columns[v] >= 0)) {
            all[count++] = (unsigned int)v;
        }
    }
    for (k = 0; unknowns && k < MODEL_STATE_COUNT; k++) {
        all[count++] = (unsigned int)(MODEL_VARIABLE_COUNT + (FMI_VERSION == 3) + k);
    }
    if (!host->hostile) {
        memcpy(refs, all, count * sizeof *refs);
        return count;
    }
    n = (size_t)below(MAX_REFS + 1);
    for (i = 0; i < n; i++) {
        refs[i] = count > 0 && below(8) ? all[below((int)count)] : (unsigned int)a_reference(host, -1);
    }
    return n;
}

/* ---- the saved states' bytes ---------------------------------------------------------------- */

static uint64_t fnv1a(const unsigned char *bytes, size_t size)
{
    uint64_t hash = 14695981039346656037ull;
    size_t i;
    for (i = 0; i < size; i++) {
        hash = (hash ^ bytes[i]) * 1099511628211ull;
    }
    return hash;
}

/* Serializes a kept state, then (hostile) changes it: a byte flipped, a double slot made NaN, infinite or
 * huge, or the bytes cut short, most with the checksum remade; deserializes it and may set it. */
static void saved_bytes(Host *host, Saved state)
{
    static const double odd[] = {NAN, INFINITY, -INFINITY, 1e308, -1e308, 5e-324};
    Saved decoded = NULL;
    unsigned char *bytes;
    size_t size = 0, at, cut;
    uint64_t sum;
    int status = checked(STATE_SIZE(host->c, state, &size), A_SAVED_BYTES);
    if (status > 1 || size < 16 || size > (1u << 24)) {
        return;
    }
    bytes = malloc(size);
    if (bytes == NULL) {
        return;
    }
    if (checked(SERIALIZE(host->c, state, (void *)bytes, size), A_SAVED_BYTES) <= 1) {
        cut = size;
        if (host->hostile) {
            at = (size_t)below((int)size);
            switch (below(4)) {
            case 0:
                bytes[at] ^= (unsigned char)(1u << below(8));
                break;
            case 1:
                at = size > 16 + 8 ? (size_t)below((int)(size - 16)) : 0;
                memcpy(bytes + at, &odd[below((int)(sizeof odd / sizeof odd[0]))], sizeof(double));
                break;
            case 2:
                cut = (size_t)below((int)size);
                break;
            default:
                break;
            }
            if (below(4) != 0 && cut >= 8) { /* the checksum remade: only the values' checks are left */
                sum = fnv1a(bytes, cut - 8);
                memcpy(bytes + cut - 8, &sum, sizeof sum);
            }
        }
        if (checked(DESERIALIZE(host->c, (void *)bytes, cut, &decoded), A_SAVED_BYTES) <= 1 &&
            decoded != NULL) {
            if (below(2)) {
                checked(SET_STATE(host->c, decoded), A_SAVED_BYTES);
            }
            checked(FREE_STATE(host->c, &decoded), A_SAVED_BYTES);
        }
    }
    free(bytes);
}

/* ---- the calls ---------------------------------------------------------------------------------- */

static int is_output_value(unsigned int reference)
{
    unsigned int first = MODEL_VARIABLE_COUNT + (FMI_VERSION == 3);
    if (reference < MODEL_VARIABLE_COUNT) {
        return model_variables[reference].type == VAR_REAL && model_variables[reference].causality == CAUSALITY_OUTPUT;
    }
    return reference >= first && (int)(reference - first) < MODEL_STATE_COUNT;
}

static int enter_initialization(Host *host)
{
    double start = host->hostile && below(4) == 0 ? a_real(host, -1) : 0.0;
    host->time = start;
#if FMI_VERSION == 2
    {
        int status = checked(fmi2SetupExperiment(host->c, fmi2False, 0.0, start, fmi2False, 0.0), A_ENTER_INIT);
        if (status > 1) {
            return status;
        }
        return checked(fmi2EnterInitializationMode(host->c), A_ENTER_INIT);
    }
#else
    return checked(fmi3EnterInitializationMode(host->c, fmi3False, 0.0, start, fmi3False, 0.0), A_ENTER_INIT);
#endif
}

static int do_step(Host *host)
{
    double h = host->hostile && below(3) == 0 ? a_real(host, -1) : 1e-3, t = host->time;
    int status;
    if (host->hostile && below(6) == 0) {
        t = a_real(host, -1);
    }
#if FMI_VERSION == 2
    status = checked(fmi2DoStep(host->c, t, h, fmi2True), A_DO_STEP);
#else
    {
        fmi3Boolean event = fmi3False, terminate = fmi3False, early = fmi3False;
        fmi3Float64 last = 0.0;
        status = checked(fmi3DoStep(host->c, t, h, fmi3True, &event, &terminate, &early, &last), A_DO_STEP);
    }
#endif
    if (status <= 1 && isfinite(t + h)) {
        host->time = t + h;
    }
    return status;
}

static int continuous(Host *host, Action action)
{
    double x[SLOTS + 1];
    size_t n = a_count(host), i;
    int status;
    for (i = 0; i < SLOTS + 1; i++) {
        x[i] = 0.0;
    }
    switch (action) {
    case A_SET_STATES:
        if (F(GetContinuousStates)(host->c, x, MODEL_STATE_COUNT) > 1) {
            for (i = 0; i < SLOTS; i++) {
                x[i] = 0.0;
            }
        }
        calls_made++;
        for (i = 0; i < n; i++) {
            x[i] = host->hostile && below(2) ? a_real(host, STATE_VARIABLE(i))
                                             : x[i] + 1e-3;
        }
        return checked(F(SetContinuousStates)(host->c, x, n), action);
    case A_GET_STATES:
        status = checked(F(GetContinuousStates)(host->c, x, n), action);
        break;
    case A_GET_DERIVATIVES:
#if FMI_VERSION == 2
        status = checked(fmi2GetDerivatives(host->c, x, n), action);
#else
        status = checked(fmi3GetContinuousStateDerivatives(host->c, x, n), action);
#endif
        break;
    case A_GET_NOMINALS:
        status = checked(F(GetNominalsOfContinuousStates)(host->c, x, n), action);
        break;
    default: /* A_GET_INDICATORS */
        return checked(F(GetEventIndicators)(host->c, x, host->hostile ? (size_t)below(2) : 0), action);
    }
    finite_with(status, action, x, n < SLOTS + 1 ? n : SLOTS + 1);
    return status;
}

static int derivative(Host *host, int adjoint)
{
    unsigned int unknowns[ROWS], knowns[ROWS];
    double seed[ROWS], sensitivity[ROWS];
    size_t nu = jacobian_references(host, unknowns, 1), nk = jacobian_references(host, knowns, 0), i;
    size_t n_seed = adjoint ? nu : nk, n_sensitivity = adjoint ? nk : nu;
    int status;
    for (i = 0; i < ROWS; i++) {
        seed[i] = host->hostile && below(3) == 0 ? a_real(host, -1) : (i == 0 ? 1.0 : 0.0);
        sensitivity[i] = 0.0;
    }
#if FMI_VERSION == 2
    (void)n_seed, (void)n_sensitivity;
    if (adjoint) {
        return -1;
    }
    status = checked(fmi2GetDirectionalDerivative(host->c, unknowns, nu, knowns, nk, seed, sensitivity), A_DIRECTIONAL);
#else
    if (host->hostile && below(10) == 0) {
        n_seed += 1; /* a size that does not match */
    }
    status = checked((adjoint ? fmi3GetAdjointDerivative : fmi3GetDirectionalDerivative)(
                         host->c, unknowns, nu, knowns, nk, seed, n_seed, sensitivity, n_sensitivity),
                     adjoint ? A_ADJOINT : A_DIRECTIONAL);
#endif
    finite_with(status, A_DIRECTIONAL, sensitivity, n_sensitivity < ROWS ? n_sensitivity : ROWS);
    return status;
}

static int values(Host *host, Action action)
{
    unsigned int refs[MAX_REFS];
    double reals[MAX_REFS];
    int32_t integers[MAX_REFS];
    Truth truths[MAX_REFS];
    const char *strings[MAX_REFS];
    int type = action <= A_SET_REAL ? VAR_REAL : action <= A_SET_INTEGER ? VAR_INTEGER
               : action <= A_SET_BOOLEAN ? VAR_BOOLEAN : VAR_STRING;
    size_t n = references(host, refs, host->hostile && below(8) == 0 ? -1 : type), i;
    int status;
    for (i = 0; i < n; i++) {
        reals[i] = a_real(host, (int)refs[i]);
        integers[i] = an_integer(host, (int)refs[i]);
        truths[i] = (Truth)(host->hostile ? below(2) : refs[i] < MODEL_VARIABLE_COUNT && model_variables[refs[i]].start != 0.0);
        strings[i] = a_string(host, (int)refs[i]);
    }
    switch (action) {
#if FMI_VERSION == 2
    case A_GET_REAL:
        status = checked(fmi2GetReal(host->c, refs, n, reals), action);
        break;
    case A_SET_REAL:
        return checked(fmi2SetReal(host->c, refs, n, reals), action);
    case A_GET_INTEGER:
        return checked(fmi2GetInteger(host->c, refs, n, integers), action);
    case A_SET_INTEGER:
        return checked(fmi2SetInteger(host->c, refs, n, integers), action);
    case A_GET_BOOLEAN:
        return checked(fmi2GetBoolean(host->c, refs, n, truths), action);
    case A_SET_BOOLEAN:
        return checked(fmi2SetBoolean(host->c, refs, n, truths), action);
    case A_GET_STRING:
        return checked(fmi2GetString(host->c, refs, n, strings), action);
    default:
        return checked(fmi2SetString(host->c, refs, n, strings), action);
#else
    case A_GET_REAL:
        status = checked(fmi3GetFloat64(host->c, refs, n, reals, n), action);
        break;
    case A_SET_REAL:
        return checked(fmi3SetFloat64(host->c, refs, n, reals, n), action);
    case A_GET_INTEGER:
        return checked(fmi3GetInt32(host->c, refs, n, integers, n), action);
    case A_SET_INTEGER:
        return checked(fmi3SetInt32(host->c, refs, n, integers, n), action);
    case A_GET_BOOLEAN:
        return checked(fmi3GetBoolean(host->c, refs, n, truths, n), action);
    case A_SET_BOOLEAN:
        return checked(fmi3SetBoolean(host->c, refs, n, truths, n), action);
    case A_GET_STRING:
        return checked(fmi3GetString(host->c, refs, n, strings, n), action);
    default:
        return checked(fmi3SetString(host->c, refs, n, strings, n), action);
#endif
    }
    for (i = 0; status <= 1 && i < n; i++) {
        if (is_output_value(refs[i]) && !isfinite(reals[i])) {
            broken(ACTION[action], "gave an output that is not finite with OK");
        }
    }
    return status;
}

static int act(Host *host, Action action)
{
    static const char *const categories[] = {"logStatusError", "no such category"};
    int k = below(KEPT);
    switch (action) {
    case A_ENTER_INIT:
        return enter_initialization(host);
    case A_EXIT_INIT:
        return checked(F(ExitInitializationMode)(host->c), action);
    case A_TERMINATE:
        return checked(F(Terminate)(host->c), action);
    case A_RESET:
        return checked(F(Reset)(host->c), action);
    case A_DO_STEP:
        return do_step(host);
    case A_SET_TIME: {
        double t = host->hostile && below(3) == 0 ? a_real(host, -1) : host->time + 1e-3;
        int status = checked(F(SetTime)(host->c, t), action);
        host->time = status <= 1 && isfinite(t) ? t : host->time;
        return status;
    }
    case A_SET_STATES:
    case A_GET_STATES:
    case A_GET_DERIVATIVES:
    case A_GET_NOMINALS:
    case A_GET_INDICATORS:
        return continuous(host, action);
    case A_ENTER_EVENT:
        return checked(F(EnterEventMode)(host->c), action);
    case A_ENTER_CONTINUOUS:
        return checked(F(EnterContinuousTimeMode)(host->c), action);
    case A_DISCRETE: {
#if FMI_VERSION == 2
        fmi2EventInfo info;
        return checked(fmi2NewDiscreteStates(host->c, &info), action);
#else
        fmi3Boolean a, b, c, d, e;
        fmi3Float64 t;
        return checked(fmi3UpdateDiscreteStates(host->c, &a, &b, &c, &d, &e, &t), action);
#endif
    }
    case A_COMPLETED: {
        Truth enter = 0, terminate = 0;
        return checked(F(CompletedIntegratorStep)(host->c, 1, &enter, &terminate), action);
    }
    case A_DIRECTIONAL:
    case A_ADJOINT:
        return derivative(host, action == A_ADJOINT);
    case A_GET_STATE:
        return checked(GET_STATE(host->c, &host->kept[k]), action);
    case A_SET_STATE:
        return host->kept[k] != NULL ? checked(SET_STATE(host->c, host->kept[k]), action) : -1;
    case A_FREE_STATE:
        return checked(FREE_STATE(host->c, &host->kept[k]), action);
    case A_SAVED_BYTES:
        if (host->kept[k] != NULL) {
            saved_bytes(host, host->kept[k]);
        }
        return -1;
    case A_DEBUG_LOGGING:
        return checked(F(SetDebugLogging)(host->c, 1, host->hostile ? (size_t)below(3) : 1, categories), action);
    default:
        return values(host, action);
    }
}

/* ---- instances ---------------------------------------------------------------------------------- */

static char location[4096];

static int instantiate(Host *host, int model_exchange)
{
    memset(host, 0, sizeof *host);
#if FMI_VERSION == 2
    host->c = fmi2Instantiate("fuzz", model_exchange ? fmi2ModelExchange : fmi2CoSimulation, MODEL_TOKEN, location,
                              &callbacks, fmi2False, fmi2False);
#else
    host->c = model_exchange ? fmi3InstantiateModelExchange("fuzz", MODEL_TOKEN, location, fmi3False, fmi3False, NULL,
                                                            logger)
                             : fmi3InstantiateCoSimulation("fuzz", MODEL_TOKEN, location, fmi3False, fmi3False,
                                                           fmi3False, fmi3False, NULL, 0, NULL, logger, NULL);
#endif
    calls_made++;
    host->model_exchange = model_exchange;
    return host->c != NULL;
}

static void release(Host *host)
{
    int k;
    for (k = 0; k < KEPT; k++) {
        if (host->kept[k] != NULL) {
            checked(FREE_STATE(host->c, &host->kept[k]), A_FREE_STATE);
        }
    }
    F(FreeInstance)(host->c);
    calls_made++;
    cases_made++;
}

/* ---- the state machines -------------------------------------------------------------------------- */

/* 1 when the standard forbids ``a`` in ``w`` (of the Model Exchange interface ``me`` or co-simulation): the
 * call must be refused with Error. What the standard allows is not asked here (the FMUs' tests say what it
 * gives). */
static int forbidden(Action a, Where w, int me)
{
    int me_only = a == A_SET_TIME || a == A_SET_STATES || a == A_GET_STATES || a == A_GET_DERIVATIVES ||
                  a == A_GET_NOMINALS || a == A_GET_INDICATORS || a == A_ENTER_CONTINUOUS || a == A_COMPLETED ||
                  (FMI_VERSION == 2 && (a == A_ENTER_EVENT || a == A_DISCRETE));
    int sets = a == A_SET_REAL || a == A_SET_INTEGER || a == A_SET_BOOLEAN || a == A_SET_STRING;
    int moves = a == A_ENTER_INIT || a == A_EXIT_INIT || a == A_DO_STEP || a == A_SET_TIME || a == A_SET_STATES ||
                a == A_ENTER_EVENT || a == A_ENTER_CONTINUOUS || a == A_DISCRETE || a == A_COMPLETED ||
                a == A_TERMINATE;
    if ((!me && me_only) || (me && a == A_DO_STEP)) {
        return 1;
    }
    switch (w) {
    case S_INSTANTIATED:
        return a == A_EXIT_INIT || a == A_TERMINATE || a == A_DO_STEP || a == A_SET_TIME || a == A_SET_STATES ||
               a == A_ENTER_EVENT || a == A_ENTER_CONTINUOUS || a == A_DISCRETE || a == A_COMPLETED ||
               a == A_GET_DERIVATIVES || a == A_DIRECTIONAL || a == A_ADJOINT;
    case S_INITIALIZATION:
        return a == A_ENTER_INIT || a == A_DO_STEP || a == A_SET_TIME || a == A_SET_STATES || a == A_ENTER_EVENT ||
               a == A_ENTER_CONTINUOUS || a == A_DISCRETE || a == A_COMPLETED;
    case S_EVENT:
        return a == A_ENTER_INIT || a == A_EXIT_INIT || a == A_COMPLETED || (FMI_VERSION == 2 && a == A_SET_STATES);
    case S_CONTINUOUS:
        return a == A_ENTER_INIT || a == A_EXIT_INIT || a == A_DISCRETE || a == A_ENTER_CONTINUOUS;
    case S_STEP:
        return a == A_ENTER_INIT || a == A_EXIT_INIT;
    case S_TERMINATED:
        return moves || sets;
    default: /* S_ERROR */
        return moves || sets;
    }
}

/* Drives a fresh instance into ``w``; 0 if the model cannot get there (its start values refused). */
static int drive(Host *host, Where w)
{
    double x = NAN;
    if (w == S_INSTANTIATED) {
        return 1;
    }
    if (act(host, A_ENTER_INIT) > 1) {
        return 0;
    }
    if (w == S_INITIALIZATION) {
        return 1;
    }
    if (act(host, A_EXIT_INIT) > 1) {
        return 0;
    }
    if (w == S_CONTINUOUS) {
        return act(host, A_ENTER_CONTINUOUS) <= 1;
    }
    if (w == S_TERMINATED) {
        return act(host, A_TERMINATE) <= 1;
    }
    if (w == S_ERROR) { /* misuse: a time that is not finite */
        if (host->model_exchange) {
            return checked(F(SetTime)(host->c, x), A_SET_TIME) == 3;
        }
#if FMI_VERSION == 2
        return checked(fmi2DoStep(host->c, x, 1e-3, fmi2True), A_DO_STEP) == 3;
#else
        {
            fmi3Boolean e, t, r;
            fmi3Float64 last;
            return checked(fmi3DoStep(host->c, x, 1e-3, fmi3True, &e, &t, &r, &last), A_DO_STEP) == 3;
        }
#endif
    }
    return 1;
}

static void states(void)
{
    Host host;
    int me, w, a, status;
    for (me = 0; me <= 1; me++) {
        for (w = 0; w < S_COUNT; w++) {
            if ((me && w == S_STEP) || (!me && (w == S_EVENT || w == S_CONTINUOUS))) {
                continue;
            }
            for (a = 0; a < A_COUNT; a++) {
                if (!instantiate(&host, me)) {
                    if (me) {
                        return; /* a co-simulation-only model */
                    }
                    broken("Instantiate", "refused the model's own token");
                }
                if (!drive(&host, (Where)w)) {
                    printf("%s: cannot reach %s\n", me ? "ModelExchange" : "CoSimulation", WHERE[w]);
                    exit(1);
                }
                status = act(&host, (Action)a);
                if (status >= 0 && status != 3 && forbidden((Action)a, (Where)w, me)) {
                    printf("%s in %s of %s: status %d\n", ACTION[a], WHERE[w], me ? "ModelExchange" : "CoSimulation",
                           status);
                    broken(ACTION[a], "is forbidden there and was not refused with Error");
                }
                release(&host);
            }
        }
    }
}

/* The entry points the layer added or hardened (issue 45): each is a fuzz target of MODE "targets". */
static const Action TARGETS[] = {A_SET_TIME, A_SET_STATES, A_GET_STATES, A_GET_DERIVATIVES, A_GET_NOMINALS,
                                 A_GET_INDICATORS, A_ENTER_EVENT, A_ENTER_CONTINUOUS, A_DISCRETE, A_COMPLETED,
                                 A_DIRECTIONAL, A_ADJOINT, A_DO_STEP, A_GET_STATE, A_SET_STATE, A_SAVED_BYTES};
#define TARGET_COUNT ((int)(sizeof TARGETS / sizeof TARGETS[0]))
#define TARGET_CALLS 8

static void follow(Host *host, Action action, int status, Where *phase);

/* 1 when ``a`` belongs to the Model Exchange interface only */
static int model_exchange_only(Action a)
{
    return a == A_SET_TIME || a == A_SET_STATES || a == A_GET_STATES || a == A_GET_DERIVATIVES ||
           a == A_GET_NOMINALS || a == A_GET_INDICATORS || a == A_ENTER_CONTINUOUS || a == A_COMPLETED ||
           (FMI_VERSION == 2 && (a == A_ENTER_EVENT || a == A_DISCRETE));
}

static void targets(unsigned long cases)
{
    static const Where me_states[] = {S_INSTANTIATED, S_INITIALIZATION, S_EVENT, S_CONTINUOUS, S_TERMINATED, S_ERROR};
    static const Where cs_states[] = {S_INSTANTIATED, S_INITIALIZATION, S_STEP, S_TERMINATED, S_ERROR};
    Host host;
    Where phase;
    Action action;
    unsigned long c;
    int t, i, me, status, k, known;
    for (t = 0; t < TARGET_COUNT; t++) {
        for (c = 0; c < cases; c++) {
            me = model_exchange_only(TARGETS[t]) || TARGETS[t] == A_ADJOINT ? 1 : TARGETS[t] == A_DO_STEP ? 0 : below(2);
            if (!instantiate(&host, me)) {
                if (me) {
                    break; /* a co-simulation-only model */
                }
                broken("Instantiate", "refused the model's own token");
            }
            phase = me ? me_states[below(6)] : cs_states[below(5)];
            if (!drive(&host, phase)) {
                printf("%s: cannot reach %s\n", me ? "ModelExchange" : "CoSimulation", WHERE[phase]);
                exit(1);
            }
            for (k = 0; k < KEPT && (TARGETS[t] == A_SET_STATE || TARGETS[t] == A_SAVED_BYTES); k++) {
                act(&host, A_GET_STATE); /* a state to set or to corrupt */
            }
            for (i = 0, known = 1; i < TARGET_CALLS; i++) {
                action = i % 2 == 0 ? TARGETS[t] : (Action)below(A_COUNT);
                host.hostile = 1;
                status = act(&host, action);
                if (known && action == TARGETS[t] && status >= 0 && status != 3 && forbidden(action, phase, me)) {
                    printf("%s in %s of %s: status %d\n", ACTION[action], WHERE[phase],
                           me ? "ModelExchange" : "CoSimulation", status);
                    broken(ACTION[action], "is forbidden there and was not refused with Error");
                }
                follow(&host, action, status, &phase);
                known = known && action != A_SET_STATE && action != A_SAVED_BYTES; /* a saved state's mode */
            }
            release(&host);
        }
        printf("target %s cases %lu\n", ACTION[TARGETS[t]], c);
    }
}

/* The next call of a host that mostly goes on as a solver or a master would, from the phase its calls' statuses
 * left the instance in. */
static Action next_action(const Host *host, Where *phase)
{
    static const Action continuous_calls[] = {A_SET_STATES, A_GET_DERIVATIVES, A_DIRECTIONAL, A_SET_TIME, A_COMPLETED,
                                              A_GET_REAL, A_ADJOINT, A_GET_STATE, A_SET_REAL};
    static const Action step_calls[] = {A_DO_STEP, A_DIRECTIONAL, A_ADJOINT, A_SET_REAL, A_GET_REAL, A_GET_STATE};
    if (below(2)) {
        return (Action)below(A_COUNT);
    }
    switch (*phase) {
    case S_INSTANTIATED:
        return A_ENTER_INIT;
    case S_INITIALIZATION:
        return below(3) ? A_EXIT_INIT : A_SET_REAL;
    case S_EVENT:
        return A_ENTER_CONTINUOUS;
    case S_CONTINUOUS:
        return continuous_calls[below((int)(sizeof continuous_calls / sizeof continuous_calls[0]))];
    case S_STEP:
        return step_calls[below((int)(sizeof step_calls / sizeof step_calls[0]))];
    default:
        (void)host;
        return below(2) ? A_RESET : A_SET_STATE;
    }
}

static void follow(Host *host, Action action, int status, Where *phase)
{
    if (status == 3) {
        *phase = S_ERROR;
    } else if (status > 1 || status < 0) {
        return;
    } else if (action == A_ENTER_INIT) {
        *phase = S_INITIALIZATION;
    } else if (action == A_EXIT_INIT) {
        *phase = host->model_exchange ? S_EVENT : S_STEP;
    } else if (action == A_ENTER_CONTINUOUS) {
        *phase = S_CONTINUOUS;
    } else if (action == A_ENTER_EVENT) {
        *phase = S_EVENT;
    } else if (action == A_RESET) {
        *phase = S_INSTANTIATED;
    } else if (action == A_TERMINATE) {
        *phase = S_TERMINATED;
    }
}

static void sequences(unsigned long cases)
{
    Host host;
    Where phase;
    unsigned long c;
    int i, status;
    Action action;
    for (c = 0; c < cases; c++) {
        if (!instantiate(&host, below(3) != 0) && !instantiate(&host, 0)) {
            broken("Instantiate", "refused the model's own token");
        }
        phase = S_INSTANTIATED;
        for (i = 0; i < CALLS; i++) {
            action = next_action(&host, &phase);
            host.hostile = below(3) != 0;
            status = act(&host, action);
            follow(&host, action, status, &phase);
        }
        release(&host);
    }
}

int main(int argc, char **argv)
{
    unsigned long cases, c;
    Host host;
    if (argc != 5) {
        fprintf(stderr, "usage: %s sequences|states|targets|instantiate SEED CASES RESOURCES\n", argv[0]);
        return 2;
    }
    rng_state ^= strtoull(argv[2], NULL, 10) * 0x9E3779B97F4A7C15ull;
    if (rng_state == 0) {
        rng_state = 1;
    }
    cases = strtoul(argv[3], NULL, 10);
#if FMI_VERSION == 2
    snprintf(location, sizeof location, "file://%s", argv[4]);
#else
    snprintf(location, sizeof location, "%s", argv[4]);
#endif
    if (strcmp(argv[1], "states") == 0) {
        states();
    } else if (strcmp(argv[1], "sequences") == 0) {
        sequences(cases);
    } else if (strcmp(argv[1], "targets") == 0) {
        targets(cases);
    } else {
        for (c = 0; c < cases; c++) {
            if (instantiate(&host, 0)) {
                release(&host);
            }
        }
    }
    printf("calls %lu cases %lu\n", calls_made, cases_made);
    return 0;
}
