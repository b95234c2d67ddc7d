/* The C library of the native PowertrainMounts FMU (port of driveline/mounts/; rigid_body.py, joints.py,
 * system.py, exact_step.py and model.py are in the model file next to this folder):
 *   layout.c          the layouts (layout.py), read by the shared layout reader (lib/toml.h)
 *   characteristic.c  a mount's force-deflection characteristic along an axis (characteristic.py)
 *   rubber.c          the Maxwell branches' fit to a constant loss factor (rubber.py)
 *   forces.c          the mounts' forces, the static equilibrium, the branches' map (forces.py)
 *   exact_step.c      the exact step where the mounts are linear (exact_step.py)
 *   implicit_step.c   the energy-exact implicit step of progressive mounts (implicit_step.py)
 *   dense.c           small dense linear algebra: products, solutions, symmetric eigenvalues, the matrix exponential
 *   halfshaft.c       the halfshafts' geometry on the moving powertrain (halfshaft/geometry.py, halfshafts.py)
 *   halfshaft_outputs.c  the model's halfshaft outputs, their limits at the start and their Jacobian rows (model.py)
 */
#ifndef MOUNTS_H
#define MOUNTS_H

#include <stddef.h>

#include "fmi/fmu_instance.h"
#include "lib/toml.h"

/* The Maxwell branches' forces of a layout at most (a mount, an axis, a branch each): the model's internal state */
#define MOUNTS_MAX_BRANCHES (MOUNTS_LAYOUT_MAX_MOUNTS * 3 * MOUNTS_RUBBER_BRANCHES)
/* The state (q, q', z) at most, and exact_step.augmented's Z h at most (the state and the load's 12) */
#define MOUNTS_MAX_STATE (12 + MOUNTS_MAX_BRANCHES)
#define MOUNTS_MAX_AUGMENTED (MOUNTS_MAX_STATE + 12)

/* ---- layout.c ---------------------------------------------------------------------------------- */

/* layout.Mount: axes (rows, the mount's axes in vehicle axes), linear rate and viscous damping along each, a
 * snubber along each (stop_rate 0: none), the Maxwell branches' weights (``branch_count`` 0: none) */
typedef struct {
    double position[3], stiffness[3], damping[3], axes[3][3];
    double gap[3], stop_rate[3], stop_blend;
    int branch_count;
    double branches[MOUNTS_RUBBER_BRANCHES];
} Mount;

/* layout.Layout: mass [kg], centre of gravity [m], inertia tensor about it [kg m^2], mounts */
typedef struct {
    double mass, centre[3], inertia[3][3];
    int count;
    Mount mounts[MOUNTS_LAYOUT_MAX_MOUNTS];
} Layout;

/* layout.loads_layout into the Layout ``out`` (a LayoutLoads of layout_file_load) */
ErrorKind loads_layout(const char *text, size_t length, const char *source, void *out, char *error, size_t size);

/* Mount.progressive: a stop makes the characteristic nonlinear */
int mount_progressive(const Mount *m);

/* ---- characteristic.c -------------------------------------------------------------------------- */

/* F(d), F'(d) and V(d) along axis k of mount ``m`` (characteristic.force, tangent, energy) */
double characteristic_force(const Mount *m, int k, double d);
double characteristic_tangent(const Mount *m, int k, double d);
double characteristic_energy(const Mount *m, int k, double d);
/* characteristic.mean_force along the mount's three axes */
void characteristic_mean_force(const Mount *m, const double d0[3], const double d1[3], double mean[3],
                               double slope[3]);

/* ---- rubber.c ---------------------------------------------------------------------------------- */

/* rubber.Fit */
typedef struct {
    double weights[MOUNTS_RUBBER_BRANCHES], loss_error, ratio_error;
} RubberFit;

/* tau_j = 1 / (2 pi f_j) [s] */
double rubber_relaxation_time(int j);
/* rubber.fit_branches */
void rubber_fit(double loss_factor, double dynamic_ratio, RubberFit *fit);
/* rubber.fit_error: 1 with the message naming the mount ``where``, else 0 */
int rubber_fit_error(const char *where, const RubberFit *fit, double loss_factor, double dynamic_ratio, char *error,
                     size_t size);

/* ---- forces.c --------------------------------------------------------------------------------- */

/* forces.BranchMap: a row per branch (mount, then axis, then branch): the deflection rate it sees from q',
 * its gain w_j F'(d_op) [N/m], its relaxation time [s], its slot among Model Exchange's branch states
 * ((3 mount + axis) MOUNTS_RUBBER_BRANCHES + branch) */
