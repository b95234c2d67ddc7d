/* CriticalSpeeds: bending critical speeds, whirl frequencies, order resonances and the unbalance
 * response of a driveline shaft (Hruby, Nahlik 2021; port of driveline/rotor/model.py over the
 * rotor library, rotor.h next to this file).
 *
 * The analysis is the model's derived data (CriticalSpeedsModel.derived_state): built when the
 * parameters are checked, and only in the parts a change affects, each part kept with the
 * parameters it was built for (CriticalSpeedsModel._part): the driveline (structure and damping),
 * the structure (critical speeds, finite-element check), the Campbell table (structure and
 * omega_in_max), the order resonances (structure, orders, omega_in_max) and the unbalance outputs
 * (structure, damping, unbalance parameters, omega_in_max). A step only looks values up.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rotor.h"
#include "fmi/fmu_instance.h"

#define ERROR_SIZE FMU_MESSAGE_SIZE

/* ---- the parts of the analysis and their keys ------------------------------------------------ */

/* A part of the analysis (PART_<NAME>) and the parameters each is built for besides ``layout`` (and
 * ``orders`` for the resonances): model_part_values, generated from the Python model's
 * ANALYSIS_PARTS (driveline/rotor/model.py). */
typedef int Part;

/* The parameters a part was built for (compared by value, as Python compares the key tuples). */
typedef struct {
    int held;
    char *layout; /* owned */
    double values[PART_MOST_VALUES];
    int orders[ROTOR_MODEL_MAX_ORDERS], n_orders;
} Key;

typedef struct {
    Key keys[PARTS];
    Driveline driveline;
    /* structure */
    Chain *chain;
    double critical[3];
    int critical_count;
    double *natural;
    int natural_count;
    WhirlTable *whirl;
    OrderResonance *resonances;
    int resonance_count;
    UnbalanceOutputs *unbalance;
} Analysis;

static double parameter(const ModelData *data, int variable)
{
    return model_variables[variable].type == VAR_REAL ? data->real_value[variable] : (double)data->int_value[variable];
}

static int key_matches(const Key *key, const ModelData *data, Part part, const int *orders, int n_orders)
{
    int i;
    if (!key->held || strcmp(key->layout, data->string_value[V_layout]) != 0) {
        return 0;
    }
    for (i = 0; model_part_values[part][i] >= 0; i++) {
        if (!(key->values[i] == parameter(data, model_part_values[part][i]))) {
            return 0;
        }
    }
    if (part == PART_RESONANCES) {
        if (key->n_orders != n_orders) {
            return 0;
        }
        for (i = 0; i < n_orders; i++) {
            if (key->orders[i] != orders[i]) {
                return 0;
            }
        }
    }
    return 1;
}

/* Records that ``part`` now holds what ``data`` gives; 0 without memory (the part then counts as
 * not held). */
static int key_store(Key *key, const ModelData *data, Part part, const int *orders, int n_orders)
{
    size_t length = strlen(data->string_value[V_layout]);
    int i;
    free(key->layout);
    key->held = 0;
    key->layout = malloc(length + 1);
    if (key->layout == NULL) {
        return 0;
    }
    memcpy(key->layout, data->string_value[V_layout], length + 1);
    for (i = 0; model_part_values[part][i] >= 0; i++) {
        key->values[i] = parameter(data, model_part_values[part][i]);
    }
    key->n_orders = part == PART_RESONANCES ? n_orders : 0;
    for (i = 0; i < key->n_orders; i++) {
        key->orders[i] = orders[i];
    }
    key->held = 1;
    return 1;
}

static void drop_part(Analysis *analysis, Part part)
{
    Key *key = &analysis->keys[part];
    free(key->layout);
    key->layout = NULL;
    key->held = 0;
    switch (part) {
    case PART_DRIVELINE:
        driveline_free(&analysis->driveline);
        memset(&analysis->driveline, 0, sizeof analysis->driveline);
        break;
    case PART_STRUCTURE:
        chain_free(analysis->chain);
        analysis->chain = NULL;
        free(analysis->natural);
        analysis->natural = NULL;
        analysis->natural_count = 0;
        break;
    case PART_WHIRL:
        whirl_table_free(analysis->whirl);
        analysis->whirl = NULL;
        break;
    case PART_RESONANCES:
        free(analysis->resonances);
        analysis->resonances = NULL;
        analysis->resonance_count = 0;
        break;
    case PART_UNBALANCE:
        unbalance_outputs_free(analysis->unbalance);
        analysis->unbalance = NULL;
        break;
    case PARTS:
        break;
    }
}

static void free_analysis(void *derived)
{
    Analysis *analysis = derived;
    int part;
    if (analysis == NULL) {
        return;
    }
    for (part = 0; part < PARTS; part++) {
        drop_part(analysis, (Part)part);
    }
    free(analysis);
}

/* ---- Python's arithmetic ----------------------------------------------------------------------- */

