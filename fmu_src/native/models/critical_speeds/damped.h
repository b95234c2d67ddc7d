/* The damped finite-element model (damped.c) as unbalance_outputs.c uses it: the rotor's band matrices,
 * and the damped modes tabulated over the speed. Internal to the rotor library (rotor.h is its interface). */
#ifndef DAMPED_H
#define DAMPED_H

#include "rotor.h"

#include "linalg.h"

/* ---- damped.DampedRotor ---------------------------------------------------------------------- */
typedef struct {
    FeModel fe;                /* fem.assemble_damped's mesh and real K, M, G (bearings left out) */
    int n, doubled, size;      /* p unknowns; [p, q] when doubled; size = n or 2 n */
    int conservative;          /* no damping, symmetric bearing stiffness: imaginary eigenvalues */
    cplx *K, *C, *G;           /* K2, C2, Gv (size x size); NULL once the rotor only solves */
    Band band;                 /* the interleaved order [p0, q0, p1, q1, ...] */
    cplx *banded[4];           /* k, c, g, m in band storage */
    int *order;                /* size: the unknown at each row of the interleaved order */
    int n_translations, *translations;
    int n_bearings, *bearing_rows; /* per bearing, -1 on a pinned or clamped end */
    cplx *coefficients;        /* per bearing: k_a, k_b, c_a, c_b */
    double scale;              /* DampedRotor._scale */
} Rotor;

/* DampedRotor.__init__ (with fem.assemble_damped) with ``counts`` beam elements per segment; ERROR_NONE,
 * or the failure's kind with the message */
ErrorKind rotor_init(Rotor *rotor, const Driveline *d, const int *counts, char *error, size_t size);
void rotor_free(Rotor *rotor);
/* The mode table of UnbalanceOutputs.build on the model of ``counts`` elements per segment: at each of the
 * DAMPING_POINTS ``spins``, the damped frequencies of the first DAMPED_MODES unbalance-excited modes, then their
 * damping ratios (SEARCH_LIMIT and 0 for missing ones), into ``table``; ERROR_NONE, or the failure's kind with
 * the message */
ErrorKind mode_table(const Driveline *d, const int *counts, const double *spins, double *table, char *error,
                     size_t size);

#endif
