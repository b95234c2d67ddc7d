/* The rotor library of the native CriticalSpeeds FMU: a C port of driveline/rotor/ (the Python core
 * stays the readable reference; every function names the Python function it ports).
 *
 * One header for the library's modules, one module per concern:
 *   layout.c     the driveline (segments, point elements, unbalances) of a layout read by the
 *                TOML-subset reader (toml.h), checked with the Python loader's messages and work
 *                limits; the one-piece tube
 *   pyrepr.c     Python's repr() of the values the messages show
 *   mechanism.c  whether the supports hold the shaft still (no zero-frequency mechanism mode)
 *   transfer.c   element transfer matrices and the scaled frequency determinant (seed Eqs. 16-31)
 *   roots.c      the batched bracketing root search and the searches along lines (w, spin)
 *   spline.c     not-a-knot cubic splines (scipy's CubicSpline default)
 *   campbell.c   whirl branches over the speed and the Campbell table
 *   fem.c        finite-element model: the plausibility check's natural frequencies
 *   damped.c     damped finite-element model: damped modes, unbalance response, bearing forces
 * Every function that can fail returns 0 on success, or -1 with a message in ``error`` (``size``
 * bytes, always terminated) worded as the Python core's exception text. No global state.
 */
#ifndef ROTOR_H
#define ROTOR_H

#include <stddef.h>

#include "../python_numbers.h"

/* ---- limits and constants (the modules of driveline/rotor/) -------------------------------- */
#define ROTOR_SEARCH_LIMIT 1.0e5     /* driveline.SEARCH_LIMIT [rad/s] */
#define ROTOR_EXCITED_SHARE 0.01     /* driveline.EXCITED_SHARE */
#define LAYOUT_MAX_FILE_BYTES 65536  /* loader.MAX_FILE_BYTES */
#define LAYOUT_MAX_NESTING 16        /* loader.MAX_NESTING */
#define LAYOUT_MAX_SEGMENTS 100      /* loader.MAX_SEGMENTS */
#define LAYOUT_MAX_POINT_ELEMENTS 202 /* loader.MAX_POINT_ELEMENTS */

/* ---- the driveline (elements.py, driveline.py) --------------------------------------------- */
typedef enum { END_FREE, END_PINNED, END_CLAMPED } EndCondition;

/* elements.ShaftSegment */
typedef struct {
    double length, outer_diameter, inner_diameter, youngs_modulus, density, poisson_ratio;
    int rotary_inertia, gyroscopic, shear;
} RotorSegment;

/* elements.ConcentratedMass */
typedef struct {
    int node;
    double mass, polar_inertia, diametral_inertia;
} RotorMass;

/* elements.Bearing, kyy and cyy resolved (kyy = kxx, cyy = cxx where the Python one has None) */
typedef struct {
    int node;
    double kxx, kyy, cxx, cyy, kxy, kyx, cxy, cyx;
} RotorBearing;

/* elements.Hinge */
typedef struct {
    int node;
    double bending_stiffness;
} RotorHinge;

/* elements.Unbalance */
typedef struct {
    double position, amount, phase;
} RotorUnbalance;

/* driveline.Driveline: node k is the start of segment k. At a node the point elements act in the
 * order masses, bearings, hinges, each kind in the order given (Driveline.point_elements). The
 * arrays are owned (driveline_free). */
typedef struct {
    int n_segments, n_masses, n_bearings, n_hinges, n_unbalances;
    RotorSegment *segments;
    RotorMass *masses;
    RotorBearing *bearings;
    RotorHinge *hinges;
    RotorUnbalance *unbalances;
    EndCondition left, right;
} Driveline;

/* mechanism.mechanism_error: MECHANISM_NONE when the supports hold the driveline still,
 * MECHANISM_HINGE_FOLDS with the index (in ``hinges``) and node of the hinge that folds, or
 * MECHANISM_RIGID_BODY when the whole shaft moves rigidly; -1: out of memory. */
enum { MECHANISM_NONE = 0, MECHANISM_HINGE_FOLDS = 1, MECHANISM_RIGID_BODY = 2 };
int driveline_mechanism(const Driveline *driveline, int *hinge_index, int *hinge_node);

/* The parameters of loader.one_piece_shaft (the FMU's one-piece tube). */
typedef struct {
    double L_shaft, D_outer, D_inner, E, density, m_joint, Jp_joint, Jd_joint, k_bearing, c_bearing;
    int shear;
} OnePieceShaft;