/* Python's float ``x ** y``: finite operands with an infinite result raise OverflowError. */
static ErrorKind python_pow(double x, double y, double *out, char *error)
{
    *out = pow(x, y);
    if (isinf(*out) && isfinite(x) && isfinite(y)) {
        snprintf(error, ERROR_SIZE, "(34, 'Numerical result out of range')");
        return ERROR_OVERFLOW;
    }
    return ERROR_NONE;
}

/* Python's float ``x / y``: a zero divisor raises ZeroDivisionError. */
static ErrorKind python_divide(double x, double y, double *out, char *error)
{
    if (y == 0.0) {
        snprintf(error, ERROR_SIZE, "float division by zero");
        return ERROR_ZERO_DIVISION;
    }
    *out = x / y;
    return ERROR_NONE;
}

/* math.fsum; its failure's kind with Python's message. */
static ErrorKind fsum(const double *values, int n, double *sum, char *error)
{
    const char *failure;
    ErrorKind kind = python_fsum(values, n, sum, &failure);
    if (kind != ERROR_NONE) {
        snprintf(error, ERROR_SIZE, "%s", failure);
    }
    return kind;
}

/* ---- parse_orders ------------------------------------------------------------------------------ */

/* The code point of UTF-8 ``text`` at ``at`` (of ``end``), its byte count in ``*bytes``; a byte
 * that starts no valid sequence is itself. */
static unsigned long code_point(const unsigned char *text, size_t at, size_t end, size_t *bytes)
{
    unsigned long point = text[at];
    size_t count = point >= 0xF0u ? 4 : point >= 0xE0u ? 3 : point >= 0xC0u ? 2 : 1, i;
    if (count == 1 || at + count > end) {
        *bytes = 1;
        return point;
    }
    point &= 0x3Fu >> (count - 1);
    for (i = 1; i < count; i++) {
        if ((text[at + i] & 0xC0u) != 0x80u) {
            *bytes = 1;
            return text[at];
        }
        point = (point << 6) | (text[at + i] & 0x3Fu);
    }
    *bytes = count;
    return point;
}

/* str.isspace of one code point */
static int python_space(unsigned long c)
{
    return (c >= 0x09 && c <= 0x0D) || (c >= 0x1C && c <= 0x20) || c == 0x85 || c == 0xA0 || c == 0x1680 ||
           (c >= 0x2000 && c <= 0x200A) || c == 0x2028 || c == 0x2029 || c == 0x202F || c == 0x205F || c == 0x3000;
}

/* The start of the last code point before ``end`` (after ``start``). */
static size_t previous_point(const unsigned char *text, size_t start, size_t end)
{
    size_t at = end - 1;
    while (at > start && end - at < 4 && (text[at] & 0xC0u) == 0x80u) {
        at--;
    }
    return at;
}

/* parse_orders: "1,2,3,6" -> 1, 2, 3, 6; ERROR_NONE, else ERROR_VALUE with the Python message. */
static ErrorKind parse_orders(const char *text, int *orders, int *count, char *error)
{
    const unsigned char *bytes = (const unsigned char *)text;
    size_t length = strlen(text), start = 0, end, at, size, cut;
    int commas = 0, value;
    char shown[256], prefix[4 * 20 + 1]; /* repr of 20 characters: 10 bytes each at most */
    for (at = 0; at < length; at++) {
        commas += text[at] == ',';
    }
    if (commas >= ROTOR_MODEL_MAX_ORDERS) { /* text.split(",", MAX_ORDERS) gives more than MAX_ORDERS entries */
        snprintf(error, ERROR_SIZE, "parameter orders lists more than %d orders", ROTOR_MODEL_MAX_ORDERS);
        return ERROR_VALUE;
    }
    *count = 0;
    while (start <= length) {
        const char *comma = memchr(text + start, ',', length - start);
        size_t stop = comma != NULL ? (size_t)(comma - text) : length, first = start, points = 0;
        int ascii_digits = 1;
        end = stop;
        while (first < end && python_space(code_point(bytes, first, end, &size))) { /* str.strip() */
            first += size;
        }
        while (end > first) {
            size_t last = previous_point(bytes, first, end);
            if (!python_space(code_point(bytes, last, end, &size)) || last + size != end) {
                break;
            }
            end = last;
        }
        value = 0;
        for (at = first; at < end; at++) {
            ascii_digits = ascii_digits && text[at] >= '0' && text[at] <= '9';
            value = ascii_digits && at - first < 3 ? 10 * value + (text[at] - '0') : value;
        }
        if (!(ascii_digits && end > first && end - first <= 3 && value >= 1 && value <= ROTOR_MODEL_MAX_ORDER)) {
            for (cut = first; cut < end && points < 20; points++) { /* digits[:20] */
                code_point(bytes, cut, end, &size);
                cut += size;
            }
            memcpy(prefix, text + first, cut - first);
            prefix[cut - first] = '\0';
            python_str_repr(prefix, 20, shown, sizeof shown);
            snprintf(error, ERROR_SIZE, "parameter orders: %s is not an integer from 1 to %d", shown,
                     ROTOR_MODEL_MAX_ORDER);
            return ERROR_VALUE;
        }
        orders[(*count)++] = value;
        start = stop + 1;
    }
    return ERROR_NONE;
}

