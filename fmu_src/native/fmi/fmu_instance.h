/* Shared core of the native co-simulation FMUs (FMI 2.0 and FMI 3.0): one instance, no global state.
 *
 * The FMI layers (fmi2_functions.c, fmi3_functions.c) translate the standard's calls into the
 * functions below; a model file (one per model) supplies the physics through the model_* hooks;
 * the generated model_variables.c supplies the variable table and the range checks' messages.
 * The step logic mirrors driveline/model.py (SteppedModel): a refused step leaves the model
 * exactly as it was and reports the same reasons, word for word.
 */
#ifndef FMU_INSTANCE_H
#define FMU_INSTANCE_H

#include <stddef.h>
#include <stdint.h>

#include "model_variables.h"
#include "fmu_messages.h"
#include "lib/python_numbers.h"

/* Marks a parameter the standard's signature has and this implementation does not need. */
#if defined(__GNUC__) || defined(__clang__)
#define UNUSED __attribute__((unused))
#else
#define UNUSED
#endif

/* Internal state slots: the most any model needs (PowertrainMounts: the Maxwell branches' forces, one per
 * mount, axis and branch; TripodCoupling needs 12: a flag and the exact solver's five-number warm start, the
 * bend samples, the rates' choice); a new count needs a new STATE_FORMAT (fmu_state.c). */
#define FMU_INTERNAL_SLOTS (MOUNTS_LAYOUT_MAX_MOUNTS * 3 * MOUNTS_RUBBER_BRANCHES)
/* Longest String value accepted, in characters (code points; model_adapter.MAX_STRING), and so
 * in bytes of UTF-8 at most four times that. */
#define FMU_MAX_STRING 4096
#define FMU_MAX_STRING_BYTES (4 * FMU_MAX_STRING)

typedef enum { VAR_REAL, VAR_INTEGER, VAR_BOOLEAN, VAR_STRING } VariableType;
/* A local is computed as an output is (checked after each step, read, never set) but is the model's own: an
 * internal state no host wires, in no list of outputs */
typedef enum { CAUSALITY_PARAMETER, CAUSALITY_INPUT, CAUSALITY_OUTPUT, CAUSALITY_LOCAL } Causality;

/* A refusal message: text, then the checked value or the bound it broke (as Python's repr(), or
 * in the display unit with format '.6g'), up to two values; generated from the Python checks. */
typedef enum { SLOT_END, SLOT_VALUE_REPR, SLOT_VALUE_DISPLAY, SLOT_BOUND_REPR, SLOT_BOUND_DISPLAY } Slot;

typedef struct {
    const char *text;
    Slot slot;
} MessagePiece;

typedef struct {
    MessagePiece pieces[3];
} MessageTemplate;

/* One variable of the model's spec; its value reference is its index in model_variables[]. */
typedef struct {
    const char *name;
    VariableType type;
    Causality causality;
    int tunable;  /* a parameter the host may change after initialisation */
    double start; /* start value (an Integer's as a double: exact for int32; a Boolean's 0 or 1) */
    int has_min, has_max, min_exclusive, max_exclusive;
    double min, max;
    double display_factor, display_offset; /* display unit (1, 0 without one) */
    MessageTemplate not_finite, outside_min, outside_max;
    const char *start_string; /* a String's start value, else NULL */
} VariableInfo;

/* The closed interval of doubles in which a checked variable needs no message of the range checks (a Real
 * finite, an exclusive bound the next double inward): the checks' common case in a few instructions. */
typedef struct {
    int variable, real;
    double low, high;
} CheckedRange;

typedef enum { OP_LT, OP_LE, OP_GT, OP_GE } Operator;

/* A declared relation ``lhs op scale * rhs + offset`` (rhs: a variable, or ``constant`` if -1). */
typedef struct {
    int lhs;
    Operator op;
    int rhs;
    double constant, scale, offset;
    int integer_bound; /* the bound is the Integer rhs itself */
    int involves_input; /* checked with the inputs, else with the parameters */
    MessageTemplate message;
} RelationInfo;

/* A message of one of the model's own checks (SteppedModel.extra_parameter_errors), cut from the
 * Python check run on its declared probe; it shows the value of ``variable``. */