typedef struct {
    int count;
    double rows[MOUNTS_MAX_BRANCHES][6], gains[MOUNTS_MAX_BRANCHES], times[MOUNTS_MAX_BRANCHES];
    int slots[MOUNTS_MAX_BRANCHES];
} Branches;

/* MAX_NEWTON as text, for the messages */
#define MOUNTS_TEXT_(x) #x
#define MOUNTS_TEXT(x) MOUNTS_TEXT_(x)
#define MOUNTS_NEWTON_TEXT MOUNTS_TEXT(MOUNTS_FORCES_MAX_NEWTON)

/* Mount n's elastic force along its axes at q (from the unloaded mounts) */
void forces_elastic(const Layout *layout, const double maps[][3][6], int n, const double q[6], double out[3]);
/* sum_n T_n^T A_n^T forces[n]: the generalised force of each mount's ``forces`` along its axes */
void forces_generalised(const Layout *layout, const double maps[][3][6], const double forces[][3], double out[6]);
/* forces.elastic_load, tangent_stiffness, elastic_energy, mean_elastic_load (its Jacobian left out when
 * ``jacobian`` is NULL) */
void forces_elastic_load(const Layout *layout, const double maps[][3][6], const double q[6], double out[6]);
void forces_tangent_stiffness(const Layout *layout, const double maps[][3][6], const double q[6], double out[6][6]);
double forces_elastic_energy(const Layout *layout, const double maps[][3][6], const double q[6]);
void forces_mean_elastic_load(const Layout *layout, const double maps[][3][6], const double q0[6], const double q1[6],
                              double load[6], double jacobian[6][6]);
/* forces.equilibrium: Q with elastic_load(Q) = load, Newton from the linear rates' solution; ERROR_NONE or the
 * failure's kind with its message */
ErrorKind forces_equilibrium(const Layout *layout, const double maps[][3][6], const double load[6],
                             const double linear_stiffness[6][6], double q[6], const char **message);
/* BranchMap of the layout at the operating point Q ``operating``; the branches' count */
int forces_branch_map(const Layout *layout, const double maps[][3][6], const double operating[6], Branches *out);
/* BranchMap.stiffness: the branches' storage and loss stiffness at ``frequency`` [Hz], the storage's w dK_s/dw */
void forces_branch_stiffness(const Branches *b, double frequency, double storage[6][6], double loss[6][6],
                             double slope[6][6]);

/* ---- exact_step.c ------------------------------------------------------------------------------ */

/* exact_step.Propagator of the state's ``n`` numbers */
typedef struct {
    double h;
    int n;
    double phi[MOUNTS_MAX_STATE][MOUNTS_MAX_STATE], gamma0[MOUNTS_MAX_STATE][6], gamma1[MOUNTS_MAX_STATE][6];
} Propagator;

/* exact_step.state_matrices: A (n x n) and B (n x 6), n = 12 + the branches; 0 for a singular mass matrix */
int exact_state_matrices(double mass[6][6], double stiffness[6][6], double damping[6][6],
                         const Branches *branches, double (*a)[MOUNTS_MAX_STATE], double (*b)[6]);
/* exact_step.work_error and Propagator.build; 0 with the message in ``failure`` */
int exact_propagator(const double (*a)[MOUNTS_MAX_STATE], const double (*b)[6], int n, double h, Propagator *p,
                     char *failure, size_t size);
/* Propagator.step */
void exact_step(const Propagator *p, const double *state, const double f0[6], const double f1[6], double *next);

/* ---- implicit_step.c --------------------------------------------------------------------------- */

/* What implicit_step needs of the system */
typedef struct {
    const Layout *layout;
    const double (*maps)[3][6];
    const double (*mass)[6], (*damping)[6];
    const Branches *branches;
    const double *weight, *weight_sag;
} StepSystem;

/* implicit_step.StepMatrices: what the steps of one size h take of h and the parameters alone, the branches'
 * z1 = keep z0 + gain (R dq), ``resistance`` C / h + R^T diag(gain / 2) R and the Jacobian's linear part
 * ``jacobian`` 2 M / h^2 + resistance */
typedef struct {
    double h, keep[MOUNTS_MAX_BRANCHES], gain[MOUNTS_MAX_BRANCHES], resistance[6][6], jacobian[6][6];
} StepMatrices;