/* ---- layout.c ------------------------------------------------------------------------------ */
void driveline_free(Driveline *driveline);
/* loader.one_piece_shaft */
int driveline_one_piece(const OnePieceShaft *shaft, Driveline *out, char *error, size_t size);
/* model.build_driveline for a non-empty ``layout``: a file path ending in ".toml" (any case; relative
 * to the working directory; messages name it by its absolute path, as pathlib's absolute()) or the
 * name of a description shipped in ``resources`` (the FMU's resources folder: loader.example_path). */
int driveline_from_layout(const char *layout, const char *resources, Driveline *out, char *error, size_t size);
/* loader.loads_driveline: TOML text (``length`` bytes, not necessarily terminated) from ``source``. */
int driveline_from_text(const char *text, size_t length, const char *source, Driveline *out, char *error,
                        size_t size);
/* Driveline.length (math.fsum of the segment lengths) */
double driveline_length(const Driveline *driveline);
/* Driveline.is_isotropic: every bearing has kxx == kyy */
int driveline_isotropic(const Driveline *driveline);

/* ---- pyrepr.c -------------------------------------------------------------------------------- */
/* repr() of a Python str holding the UTF-8 ``text`` cut to its first ``max_chars`` code points (0: all). */
void python_str_repr(const char *text, size_t max_chars, char *out, size_t size);
/* The same for ``length`` bytes (the text may hold NUL characters). */
void python_str_repr_n(const char *text, size_t length, size_t max_chars, char *out, size_t size);
/* Appends ``count`` bytes to the text of ``*used`` bytes in ``out`` (``size`` bytes), cut to fit,
 * always terminated; ``*used`` grows by what was written. */
void text_append(char *out, size_t size, size_t *used, const char *bytes, size_t count);

/* ---- transfer.c: the scaled frequency determinant (transfer.py) ---------------------------- */
typedef struct Chain Chain; /* transfer.Chain of a driveline (it keeps no pointer to it) */
/* transfer.Chain.build; fails with elements.Bearing._undamped_stiffness's message on cross-coupling */
Chain *chain_new(const Driveline *driveline, char *error, size_t size);
void chain_free(Chain *chain);
int chain_isotropic(const Chain *chain);
/* Driveline._kappa: sum of L (m'/EI)^(1/4) */
double chain_kappa(const Chain *chain);
/* Driveline._grid's ``extra``: the distinct freedoms (translation, tilt, hinge) of each node's point
 * elements, summed over the nodes */
int chain_freedoms(const Chain *chain);
/* transfer.determinant at ``n`` points (w[i], spin[i]); signed w for an isotropic chain. */
void chain_determinant(const Chain *chain, size_t n, const double *w, const double *spin, double *f);
/* transfer.mode_shape(chain, w, spin, 4).forward_fraction */
double chain_forward_fraction(const Chain *chain, double w, double spin);

/* ---- roots.c: searches (roots.py and Driveline's searches) --------------------------------- */
/* A line (w, spin) = (w x, s x + o) of Driveline._line_roots, or a case (r, s, o) of _roots_by_whirl. */
typedef struct {
    double w, s, o;
} RotorLine;

/* Roots x of one line or one whirl sense, ascending (owned: rotor_roots_free). */
typedef struct {
    int count;
    double *x;
} RotorRoots;

void rotor_roots_free(RotorRoots *roots, int m);
/* Driveline._line_roots: ``x_max`` > 0: every root up to x_max (``coarse`` per line, NULL: none
 * coarse); x_max = 0: the first ``n`` below ``limit``. ``roots`` has ``m`` entries. */
int rotor_line_roots(const Chain *chain, const RotorLine *lines, int m, int n, double x_max, double limit,
                     const unsigned char *coarse, RotorRoots *roots, char *error, size_t size);
/* Driveline._roots_by_whirl for both senses: ``forward`` and ``backward`` have ``m`` entries;
 * n = 0 means all up to x_max. */
int rotor_roots_by_whirl(const Chain *chain, const RotorLine *cases, int m, int n, double x_max, double limit,
                         RotorRoots *forward, RotorRoots *backward, char *error, size_t size);

/* driveline.OrderResonance; whirl 1 forward, -1 backward */
typedef struct {
    int order, whirl;
    double spin;
} OrderResonance;

#define WHIRL_FORWARD 1
#define WHIRL_BACKWARD 2
/* Driveline.order_resonances(orders, whirls (WHIRL_* bits, forward first), n (0: all up to
 * spin_max), spin_max (0: none), limit), sorted by (spin, order); *found is owned (free()). */
int rotor_order_resonances(const Chain *chain, const int *orders, int n_orders, int whirls, int n, double spin_max,
                           double limit, OrderResonance **found, int *count, char *error, size_t size);