typedef struct {
    int variable;
    MessageTemplate message;
} ExtraMessage;

/* An input that holds the ``order``-th time derivative of input ``input`` (Variable.derivative). */
typedef struct {
    int input, order, target;
} InputDerivative;

extern const VariableInfo model_variables[MODEL_VARIABLE_COUNT];
/* the variables the range checks read, by group (model_checked_from), with their ranges: generated */
extern const CheckedRange model_checked_ranges[MODEL_CHECKED_COUNT + 1];
#if MODEL_STATE_COUNT > 0
/* Model Exchange: the continuous states, the variables their time derivatives are, their nominal values */
extern const int model_states[MODEL_STATE_COUNT];
extern const int model_state_derivatives[MODEL_STATE_COUNT];
extern const double model_state_nominals[MODEL_STATE_COUNT];
#endif
/* Directional derivatives: each variable's row of the Jacobian (a Real output; der(<state k>) has row
 * MODEL_OUTPUT_ROWS + k) and column (a Real input or a state), -1 for none */
extern const int model_jacobian_rows[MODEL_VARIABLE_COUNT];
extern const int model_jacobian_columns[MODEL_VARIABLE_COUNT];
#if MODEL_INPUT_DERIVATIVE_COUNT > 0
extern const InputDerivative model_input_derivatives[MODEL_INPUT_DERIVATIVE_COUNT];
#endif
#if MODEL_RELATION_COUNT > 0
extern const RelationInfo model_relations[MODEL_RELATION_COUNT];
#endif
#if MODEL_EXTRA_MESSAGE_COUNT > 0
extern const ExtraMessage model_extra_messages[MODEL_EXTRA_MESSAGE_COUNT];
#endif

/* What a model keeps beside its variables that is not part of the FMU state (SteppedModel's
 * derived_state): data derived from the parameters, which the model rebuilds when the parameters
 * it was built for differ (after a change, a reset or a restored FMU state), and the FMU's
 * resources folder. One per instance; freed with it and on reset (ModelHooks.free_derived). */
typedef struct {
    void *derived;         /* owned by the model; NULL until it builds it */
    const char *resources; /* the resources folder, a path without a trailing separator; NULL: none */
} ModelCache;

/* The FMU state. Values are indexed by value reference; an Integer or a Boolean (0 or 1) is held in
 * int_value, a Real in real_value, a String in string_value (NUL-terminated UTF-8 the instance owns;
 * NULL for the other types). Strings are parameters: a step never changes them, so a copy of ModelData
 * made for a computation (Initialization Mode's values, the derivatives' point) may share them; every other
 * copy (an FMU state) owns copies of its own.
 * ``cache`` points at the instance's cache, never part of a state. A step (or a Model Exchange
 * evaluation) changes the values of the outputs and locals and the internal slots alone (StepUndo). */
typedef struct {
    double real_value[MODEL_VARIABLE_COUNT];
    int32_t int_value[MODEL_VARIABLE_COUNT];
    char *string_value[MODEL_VARIABLE_COUNT];
    double internal[FMU_INTERNAL_SLOTS]; /* model-specific internal state */
    double time;
    int initialized;
    ModelCache *cache;
} ModelData;

/* What a step may change, kept to undo a refused one: the values of the outputs and locals (the states among
 * them: model_real_computed, model_int_computed) and the internal slots. A model's hooks write nothing else
 * (tests/native/test_native_fmus.py reads every parameter and input around steps). */
typedef struct {
    double real[MODEL_REAL_COMPUTED_COUNT + 1];
    int32_t integer[MODEL_INT_COMPUTED_COUNT + 1];
    double internal[FMU_INTERNAL_SLOTS];
} StepUndo;

void step_undo_keep(const ModelData *data, StepUndo *undo);
void step_undo_restore(ModelData *data, const StepUndo *undo);

typedef enum { MODE_INSTANTIATED, MODE_INITIALIZATION, MODE_STEP, MODE_TERMINATED, MODE_ERROR } Mode;

typedef enum { STATUS_OK = 0, STATUS_WARNING = 1, STATUS_DISCARD = 2, STATUS_ERROR = 3 } Status;

typedef struct Instance Instance;
/* Hands one message to the host's logger of the instance's FMI version (as data, never a format). */
typedef void (*Emit)(const Instance *instance, Status status, const char *category, const char *message);