/* A tuple of ints as Python prints it: "(1, 2, 3)", "(1,)". */
static void orders_tuple(const int *orders, int count, char *out, size_t size)
{
    size_t used;
    int i;
    snprintf(out, size, "(");
    for (i = 0; i < count; i++) {
        used = strlen(out);
        snprintf(out + used, size - used, i == 0 ? "%d" : ", %d", orders[i]);
    }
    used = strlen(out);
    snprintf(out + used, size - used, count == 1 ? ",)" : ")");
}

/* ---- the analysis ------------------------------------------------------------------------------ */

static ErrorKind build_one_piece(const ModelData *data, Driveline *out, char *error);

/* build_driveline: the one-piece tube of the parameters, or the layout (a file or a shipped name);
 * refused when shear = false meets a layout segment with shear, or when the supports leave the
 * shaft a mechanism (mechanism.py). */
static ErrorKind build_driveline(const ModelData *data, Driveline *out, char *error)
{
    const char *layout = data->string_value[V_layout];
    int hinge = 0, node = 0, i;
    char least[40];
    ErrorKind failed;
    if (layout[0] != '\0') {
        failed = driveline_from_layout(layout, data->cache->resources, out, error, ERROR_SIZE);
        for (i = 0; !failed && !data->int_value[V_shear] && i < out->n_segments; i++) {
            if (out->segments[i].shear) {
                snprintf(error, ERROR_SIZE, "%s", SHEAR_CONFLICT);
                failed = ERROR_VALUE;
            }
        }
    } else {
        failed = build_one_piece(data, out, error);
    }
    switch (failed ? MECHANISM_NONE : driveline_mechanism(out, &hinge, &node)) {
    case MECHANISM_NONE:
        return failed;
    case MECHANISM_HINGE_FOLDS:
        python_format_g(driveline_least_resolved_stiffness(out), 6, least, sizeof least);
        snprintf(error, ERROR_SIZE, MECHANISM_HINGE, hinge, node, least);
        return ERROR_VALUE;
    case MECHANISM_RIGID_BODY:
        snprintf(error, ERROR_SIZE, "%s", MECHANISM_RIGID);
        return ERROR_VALUE;
    default:
        snprintf(error, ERROR_SIZE, "out of memory");
        return ERROR_VALUE;
    }
}

/* loader.one_piece_shaft of the parameters; returns as driveline_one_piece. */
static ErrorKind build_one_piece(const ModelData *data, Driveline *out, char *error)
{
    OnePieceShaft shaft;
    shaft.L_shaft = VALUE(L_shaft);
    shaft.D_outer = VALUE(D_outer);
    shaft.D_inner = VALUE(D_inner);
    shaft.E = VALUE(E);
    shaft.density = VALUE(density);
    shaft.m_joint = VALUE(m_joint);
    shaft.Jp_joint = VALUE(Jp_joint);
    shaft.Jd_joint = VALUE(Jd_joint);
    shaft.k_bearing = VALUE(k_bearing);
    shaft.c_bearing = VALUE(c_bearing);
    shaft.shear = data->int_value[V_shear] != 0;
    return driveline_one_piece(&shaft, out, error, ERROR_SIZE);
}

/* searched_modes: bare-shaft bending modes below the frequencies the order-resonance searches scan,
 * times the stations a determinant evaluation passes. */
static ErrorKind searched_modes(const Driveline *driveline, const int *orders, int n_orders, double omega_max,
                                double *work, char *error)
{
    double *terms, kappa, scanned, squared_outer, squared_inner, fourth_outer, fourth_inner, ratio, root;
    int seen[ROTOR_MODEL_MAX_ORDER + 1] = {0}, i, n = 0;
    ErrorKind failed = ERROR_NONE;
    terms = malloc(((size_t)driveline->n_segments + ROTOR_MODEL_MAX_ORDERS + 1) * sizeof *terms);
    if (terms == NULL) {
        snprintf(error, ERROR_SIZE, "out of memory");
        return ERROR_VALUE;
    }
    for (i = 0; i < driveline->n_segments && !failed; i++) {
        const RotorSegment *s = &driveline->segments[i];
        double mass_per_length, bending_stiffness;
        failed = python_pow(s->outer_diameter, 2.0, &squared_outer, error); /* rho A */
        failed = failed ? failed : python_pow(s->inner_diameter, 2.0, &squared_inner, error);
        if (failed) {
            break;
        }
        mass_per_length = s->density * (FMU_PI / 4.0 * (squared_outer - squared_inner));
        failed = python_pow(s->outer_diameter, 4.0, &fourth_outer, error); /* E J */
        failed = failed ? failed : python_pow(s->inner_diameter, 4.0, &fourth_inner, error);
        if (failed) {
            break;
        }
        bending_stiffness = s->youngs_modulus * (FMU_PI / 64.0 * (fourth_outer - fourth_inner));
        failed = python_divide(mass_per_length, bending_stiffness, &ratio, error);
        failed = failed ? failed : python_pow(ratio, 0.25, &root, error);
        if (!failed) {
            terms[n++] = s->length * root;
        }
    }
    failed = failed ? failed : fsum(terms, n, &kappa, error);
    if (failed) {
        free(terms);
        return failed;
    }
    n = 0;
    seen[1] = 1; /* {1, *orders} */
    terms[n++] = sqrt(2.0 * 1 * omega_max);
    for (i = 0; i < n_orders; i++) {
        if (!seen[orders[i]]) {
            seen[orders[i]] = 1;
            terms[n++] = sqrt(2.0 * orders[i] * omega_max);
        }
    }
    failed = fsum(terms, n, &scanned, error);
    free(terms);
    if (failed) {
        return failed;
    }
    *work = kappa * scanned / FMU_PI * (driveline->n_segments + 1);
    return ERROR_NONE;
}