/* Driveline.critical_speeds(n) (forward: unbalance_critical_speeds); ``spins`` holds n. */
int rotor_critical_speeds(const Chain *chain, int n, double *spins, int *count, char *error, size_t size);

/* ---- spline.c: scipy.interpolate.CubicSpline(x, y) (not-a-knot), y of shape (n, m) -------- */
typedef struct {
    int n, m;
    double *x;
    double *c; /* (n - 1) intervals x 4 powers x m columns */
} CubicSpline;

int cubic_spline_build(CubicSpline *spline, int n, const double *x, int m, const double *y);
/* All m columns at ``x`` (extrapolated beyond the ends, as scipy's). */
void cubic_spline_evaluate(const CubicSpline *spline, double x, double *out);
/* Column ``column`` alone of cubic_spline_evaluate. */
double cubic_spline_value(const CubicSpline *spline, double x, int column);
void cubic_spline_free(CubicSpline *spline);

/* ---- campbell.c: model.whirl_table (campbell.whirl_branches + WhirlTable) ------------------ */
typedef struct WhirlTable WhirlTable;
/* The first ``n_modes`` forward and backward whirl frequencies over ``points`` equal speeds on
 * [0, omega_max], refined where a branch bends; missing values read as ROTOR_SEARCH_LIMIT. */
WhirlTable *whirl_table_new(const Chain *chain, double omega_max, int points, int n_modes, char *error, size_t size);
/* WhirlTable.__call__: forward_1..n, backward_1..n at ``speed`` */
void whirl_table_evaluate(const WhirlTable *table, double speed, double *out);
/* The speeds the splines pass through (whirl_branches' knots: ``points`` and those added). */
int whirl_table_knots(const WhirlTable *table);
void whirl_table_free(WhirlTable *table);

/* ---- fem.c, damped.c: finite elements ------------------------------------------------------ */
/* fem.Mesh with its matrices (Mesh.matrices restricted to Mesh.kept), shared by fem.c and damped.c */
typedef struct {
    int n_dof, n_kept;   /* all dofs; those the end conditions leave */
    int *index;          /* n_dof: the row of a dof, -1 where an end condition fixes it */
    int n_elements;      /* beam elements */
    int *elements;       /* 4 per beam element: its dofs [U1, psi1, U2, psi2] */
    double *z;           /* n_elements + 1 axial positions of the beam nodes */
    int *node_u;         /* n_segments + 1: the translation dof of each driveline node */
    double *K, *M, *G;   /* n_kept x n_kept, row-major, end conditions applied */
} FeModel;

/* fem.elements_by_length: ``counts`` has n_segments entries */
void fe_elements_by_length(const Driveline *driveline, int most, int *counts);
/* fem.mesh(driveline, counts, undamped = with_bearings) and its kept K, M, G (fem.assemble) */
int fe_model_build(const Driveline *driveline, const int *counts, int with_bearings, FeModel *model, char *error,
                   size_t size);
void fe_model_free(FeModel *model);

/* model.natural_frequencies: sqrt|eigenvalues| of the undamped FE model with ``elements``
 * elements per segment (both planes for anisotropic bearings: the kxx plane first, each plane
 * ascending); *frequencies is owned (free()). */
int fe_natural_frequencies(const Driveline *driveline, int elements, double **frequencies, int *count, char *error,
                           size_t size);

typedef struct UnbalanceOutputs UnbalanceOutputs;
/* unbalance_outputs.UnbalanceOutputs.build; the mode table from the dense eigensolver up to DENSE_SIZE
 * first-order unknowns, above from shift-invert Arnoldi (as Python) on one banded factorisation per
 * speed: O(unknowns (band^2 + vectors^2)) with at most 400 Krylov vectors, an error if the wanted
 * eigenvalues have not converged by then */
UnbalanceOutputs *unbalance_outputs_new(const Driveline *driveline, const RotorUnbalance *unbalances, int n_unbalances,
                                        double response_fraction, double omega_max, char *error, size_t size);
/* UnbalanceOutputs.evaluate: out = response, largest bearing force, damping ratio (an exactly singular
 * dynamic stiffness: infinite response and force). It allocates nothing: the object holds the
 * solve's work arrays, so one object is evaluated by one caller at a time. */
void unbalance_outputs_evaluate(const UnbalanceOutputs *outputs, double speed, double out[3]);
/* UnbalanceOutputs.modes(speed): the tabulated damped frequencies of the DAMPED_MODES (4) modes, then
 * their damping ratios (out has 8 places) */
void unbalance_outputs_modes(const UnbalanceOutputs *outputs, double speed, double out[8]);
void unbalance_outputs_free(UnbalanceOutputs *outputs);

#endif