struct Instance {
    char *name;
    Emit emit;
    void (*host_logger)(void); /* the FMI version's logger callback */
    void *host_environment;
    const char *fmi_prefix;   /* "fmi2" or "fmi3", for misuse messages */
    Mode mode;
    double start_time;
    int terminated; /* the last step was refused: the same call is refused again (fmi2Terminated) */
    ModelData data;
    Messages messages;
    ModelCache cache;
    char *resources; /* owned; cache.resources points at it */
    char refusal[FMU_MESSAGE_SIZE]; /* the first reason of the last refusal or misuse: a repeat is not logged */
    char notice[FMU_MESSAGE_SIZE];  /* the model's last step notice (ModelHooks.step_notice): a repeat is not logged */
    int model_exchange; /* instantiated for Model Exchange (fmu_model_exchange.c) */
    int logging_on;     /* the host's loggingOn: an information line (status OK) is logged only then */
    int event_mode;     /* Model Exchange after initialisation: event mode, else continuous-time mode */
    int stale;          /* a time, state, input or parameter was set since the outputs were evaluated (Model
                         * Exchange) or the values read in Initialization Mode computed (``initial``) */
    int parameters_checked; /* the parameters passed their checks and none was set, reset or restored since: a
                             * step or an evaluation does not check them again (the same values, the same answer) */
    /* Initialization Mode: the values a get reads, initialised at the start time from what has been set so
     * far on a copy, as ExitInitializationMode initialises (instance_readable); ``initial_refused``: the
     * copy's initialisation was refused, a get reads the start values with a warning */
    ModelData initial;
    int initial_refused;
    /* The derivative functions' last Jacobian (fmu_derivatives.c), reused while the point is the same: the
     * Real and Integer values and the time it was computed at, and no reset, restored FMU state or String
     * set since (``epoch`` counts those). */
    double *jacobian; /* allocated at the first call; NULL before */
    ModelData jacobian_point;
    unsigned epoch, jacobian_epoch;
    int jacobian_valid;
};

/* A failure of a model's physics: its kind (ERROR_NONE: none) and Python's message of it
 * (ERROR_ZERO_DIVISION, "float division by zero"), logged as Python names it
 * ("ZeroDivisionError: float division by zero"). */
typedef struct {
    ErrorKind kind;
    const char *message;
} Failure;

#define FAILURE(kind, message) ((Failure){(kind), (message)})
#define NO_FAILURE FAILURE(ERROR_NONE, NULL)

/* ---- what a model file defines (see driveline/<model>/model.py) -------------------------
 * The physics returns NO_FAILURE, or the arithmetic failure Python raises. A model whose outputs
 * are functions of time alone gives ``at_time`` (start: at the start time, step: at its end); the
 * others give ``start`` and ``advance``. ``evaluate`` gives the outputs at ``time`` from the current
 * states, inputs and parameters, for Model Exchange (the states are the solver's: what it writes into
 * them is replaced; the internal state was reset before).
 * A NULL ``reset_internal``, ``extra_*_errors`` or ``start_notice`` means none. A model with derived
 * data builds it in ``extra_parameter_errors`` (run before every initialisation and step, once the
 * declared checks pass) into ``data->cache->derived``, keyed by the parameters it was built for, and gives
 * ``free_derived``; NULL: the model has none. ``jacobian`` gives the exact partial derivatives of the
 * Real outputs with respect to the Real inputs and the states (PARTIAL) at the point ``data`` holds,
 * whose outputs ``evaluate`` has just computed with the internal state reset; ``partial`` is zero
 * and the model writes what is not: the states' own rows and der(<state>)'s are the layer's
 * (fmu_derivatives.c). NULL: the FMU offers no directional derivatives. */
