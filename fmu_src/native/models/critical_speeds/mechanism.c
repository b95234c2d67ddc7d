/* Whether the supports hold a driveline still (mechanism.py): a moment-free hinge (or one softer than
 * RESOLVED_HINGE_SHARE EI / L, whose mode double precision does not resolve) with too few
 * supports on its sides leaves the shaft a mechanism with a zero-frequency mode. The shaft is rigid
 * between its free hinges; a piece is held by two fixed points at distinct nodes or a clamped end,
 * and a held piece fixes the hinge it shares with its neighbour, repeated until nothing changes. */
#include <stdlib.h>

#include "elements.h"
#include "rotor.h"

/* mechanism._unheld_piece for one plane (``plane`` 0: kxx, 1: kyy): the first piece the supports
 * do not hold, or -1; ``hinges``: the ``n_hinges`` sorted distinct free-hinge nodes. */
static int unheld_piece(const Driveline *d, int plane, const int *hinges, int n_hinges, int *held)
{
    int n_pieces = n_hinges + 1, last = d->n_segments, changed = 1, p, i;
    for (p = 0; p < n_pieces; p++) {
        held[p] = 0;
    }
    while (changed) {
        changed = 0;
        for (p = 0; p < n_pieces; p++) {
            int a = p > 0 ? hinges[p - 1] : 0, b = p < n_hinges ? hinges[p] : last, first = -1, distinct = 0;
            int clamped = (d->left == END_CLAMPED && a == 0) || (d->right == END_CLAMPED && b == last);
            if (held[p]) {
                continue;
            }
            /* fixed nodes in [a, b]: supported ends, stiff bearings, hinges shared with held pieces */
#define FIX(node)                                                                                                      \
    do {                                                                                                               \
        if (distinct == 0) {                                                                                           \
            first = (node);                                                                                            \
            distinct = 1;                                                                                              \
        } else if ((node) != first) {                                                                                  \
            distinct = 2;                                                                                              \
        }                                                                                                              \
    } while (0)
            if (d->left != END_FREE && a == 0) {
                FIX(0);
            }
            if (d->right != END_FREE && b == last) {
                FIX(last);
            }
            for (i = 0; i < d->n_bearings; i++) {
                const RotorBearing *bearing = &d->bearings[i];
                if (a <= bearing->node && bearing->node <= b && (plane == 0 ? bearing->kxx : bearing->kyy) > 0.0) {
                    FIX(bearing->node);
                }
            }
            if (p > 0 && held[p - 1]) {
                FIX(a);
            }
            if (p + 1 < n_pieces && held[p + 1]) {
                FIX(b);
            }
#undef FIX
            if (distinct >= 2 || clamped) {
                held[p] = changed = 1;
            }
        }
    }
    for (p = 0; p < n_pieces; p++) {
        if (!held[p]) {
            return p;
        }
    }
    return -1;
}

double driveline_least_resolved_stiffness(const Driveline *driveline)
{
    double stiffest = 0.0;
    int i;
    for (i = 0; i < driveline->n_segments; i++) {
        const RotorSegment *s = &driveline->segments[i];
        double EI = s->youngs_modulus * segment_second_moment(s);
        stiffest = i == 0 || EI > stiffest ? EI : stiffest; /* Python's max: the first of equal ones */
    }
    return ROTOR_MECHANISM_RESOLVED_HINGE_SHARE * stiffest / driveline_length(driveline);
}

int driveline_mechanism(const Driveline *driveline, int *hinge_index, int *hinge_node)
{
    int *hinges, *held, n_hinges = 0, i, k, plane, found = MECHANISM_NONE;
    double least = driveline_least_resolved_stiffness(driveline);
    hinges = malloc(((size_t)driveline->n_hinges + 1) * sizeof *hinges);
    held = malloc(((size_t)driveline->n_hinges + 1) * sizeof *held);
    if (hinges == NULL || held == NULL) {
        free(hinges);
        free(held);
        return -1;
    }
    for (i = 0; i < driveline->n_hinges; i++) { /* the sorted distinct nodes of the free hinges */
        int node = driveline->hinges[i].node, at = 0;
        if (!(driveline->hinges[i].bending_stiffness < least)) {
            continue;
        }
        while (at < n_hinges && hinges[at] < node) {
            at++;
        }
        if (at < n_hinges && hinges[at] == node) {
            continue;
        }
        for (k = n_hinges; k > at; k--) {
            hinges[k] = hinges[k - 1];
        }
        hinges[at] = node;
        n_hinges++;
    }
    for (plane = 0; plane < 2 && found == MECHANISM_NONE; plane++) {
        int piece = unheld_piece(driveline, plane, hinges, n_hinges, held);
        if (piece < 0) {
            continue;
        }
        if (n_hinges == 0) {
            found = MECHANISM_RIGID_BODY;
            break;
        }
        *hinge_node = piece > 0 ? hinges[piece - 1] : hinges[0];
        for (i = 0; i < driveline->n_hinges; i++) {
            if (driveline->hinges[i].node == *hinge_node && driveline->hinges[i].bending_stiffness < least) {
                *hinge_index = i;
                break;
            }
        }
        found = MECHANISM_HINGE_FOLDS;
    }
    free(hinges);
    free(held);
    return found;
}
