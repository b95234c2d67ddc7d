/* Shaft segment elements shared by the transfer-matrix and finite-element models:
 *   elements.c   a ShaftSegment's section constants and finite element, the Krylov functions of its
 *                transfer matrices (driveline/rotor/elements.py; seed Eqs. 16-23); the elements' checks
 */
#ifndef ELEMENTS_H
#define ELEMENTS_H

#include "rotor.h"

/* ShaftSegment.area [m2] */
double segment_area(const RotorSegment *s);
/* ShaftSegment.second_moment: J of seed Eq. (21) [m4] */
double segment_second_moment(const RotorSegment *s);
/* ShaftSegment.shear_coefficient: Cowper's kappa of a hollow circle */
double segment_shear_coefficient(const RotorSegment *s);
/* ShaftSegment.shear_stiffness: kappa G A [N] */
double segment_shear_stiffness(const RotorSegment *s);
/* ShaftSegment.fe_matrices: one element's k, m, g (Hermite, or Timoshenko with shear), length h */
void segment_fe_element(const RotorSegment *s, double h, double k[16], double m[16], double g[16]);
/* elements._betas: beta1^2, beta2^2 of U'''' + a U'' - b U = 0 (seed Eqs. 22-23) */
void element_betas(double a, double b, double *b1sq, double *b2sq);
/* elements._krylov: C0..C3 of y'''' + a y'' - b y = 0 at z */
void element_krylov(double a, double b, double z, double C[4]);
/* elements.beam_field_matrix (seed Eqs. 16-20, corrected) */
void beam_field_matrix(double z, double EI, double c, double a, double b, double H[4][4]);

/* The checks of the elements' __post_init__, with their messages: each returns ERROR_NONE, or
 * ERROR_VALUE (Python's ValueError) with the message in ``error`` (``size`` bytes). */
/* elements._non_negative: ``value`` finite and >= 0 (``name`` in the message) */
ErrorKind element_non_negative(const char *name, double value, char *error, size_t size);
/* ShaftSegment.__post_init__ */
ErrorKind segment_check(const RotorSegment *s, char *error, size_t size);
/* ConcentratedMass.__post_init__ */
ErrorKind mass_check(const RotorMass *m, char *error, size_t size);
/* Bearing.__post_init__ (kyy and cyy resolved: checked again, as kxx and cxx before) */
ErrorKind bearing_check(const RotorBearing *b, char *error, size_t size);
/* Unbalance.__post_init__ */
ErrorKind unbalance_check(const RotorUnbalance *u, char *error, size_t size);
/* Driveline.__post_init__'s node checks: every point element at a node 0..n_segments, a hinge at
 * an inner one */
ErrorKind driveline_check_nodes(const Driveline *d, char *error, size_t size);

#endif