typedef struct {
    void (*reset_internal)(ModelData *data);
    Failure (*at_time)(ModelData *data, double time);
    Failure (*start)(ModelData *data, double start_time);
    Failure (*advance)(ModelData *data, double current_time, double step_size);
    Failure (*evaluate)(ModelData *data, double time);
    void (*extra_parameter_errors)(const ModelData *data, Messages *out);
    void (*extra_input_errors)(const ModelData *data, Messages *out);
    void (*free_derived)(void *derived);
    const char *(*start_notice)(const ModelData *data); /* SteppedModel.start_notice: logged once, a warning */
    /* SteppedModel.step_size_errors and step_notice: reasons to refuse a step of ``step_size`` (checked once the
     * parameters and inputs are valid), and after a step taken at most one warning, logged when it differs */
    void (*step_size_errors)(const ModelData *data, double step_size, Messages *out);
    void (*step_notice)(const ModelData *data, double step_size, Messages *out);
    Failure (*jacobian)(const ModelData *data, double partial[]);
} ModelHooks;

extern const ModelHooks model_hooks;

/* A Real variable of the model by its name, in a hook whose ModelData is ``data`` */
#define VALUE(name) (data->real_value[V_##name])
/* d output / d known in a ``jacobian`` hook: a Real output by name, a Real input or state by name */
#define PARTIAL(output, known) (partial[ROW_##output * MODEL_COLUMN_COUNT + COLUMN_##known])

/* ``start`` and ``advance`` of a model driven by an input shaft (DrivenShaftModel in
 * driveline/model.py): phi_in starts at phi_in_start and integrates the held omega_in exactly;
 * ``evaluate(data, input_time)`` gives the outputs at the current phi_in, input_time being the
 * communication point at which the host set the inputs. */
#define DRIVEN_SHAFT_HOOKS(evaluate)                                                                            \
    static Failure start(ModelData *data, double start_time)                                                    \
    {                                                                                                           \
        data->real_value[V_phi_in] = data->real_value[V_phi_in_start];                                          \
        return evaluate(data, start_time);                                                                      \
    }                                                                                                           \
    static Failure advance(ModelData *data, double current_time, double step_size)                              \
    {                                                                                                           \
        data->real_value[V_phi_in] = data->real_value[V_phi_in] + data->real_value[V_omega_in] * step_size;     \
        return evaluate(data, current_time);                                                                    \
    }

/* ---- helpers for model files (and messages_add, fmu_messages.h) ------------------------ */
#if MODEL_EXTRA_MESSAGE_COUNT > 0
/* Adds generated message ``message`` (a MESSAGE_* of model_variables.h) with its variable's value. */
void messages_add_extra(Messages *out, const ModelData *data, int message);
#endif

/* ---- between the layer's modules -------------------------------------------------------- */
/* fmu_checks.c: SteppedModel.parameter_errors, input_errors, output_errors, the check of state_from_saved */
void parameter_errors(const ModelData *data, Messages *out);
/* parameter_errors into the instance's messages unless the instance's parameters passed them and are unchanged */
void instance_parameter_errors(Instance *instance, const ModelData *data);
void input_errors(const ModelData *data, Messages *out);
void output_errors(const ModelData *data, Messages *out, Failure *failure);
void restored_errors(const ModelData *data, double start_time, Messages *out);
/* fmu_instance.c and fmu_values.c: String values */
char *copy_text(const char *text, size_t length);
void free_strings(char *strings[MODEL_VARIABLE_COUNT]);
int copy_strings(char *const from[MODEL_VARIABLE_COUNT], char *to[MODEL_VARIABLE_COUNT]);
size_t characters(const char *text, size_t length);

/* ---- life cycle (used by the FMI layers) -------------------------------------------- */
Status instance_reset(Instance *instance);
/* Sets the start time of the experiment; Error if it is not finite. */
Status instance_set_start_time(Instance *instance, const char *function, double start_time);
void instance_log(Instance *instance, Status status, const char *first, ...);
void instance_log_messages(Instance *instance, Status status);
/* Error unless the instance is in one of the modes of ``allowed`` (a bit mask of 1 << mode). */
int instance_allows(Instance *instance, unsigned allowed, const char *function);
Status instance_exit_initialization(Instance *instance);
/* The values a get reads now: in Initialization Mode those the instance would have after
 * ExitInitializationMode with nothing more set (``status`` Warning, the reasons logged once, where it would
 * refuse them: then the values set so far), else its own. */
const ModelData *instance_readable(Instance *instance, Status *status);
Status instance_terminate(Instance *instance);
Status instance_do_step(Instance *instance, double current_time, double step_size);
/* Discard with the instance's messages logged (once while they stay the same) if there are any;
 * else OK, the last refusal forgotten. */