/* ---- work.py: the estimate of every stage, before any stage starts ------------------------------ */

/* work._grid: points of one search line up to the bare-shaft phase ``phase``. */
static double work_grid(double per_pi, double phase)
{
    return per_pi * phase / FMU_PI + 8.0;
}

static const char *const STAGE_NAMES[WORK_STAGE_COUNT] = {WORK_STAGE_0, WORK_STAGE_1, WORK_STAGE_2,
                                                          WORK_STAGE_3, WORK_STAGE_4, WORK_STAGE_5};

/* work.estimate into ``seconds`` (one per stage), then Work.refusal: ERROR_NONE, or the refusal
 * (ERROR_VALUE) or a failure's kind with its message in ``error``. */
static ErrorKind work_refusal(const Driveline *driveline, const int *orders, int n_orders, double omega_max,
                              double seconds[WORK_STAGE_COUNT], char *error)
{
    double terms[ROTOR_MODEL_MAX_ORDERS + 1], per_pi, kappa, to_limit, resonances, check,
        total, search;
    int seen[ROTOR_MODEL_MAX_ORDER + 1] = {0}, *counts, i, n = 0, stations, planes = 1, isotropic, freedoms, table = 0,
        response = 0;
    char shown[40], stage[80];
    size_t used;
    Chain *chain;
    ErrorKind failed = chain_new(driveline, &chain, error, ERROR_SIZE);
    counts = malloc(((size_t)driveline->n_segments + 1) * sizeof *counts);
    if (failed != ERROR_NONE || counts == NULL) {
        chain_free(chain);
        free(counts);
        if (failed == ERROR_NONE) {
            snprintf(error, ERROR_SIZE, "out of memory");
            failed = ERROR_VALUE;
        }
        return failed;
    }
    isotropic = chain_isotropic(chain);
    freedoms = chain_freedoms(chain);
    kappa = chain_kappa(chain);
    chain_free(chain);
    stations = driveline->n_segments + 1 + driveline->n_masses + driveline->n_bearings + driveline->n_hinges;
    per_pi = (double)(ROTOR_DRIVELINE_POINTS_PER_ROOT * (1 + freedoms) * (isotropic ? 1 : 2));
    to_limit = work_grid(per_pi, kappa * sqrt(ROTOR_DRIVELINE_SEARCH_LIMIT));
    seen[1] = 1; /* {1, *orders} */
    terms[n++] = 2.0 * work_grid(per_pi, kappa * sqrt(2.0 * 1 * omega_max)) +
                 2.0 * work_grid(per_pi, kappa * sqrt(1 * ROTOR_DRIVELINE_SEARCH_LIMIT));
    for (i = 0; i < n_orders; i++) {
        if (!seen[orders[i]]) {
            seen[orders[i]] = 1;
            terms[n++] = 2.0 * work_grid(per_pi, kappa * sqrt(2.0 * orders[i] * omega_max)) +
                         2.0 * work_grid(per_pi, kappa * sqrt(orders[i] * ROTOR_DRIVELINE_SEARCH_LIMIT));
        }
    }
    for (i = 0; i < driveline->n_bearings; i++) {
        planes = driveline->bearings[i].kxx == driveline->bearings[i].kyy ? planes : 2;
    }
    fe_elements_by_length(driveline, ROTOR_UNBALANCE_OUTPUTS_TABLE_ELEMENTS, counts);
    for (i = 0; i < driveline->n_segments; i++) {
        table += counts[i];
    }
    fe_elements_by_length(driveline, ROTOR_UNBALANCE_OUTPUTS_FE_ELEMENTS, counts);
    for (i = 0; i < driveline->n_segments; i++) {
        response += counts[i];
    }
    free(counts);
    failed = fsum(terms, n, &resonances, error);
    if (failed) {
        return failed;
    }
    check = planes * pow(2.0 * (ROTOR_MODEL_FE_ELEMENTS * driveline->n_segments + 1 + driveline->n_hinges), 3.0);
    search = ROTOR_WORK_RATE_SEARCH * stations;
    seconds[0] = search * (2.0 * to_limit);
    seconds[1] = search * resonances;
    seconds[2] = search * (2.0 * 2.0 * (ROTOR_MODEL_CAMPBELL_POINTS + ROTOR_CAMPBELL_MAX_KNOTS) * to_limit);
    seconds[3] = ROTOR_WORK_RATE_DENSE * check;
    seconds[4] = ROTOR_WORK_RATE_BANDED * (ROTOR_UNBALANCE_OUTPUTS_DAMPING_POINTS * 4.0 * (table + 1));
    seconds[5] = ROTOR_WORK_RATE_BANDED * (4.0 * (response + 1));
    failed = fsum(seconds, WORK_STAGE_COUNT, &total, error);
    if (failed) {
        return failed;
    }
    if (total <= ROTOR_WORK_MAX_ANALYSIS_SECONDS) {
        return ERROR_NONE;
    }
    python_format_g(total, 3, shown, sizeof shown);
    snprintf(error, ERROR_SIZE, "the analysis would take about %s s (", shown);
    used = strlen(error);
    for (i = 0; i < WORK_STAGE_COUNT; i++) {
        python_format_g(seconds[i], 3, shown, sizeof shown);
        snprintf(stage, sizeof stage, "%s%s %s s", i ? ", " : "", STAGE_NAMES[i], shown);
        text_append(error, ERROR_SIZE, &used, stage, strlen(stage));
    }
    python_format_g(ROTOR_WORK_MAX_ANALYSIS_SECONDS, 6, shown, sizeof shown);
    snprintf(stage, sizeof stage, "), more than the %s s accepted ", shown);
    text_append(error, ERROR_SIZE, &used, stage, strlen(stage));
    text_append(error, ERROR_SIZE, &used, WORK_ADVICE, strlen(WORK_ADVICE));
    return ERROR_VALUE;
}