/* StepMatrices.of */
void implicit_matrices(const StepSystem *s, double h, StepMatrices *out);
/* implicit_step.implicit_step: ``next`` (12 + branches) after a step of m->h from ``state`` under f0 + f1 tau;
 * ERROR_NONE or ERROR_ARITHMETIC with its message */
ErrorKind implicit_step(const StepSystem *s, const StepMatrices *m, const double *state, const double f0[6],
                        const double f1[6], double *next, const char **message);

/* ---- dense.c ----------------------------------------------------------------------------------- */

/* max |v_i| of the ``n`` numbers of ``v`` */
double dense_largest(const double *v, int n);
/* c = a b: (n x m) (m x p) */
void dense_multiply(const double *a, const double *b, double *c, int n, int m, int p);
/* Solves a x = b for ``columns`` right-hand sides (b: n x columns, overwritten by x) by Gaussian
 * elimination with partial pivoting (a overwritten); 0 if a is singular. */
int dense_solve(double *a, double *b, int n, int columns);
/* dense_solve in two parts: P a = L U in place (``pivots``: n), 0 if a is singular; then x for ``columns``
 * right-hand sides b (overwritten), as many times as needed (the same numbers as dense_solve) */
int dense_factor(double *a, int *pivots, int n);
void dense_substitute(const double *lu, const int *pivots, double *b, int n, int columns);
/* Cyclic Jacobi rotations of the symmetric ``a`` (n x n): its eigenvalues on the diagonal, the
 * eigenvectors in the columns of ``vectors``. */
void dense_symmetric_eigen(double *a, double *vectors, int n);
/* exp(z) of the ``n``-order ``z`` (overwritten) into ``out`` by the degree-13 Pade approximant after ``count``
 * halvings, squared ``count`` times (Higham 2005); 0 without memory or for a singular denominator. */
int dense_exponential(double *z, int n, int count, double *out);

/* ---- halfshaft.c -------------------------------------------------------------------------------- */

#define HALFSHAFT_VALUES 9 /* halfshafts.GEOMETRY: beta, its rates, psi, its rates, the plunge, its rates */
#define HALFSHAFT_MOTION 18 /* q, q', q'' */
#define HALFSHAFT_JET 9     /* a, a', a'': the wheel centre in the housing frame and its rates */

/* halfshafts.Halfshaft: the housing's design frame (columns X', Y', Z') and centre O, the wheel centre W, the
 * shaft's length, T(W) and the design geometry (in the order of HALFSHAFT_VALUES) */
typedef struct {
    double frame[3][3], centre[3], wheel[3], length, wheel_map[3][6], design[HALFSHAFT_VALUES];
} Halfshaft;

/* Halfshaft.of: W from the design bend, plane angle and plunge, T(W) about the centre of gravity; ``frame`` the
 * joint's frame by rows (columns X', Y', Z') */
void halfshaft_place(Halfshaft *shaft, const double *frame, const double centre[3], const double gravity[3],
                     double length, double beta, double psi, double plunge);
/* Halfshaft.geometry: the values and, unless ``partial`` is NULL, their partial derivatives by (q, q', q''); 0
 * when the wheel centre lies beyond the shaft's reach from the housing's axis, its distance in ``reach`` */
int halfshaft_geometry(const Halfshaft *shaft, const double q[6], const double velocity[6],
                       const double acceleration[6], double values[HALFSHAFT_VALUES],
                       double partial[HALFSHAFT_VALUES][HALFSHAFT_MOTION], double *reach);

/* ---- halfshaft_outputs.c --------------------------------------------------------------------------- */

extern const char *const mounts_sides[2]; /* spec.SIDES */

/* Each side's Halfshaft.of from its design parameters; ``centres`` 2 x 3, ``frames`` 2 x 3 x 3 (rows) */
void halfshafts_place(Halfshaft shafts[2], const ModelData *data, const double *centres, const double *frames,
                      const double gravity[3]);
/* _show_halfshafts at the motion ``data`` shows (its states and accelerations); a failure's message in ``failure``
 * (FMU_MESSAGE_SIZE) */
Failure halfshafts_show(const Halfshaft shafts[2], ModelData *data, char *failure);
/* _limit_error of each side at the start, the bend and the plunge shown against the joints' limits */
Failure halfshafts_limits(const ModelData *data, char *failure);
/* The geometry outputs' rows: by the states directly and through q'', whose rows ``partial`` holds already (the
 * accelerations' partial derivatives by the states and the inputs), at the motion ``data`` shows */
Failure halfshafts_partials(const Halfshaft shafts[2], const ModelData *data, double partial[]);

#endif