Status instance_refusal(Instance *instance);
Status instance_set_real(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                         const double value[]);
Status instance_set_integer(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                            const int32_t value[]);
/* Sets the inputs that hold the ``order[i]``-th derivatives of inputs ``vr[i]`` (FMI 2.0's
 * SetRealInputDerivatives); Error, setting none, if one has no such input. */
Status instance_set_input_derivatives(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                                      const int32_t order[], const double value[]);
/* The state whose derivative has value reference ``reference`` (FMI 3.0: after time), or -1. */
int instance_derivative_of(const Instance *instance, uint32_t reference);
Status instance_get_real(Instance *instance, const char *function, const uint32_t vr[], size_t n, double value[]);
Status instance_get_integer(Instance *instance, const char *function, const uint32_t vr[], size_t n, int32_t value[]);
/* Booleans as the FMI version's type of ``size`` bytes (fmi2Boolean: int, fmi3Boolean: bool):
 * any non-zero value is true; got as 0 or 1. */
Status instance_set_boolean(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                            const void *value, size_t size);
Status instance_get_boolean(Instance *instance, const char *function, const uint32_t vr[], size_t n, void *value,
                            size_t size);
/* Strings are copied; a longer one than FMU_MAX_STRING characters, or NULL, is refused (Error)
 * and nothing is set. A string got stays valid until the next call that may change it (a set,
 * reset, set FMU state or free). */
Status instance_set_string(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                           const char *const value[]);
Status instance_get_string(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                           const char *value[]);
Status instance_fail(Instance *instance, const char *first, ...);
/* Get or set of a type the model has no variable of: OK for none, else Error naming the reference. */
Status instance_no_variables_of(Instance *instance, const char *function, const uint32_t vr[], size_t n,
                                const char *type, int setting);
/* Checks the categories; messages (all of status Error) are logged whether debug logging is on or not. */
Status instance_set_debug_logging(Instance *instance, const char *function, int logging_on, size_t n,
                                  const char *const categories[]);
/* A function of an interface type or capability these FMUs do not offer. */
Status instance_unsupported(Instance *instance, const char *function);

#define MODE_BIT(mode) (1u << (mode))
#define ANY_MODE 0x1Fu

/* The instance behind an FMI handle ``c``; a NULL handle gets ``result`` (there is no logger to tell). */
#define INSTANCE(c, result)                                                                                     \
    Instance *instance = (Instance *)(c);                                                                      \
    if (instance == NULL) {                                                                                     \
        return result;                                                                                          \
    }

/* A whole FMI function body: ``expression`` (of ``instance``, the instance behind handle ``c``) as
 * the status of FMI version ``version`` (fmi2 or fmi3); a NULL handle gets the version's Error. */