/* budget.seconds_units: the units of a stage estimated at ``seconds`` (rounded up) */
static long long seconds_units(double seconds)
{
    return (long long)ceil(seconds / ROTOR_BUDGET_SECONDS_PER_UNIT);
}

/* The stage ``stage`` (work.STAGES) pays from ``budget`` from now on; ``seconds`` >= 0: its estimate, paid
 * whole now (a finite-element stage). ERROR_NONE, or ERROR_VALUE when the budget is spent. */
static ErrorKind spend(Budget *budget, int stage, double seconds, char *error)
{
    budget->stage = STAGE_NAMES[stage];
    if (seconds >= 0.0) {
        budget_charge(budget, seconds_units(seconds));
    }
    if (budget->spent) {
        ROTOR_ERROR(error, ERROR_SIZE, ROTOR_BUDGET_SPENT);
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

/* analyse_structure: the chain, the critical speeds (missing ones read as the search limit) and the
 * finite-element check's natural frequencies, paid from ``budget`` (the check at its estimate). */
static ErrorKind analyse_structure(Analysis *analysis, Budget *budget, const double *seconds, char *error)
{
    double spins[3];
    int count = 0, i;
    ErrorKind failed;
    failed = chain_new(&analysis->driveline, &analysis->chain, error, ERROR_SIZE);
    if (failed) {
        return failed;
    }
    chain_set_budget(analysis->chain, budget);
    failed = spend(budget, 0, -1.0, error);
    failed = failed ? failed : rotor_critical_speeds(analysis->chain, 3, spins, &count, error, ERROR_SIZE);
    if (failed) {
        return failed;
    }
    for (i = 0; i < 3; i++) {
        analysis->critical[i] = i < count ? spins[i] : ROTOR_DRIVELINE_SEARCH_LIMIT;
    }
    analysis->critical_count = count;
    failed = spend(budget, 3, seconds[3], error);
    return failed ? failed : fe_natural_frequencies(&analysis->driveline, ROTOR_MODEL_FE_ELEMENTS, &analysis->natural,
                                                    &analysis->natural_count, error, ERROR_SIZE);
}

/* implausibility: the first two whirl frequencies at standstill must each match a natural
 * frequency of the finite-element check within PLAUSIBLE_DEVIATION; ERROR_NONE, else ERROR_VALUE with
 * the message (np.argmin's ValueError for no natural frequency, whirl_table's refusal). */
static ErrorKind implausibility(const Analysis *analysis, char *error)
{
    double at_rest[2 * ROTOR_MODEL_WHIRL_MODES], nearest, deviation, best = 0.0;
    char frequency_shown[40], nearest_shown[40];
    int i, j, found;
    whirl_table_evaluate(analysis->whirl, 0.0, at_rest);
    for (i = 0; i < ROTOR_MODEL_WHIRL_MODES; i++) {
        double frequency = at_rest[i];
        if (frequency >= ROTOR_DRIVELINE_SEARCH_LIMIT) {
            continue;
        }
        if (analysis->natural_count == 0) {
            snprintf(error, ERROR_SIZE, "attempt to get argmin of an empty sequence");
            return ERROR_VALUE;
        }
        found = 0;
        for (j = 0; j < analysis->natural_count; j++) { /* np.argmin: the first smallest (a NaN first) */
            deviation = fabs(analysis->natural[j] - frequency);
            if (isnan(deviation)) {
                found = j;
                break;
            }
            if (j == 0 || deviation < best) {
                best = deviation;
                found = j;
            }
        }
        nearest = analysis->natural[found];
        if (!(fabs(nearest - frequency) <= ROTOR_MODEL_PLAUSIBLE_DEVIATION * frequency)) {
            python_format_g(frequency, 6, frequency_shown, sizeof frequency_shown);
            python_format_g(nearest, 6, nearest_shown, sizeof nearest_shown);
            snprintf(error, ERROR_SIZE,
                     "the whirl frequency %s rad/s at standstill has no counterpart in the finite-element check "
                     "(nearest %s rad/s): the parameters are beyond what double precision resolves",
                     frequency_shown, nearest_shown);
            return ERROR_VALUE;
        }
    }
    return ERROR_NONE;
}

/* resonances: every order resonance of ``orders`` (both senses) up to 2 omega_max, or the first
 * forward one of each order when none lies there; ERROR_NONE, else the failure's kind with the message
 * (ERROR_VALUE for none found). */
static ErrorKind resonances(Analysis *analysis, const int *orders, int n_orders, double omega_max, char *error)
{
    char tuple[4 * ROTOR_MODEL_MAX_ORDERS + 8];
    ErrorKind failed = rotor_order_resonances(analysis->chain, orders, n_orders, WHIRL_FORWARD | WHIRL_BACKWARD, 0,
                                              2.0 * omega_max, ROTOR_DRIVELINE_SEARCH_LIMIT, &analysis->resonances,
                                              &analysis->resonance_count, error, ERROR_SIZE);
    if (failed != ERROR_NONE) {
        return failed;
    }
    if (analysis->resonance_count == 0) {
        free(analysis->resonances);
        analysis->resonances = NULL;
        failed = rotor_order_resonances(analysis->chain, orders, n_orders, WHIRL_FORWARD, 1, 0.0,
                                        ROTOR_DRIVELINE_SEARCH_LIMIT, &analysis->resonances,
                                        &analysis->resonance_count, error, ERROR_SIZE);
        if (failed != ERROR_NONE) {
            return failed;
        }
    }
    if (analysis->resonance_count == 0) {
        orders_tuple(orders, n_orders, tuple, sizeof tuple);
        snprintf(error, ERROR_SIZE, "no order resonance of the orders %s below the search limit 100000 rad/s", tuple);
        return ERROR_VALUE;
    }
    return ERROR_NONE;
}

/* The unbalance outputs: a layout's own unbalances, or the one-piece tube's single unbalance;
 * ERROR_NONE, else the failure's kind with the message (ERROR_VALUE for a position off the shaft). */
static ErrorKind unbalance_outputs(Analysis *analysis, const ModelData *data, char *error)
{
    RotorUnbalance single;
    const RotorUnbalance *unbalances = analysis->driveline.unbalances;
    int count = analysis->driveline.n_unbalances;
    char shown[40];
    if (data->string_value[V_layout][0] == '\0') {
        single.position = VALUE(unbalance_position) * driveline_length(&analysis->driveline);
        single.amount = VALUE(unbalance);
        single.phase = 0.0;
        if (!isfinite(single.position) || single.position < 0.0) { /* elements._non_negative */
            python_float_repr(single.position, shown, sizeof shown);
            snprintf(error, ERROR_SIZE, "position must be a finite number >= 0, got %s", shown);
            return ERROR_VALUE;
        }
        unbalances = &single;
        count = 1;
    }
    return unbalance_outputs_new(&analysis->driveline, unbalances, count, VALUE(response_position), VALUE(omega_in_max),
                                 &analysis->unbalance, error, ERROR_SIZE);
}

/* One part: kept when its key is unchanged, else dropped and computed anew (kept on success only), paid
 * from ``budget`` (the finite-element stages at their estimates ``seconds``). */
static ErrorKind part(Analysis *analysis, const ModelData *data, Part which, const int *orders, int n_orders,
                      Budget *budget, const double *seconds, char *error)
{
    ErrorKind failed;
    if (key_matches(&analysis->keys[which], data, which, orders, n_orders)) {
        return ERROR_NONE;
    }
    drop_part(analysis, which);
    switch (which) {
    case PART_DRIVELINE:
        failed = build_driveline(data, &analysis->driveline, error);
        break;
    case PART_STRUCTURE:
        failed = analyse_structure(analysis, budget, seconds, error);
        break;
    case PART_WHIRL:
        failed = spend(budget, 2, -1.0, error);
        failed = failed ? failed : whirl_table_new(analysis->chain, VALUE(omega_in_max), ROTOR_MODEL_CAMPBELL_POINTS,
                                                   ROTOR_MODEL_WHIRL_MODES, &analysis->whirl, error, ERROR_SIZE);
        failed = failed ? failed : implausibility(analysis, error);
        break;
    case PART_RESONANCES:
        failed = spend(budget, 1, -1.0, error);
        failed = failed ? failed : resonances(analysis, orders, n_orders, VALUE(omega_in_max), error);
        break;
    default:
        failed = spend(budget, 4, seconds[4], error);
        failed = failed ? failed : spend(budget, 5, seconds[5], error);
        failed = failed ? failed : unbalance_outputs(analysis, data, error);
        break;
    }
    if (!failed && !key_store(&analysis->keys[which], data, which, orders, n_orders)) {
        snprintf(error, ERROR_SIZE, "out of memory");
        failed = ERROR_VALUE;
    }
    if (failed) {
        drop_part(analysis, which);
    }
    return failed;
}

/* Whether every part holds for these parameters: the last analysis succeeded for exactly them, work
 * check included (Python: key == _analysed_for), so a step has nothing to check or build. */
static int analysed_for(const Analysis *analysis, const ModelData *data, const int *orders, int n_orders)
{
    int which;
    for (which = 0; which < PARTS; which++) {
        if (!key_matches(&analysis->keys[which], data, (Part)which, orders, n_orders)) {
            return 0;
        }
    }
    return 1;
}

/* CriticalSpeedsModel.extra_parameter_errors: analyse what a changed parameter affects. */
static void extra_parameter_errors(const ModelData *data, Messages *out)
{
    static const Part later[] = {PART_STRUCTURE, PART_WHIRL, PART_RESONANCES, PART_UNBALANCE};
    ModelCache *cache = data->cache;
    Analysis *analysis = cache->derived;
    int orders[ROTOR_MODEL_MAX_ORDERS], n_orders = 0;
    size_t i;
    ErrorKind failed;
    double work = 0.0, seconds[WORK_STAGE_COUNT];
    Budget budget = {ROTOR_BUDGET_UNITS, 0, "", ""}; /* the parts analysed anew pay from it, the kept ones not again */
    char error[ERROR_SIZE] = "", shown[40];
    if (analysis == NULL) {
        analysis = calloc(1, sizeof *analysis);
        if (analysis == NULL) {
            messages_add(out, "driveline: out of memory", (const char *)NULL);
            return;
        }
        cache->derived = analysis;
    }
    failed = parse_orders(data->string_value[V_orders], orders, &n_orders, error);
    if (!failed && analysed_for(analysis, data, orders, n_orders)) {
        return;
    }
    failed = failed ? failed : part(analysis, data, PART_DRIVELINE, orders, n_orders, &budget, seconds, error);
    failed = failed ? failed
                    : searched_modes(&analysis->driveline, orders, n_orders, VALUE(omega_in_max), &work, error);
    if (!failed && !(work <= ROTOR_MODEL_MAX_SEARCHED_MODES)) {
        python_format_g(work, 3, shown, sizeof shown);
        snprintf(error, sizeof error,
                 "the analysis would scan %s shaft modes, more than the %.0f accepted (shorter or stiffer shaft, "
                 "fewer or lower orders, or a smaller omega_in_max)", shown, ROTOR_MODEL_MAX_SEARCHED_MODES);
        failed = ERROR_VALUE;
    }
    failed = failed ? failed
                    : work_refusal(&analysis->driveline, orders, n_orders, VALUE(omega_in_max), seconds, error);
    if (analysis->chain != NULL) {
        chain_set_budget(analysis->chain, &budget);
    }
    for (i = 0; !failed && i < sizeof later / sizeof later[0]; i++) {
        failed = part(analysis, data, later[i], orders, n_orders, &budget, seconds, error);
    }
    if (analysis->chain != NULL) {
        chain_set_budget(analysis->chain, NULL);
    }
    if (failed && budget.spent) {
        snprintf(error, sizeof error, BUDGET_REFUSAL, budget.spent_in);
        failed = ERROR_VALUE;
    }
    if (failed) {
        messages_add(out, "driveline: ", error,
                     ERROR_IS_ARITHMETIC(failed) ? " (a structural parameter is too large or small to analyse)" : "",
                     (const char *)NULL);
    }
}

/* ---- per step ------------------------------------------------------------------------------------ */

/* CriticalSpeedsModel.evaluate: lookups in the analysis at |omega_in|. */
static Failure evaluate(ModelData *data)
{
    const Analysis *analysis = data->cache->derived;
    double speed = fabs(VALUE(omega_in)), whirl[2 * ROTOR_MODEL_WHIRL_MODES], unbalance[3], margin, smallest = 0.0;
    int closest = 0, count = 0, i;
    if (analysis == NULL || analysis->whirl == NULL || analysis->resonance_count == 0 ||
        analysis->unbalance == NULL) { /* the parameter check builds it before every step */
        return FAILURE(ERROR_RUNTIME, "the driveline was not analysed");
    }
    VALUE(omega_crit_1) = analysis->critical[0];
    VALUE(omega_crit_2) = analysis->critical[1];
    VALUE(omega_crit_3) = analysis->critical[2];
    data->int_value[V_critical_speed_count] = analysis->critical_count;
    whirl_table_evaluate(analysis->whirl, speed, whirl);
    VALUE(whirl_forward_1) = whirl[0];
    VALUE(whirl_forward_2) = whirl[1];
    VALUE(whirl_backward_1) = whirl[2];
    VALUE(whirl_backward_2) = whirl[3];
    if (VALUE(omega_crit_1) == 0.0) {
        return FAILURE(ERROR_ZERO_DIVISION, "float division by zero");
    }
    VALUE(speed_ratio) = speed / VALUE(omega_crit_1);
    for (i = 0; i < analysis->resonance_count; i++) { /* np.argmin of |margins|: the first smallest, a NaN first */
        double spin = analysis->resonances[i].spin;
        margin = fabs((speed - spin) / spin);
        if (i == 0 || (!isnan(smallest) && (isnan(margin) || margin < smallest))) {
            closest = i;
            smallest = margin;
        }
        count += margin < VALUE(band);
    }
    margin = (speed - analysis->resonances[closest].spin) / analysis->resonances[closest].spin;
    data->int_value[V_resonance_order] = analysis->resonances[closest].order;
    data->int_value[V_resonance_whirl] = analysis->resonances[closest].whirl;
    VALUE(resonance_speed) = analysis->resonances[closest].spin;
    VALUE(resonance_margin) = margin;
    data->int_value[V_resonance_count] = count;
    data->int_value[V_resonance_warning] = count > 0;
    unbalance_outputs_evaluate(analysis->unbalance, speed, unbalance);
    VALUE(unbalance_response) = unbalance[0];
    VALUE(bearing_force_max) = unbalance[1];
    VALUE(damping_ratio) = unbalance[2];
    return NO_FAILURE;
}

/* The exact derivatives of the outputs in omega_in at the point evaluate has just computed, each that of
 * the lookup that gives the output, times d|omega_in| / d omega_in (1 at omega_in = 0: for a growing
 * omega_in). The critical speeds are the structure's (0); the whirl frequencies are the Campbell
 * table's cubic splines, the derivative of the branch each sorted value comes from; the nearest order
 * resonance keeps its speed (the branch the point is on), its margin moves as 1 / resonance_speed;
 * the response and the bearing force by the response's linear solve differentiated, the damping
 * ratio by the mode table's spline of the nearest mode (unbalance_outputs_slopes). */
static Failure jacobian(const ModelData *data, double partial[])
{
    const Analysis *analysis = data->cache->derived;
    double omega = VALUE(omega_in), sign = omega < 0.0 ? -1.0 : 1.0, speed = fabs(omega);
    double whirl[2 * ROTOR_MODEL_WHIRL_MODES], whirl_slopes[2 * ROTOR_MODEL_WHIRL_MODES], unbalance[3];
    whirl_table_slopes(analysis->whirl, speed, whirl, whirl_slopes);
    PARTIAL(whirl_forward_1, omega_in) = sign * whirl_slopes[0];
    PARTIAL(whirl_forward_2, omega_in) = sign * whirl_slopes[1];
    PARTIAL(whirl_backward_1, omega_in) = sign * whirl_slopes[2];
    PARTIAL(whirl_backward_2, omega_in) = sign * whirl_slopes[3];
    PARTIAL(speed_ratio, omega_in) = sign / VALUE(omega_crit_1);
    PARTIAL(resonance_margin, omega_in) = sign / VALUE(resonance_speed);
    unbalance_outputs_slopes(analysis->unbalance, speed, unbalance);
    PARTIAL(unbalance_response, omega_in) = sign * unbalance[0];
    PARTIAL(bearing_force_max, omega_in) = sign * unbalance[1];
    PARTIAL(damping_ratio, omega_in) = sign * unbalance[2];
    return NO_FAILURE;
}

static Failure start(ModelData *data, double start_time UNUSED)
{
    return evaluate(data);
}

static Failure advance(ModelData *data, double current_time UNUSED, double step_size UNUSED)
{
    return evaluate(data);
}

/* The outputs at any time: the analysis looked up at |omega_in| (Model Exchange; no state). */
static Failure evaluate_now(ModelData *data, double time UNUSED)
{
    return evaluate(data);
}

const ModelHooks model_hooks = {.start = start, .advance = advance, .evaluate = evaluate_now,
                                .extra_parameter_errors = extra_parameter_errors, .free_derived = free_analysis,
                                .jacobian = jacobian};
