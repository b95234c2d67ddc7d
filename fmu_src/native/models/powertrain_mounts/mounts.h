/* The C library of the native PowertrainMounts FMU (port of driveline/mounts/; rigid_body.py, joints.py,
 * system.py, exact_step.py and model.py are in the model file next to this folder):
 *   layout.c     the layouts (layout.py), read by the shared layout reader (lib/toml.h)
 *   dense.c      small dense linear algebra: products, solutions, symmetric eigenvalues, the matrix exponential
 *   halfshaft.c  the halfshafts' geometry on the moving powertrain (halfshaft/geometry.py, halfshafts.py)
 *   halfshaft_outputs.c  the model's halfshaft outputs, their limits at the start and their Jacobian rows (model.py)
 */
#ifndef MOUNTS_H
#define MOUNTS_H

#include <stddef.h>

#include "fmi/fmu_instance.h"
#include "lib/toml.h"

#define MOUNTS_AUGMENTED 24 /* exact_step.augmented: the order of Z h */

/* ---- layout.c ---------------------------------------------------------------------------------- */

typedef struct {
    double position[3], stiffness[3], damping[3], axes[3][3]; /* axes: rows, the mount's axes in vehicle axes */
} Mount;

/* layout.Layout: mass [kg], centre of gravity [m], inertia tensor about it [kg m^2], mounts */
typedef struct {
    double mass, centre[3], inertia[3][3];
    int count;
    Mount mounts[MOUNTS_LAYOUT_MAX_MOUNTS];
} Layout;

/* layout.loads_layout into the Layout ``out`` (a LayoutLoads of layout_file_load) */
ErrorKind loads_layout(const char *text, size_t length, const char *source, void *out, char *error, size_t size);

/* ---- dense.c ----------------------------------------------------------------------------------- */

/* c = a b: (n x m) (m x p) */
void dense_multiply(const double *a, const double *b, double *c, int n, int m, int p);
/* Solves a x = b for ``columns`` right-hand sides (b: n x columns, overwritten by x) by Gaussian
 * elimination with partial pivoting (a overwritten); 0 if a is singular. */
int dense_solve(double *a, double *b, int n, int columns);
/* Cyclic Jacobi rotations of the symmetric ``a`` (n x n): its eigenvalues on the diagonal, the
 * eigenvectors in the columns of ``vectors``. */
void dense_symmetric_eigen(double *a, double *vectors, int n);
/* exp(z) of the MOUNTS_AUGMENTED-order ``z`` (overwritten) into ``out`` by the degree-13 Pade approximant
 * after ``count`` halvings, squared ``count`` times (Higham 2005); 0 without memory or for a singular
 * denominator. */
int dense_exponential(double *z, int count, double *out);

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
/* The geometry outputs' rows: by the states directly and through q'' = ``acceleration``, whose partials are
 * ``by_state`` (6 x 12) and ``by_load`` (6 x MODEL_INPUT_DERIVATIVE_COUNT, the loads in the input map's order) */
Failure halfshafts_partials(const Halfshaft shafts[2], const ModelData *data, const double acceleration[6],
                            const double *by_state, const double *by_load, double partial[]);

#endif