#define ON_INSTANCE(version, expression)                                                                        \
    {                                                                                                           \
        INSTANCE(c, version##Error)                                                                             \
        return (version##Status)(expression);                                                                  \
    }

/* ---- Model Exchange (fmu_model_exchange.c) -------------------------------------------- */
/* The outputs at the current time, states and inputs if one of them changed (OK otherwise, and for a
 * co-simulation instance); Discard with the reasons logged if the values are refused. */
Status model_exchange_update(Instance *instance);
Status model_exchange_set_time(Instance *instance, const char *function, double time);
Status model_exchange_set_states(Instance *instance, const char *function, const double x[], size_t n);
Status model_exchange_get_states(Instance *instance, const char *function, double x[], size_t n);
Status model_exchange_get_derivatives(Instance *instance, const char *function, double dx[], size_t n);
Status model_exchange_get_nominals(Instance *instance, const char *function, double nominals[], size_t n);
Status model_exchange_get_event_indicators(Instance *instance, const char *function, size_t n);
/* Enters event mode (``event`` 1) or continuous-time mode (0). */
Status model_exchange_enter_mode(Instance *instance, const char *function, int event);
/* 1 when ``function``, of Model Exchange after initialisation in event mode (``event`` 1) or continuous-time
 * mode (0), may run now with its output arguments (``outputs_given``: none is NULL); else Error with the
 * reason logged. */
int model_exchange_call(Instance *instance, const char *function, int outputs_given, int event);
/* Error unless the instance is one of the interface's (``model_exchange`` 1: Model Exchange). */
int instance_is(Instance *instance, int model_exchange, const char *function);
/* Evaluates the outputs into ``data`` (the instance's values, or a copy of them) at its time, states and
 * inputs with the internal state reset, checked as a co-simulation step checks them: the reasons of a
 * refusal in the instance's messages (none: the outputs are in ``data``). */
void model_exchange_evaluate(Instance *instance, ModelData *data);

/* ---- directional derivatives (fmu_derivatives.c) ------------------------------------------ */
/* The sensitivities J seed (``adjoint`` 0: FMI's directional derivative, ``n_seed`` = ``n_knowns``,
 * ``n_sensitivity`` = ``n_unknowns``) or seed^T J (``adjoint`` 1, the sizes the other way round) of the
 * Jacobian J of the ``unknowns`` (Real outputs, state derivatives) with respect to the ``knowns`` (Real
 * inputs, states) at the current time, states and inputs, after initialisation. Misuse: Error; a point a
 * step would refuse or a result that is not finite: Discard, the sensitivities unchanged. */
Status derivatives_get(Instance *instance, const char *function, const uint32_t unknowns[], size_t n_unknowns,
                       const uint32_t knowns[], size_t n_knowns, const double seed[], size_t n_seed,
                       double sensitivity[], size_t n_sensitivity, int adjoint);
/* The ``jacobian`` hook of a model whose outputs are functions of time and the parameters alone. */
Failure jacobian_of_time_alone(const ModelData *data, double partial[]);

/* ---- FMU state ------------------------------------------------------------------------ */
typedef struct StoredState StoredState;
Status state_get(Instance *instance, const char *function, void **state);
Status state_set(Instance *instance, const char *function, const void *state);
Status state_free(Instance *instance, const char *function, void **state);
Status state_size(Instance *instance, const char *function, const void *state, size_t *size);
Status state_serialize(Instance *instance, const char *function, const void *state, char *bytes, size_t size);
Status state_deserialize(Instance *instance, const char *function, const char *bytes, size_t size, void **state);

/* The six FMU state functions of FMI ``version`` (fmi2 or fmi3) over state_*: ``Handle`` is the
 * version's instance type, ``State`` and ``Deserialize`` its spellings of those words (FMI 2.0:
 * FMUstate, DeSerialize; FMI 3.0: FMUState, Deserialize). */
#define FMU_STATE_FUNCTIONS(version, Handle, State, Deserialize)                                               \
    version##Status version##Get##State(Handle c, version##State *state)                                       \
    ON_INSTANCE(version, state_get(instance, "Get" #State, state))                                             \
    version##Status version##Set##State(Handle c, version##State state)                                        \
    ON_INSTANCE(version, state_set(instance, "Set" #State, state))                                             \
    version##Status version##Free##State(Handle c, version##State *state)                                      \
    ON_INSTANCE(version, state_free(instance, "Free" #State, state))                                           \
    version##Status version##Serialized##State##Size(Handle c, version##State state, size_t *size)             \
    ON_INSTANCE(version, state_size(instance, "Serialized" #State "Size", state, size))                        \
    version##Status version##Serialize##State(Handle c, version##State state, version##Byte bytes[],           \
                                              size_t size)                                                     \
    ON_INSTANCE(version, state_serialize(instance, "Serialize" #State, state, (char *)bytes, size))            \
    version##Status version##Deserialize##State(Handle c, const version##Byte bytes[], size_t size,            \
                                                version##State *state)                                         \
    ON_INSTANCE(version, state_deserialize(instance, #Deserialize #State, (const char *)bytes, size, state))

/* ``resources``: the FMU's resources folder as a path (NULL: none); copied. */
Instance *instance_new(const char *name, const char *token, const char *fmi_prefix, Emit emit,
                       void (*host_logger)(void), void *host_environment, const char *resources);
/* The folder of an FMI 2.0 fmuResourceLocation (a file URI, percent-escapes decoded), newly
 * allocated; NULL for NULL, a URI of another scheme or no memory. */
char *resource_folder_of_uri(const char *uri);
void instance_free(Instance *instance);

#endif
