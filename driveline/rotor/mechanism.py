"""Whether the supports hold a driveline still: a moment-free hinge with too few supports on its
sides leaves the shaft a mechanism, whose rigid-body mode at zero frequency no critical-speed
search sees (a pinned-pinned shaft with a hinge at 0.4 L; free ends, a bearing near each end and
a hinge between).

For the zero-frequency modes the shaft is rigid between its free hinges (bending stiffness 0, or
too small for double precision to resolve the spring's mode: RESOLVED_HINGE_SHARE):
each piece moves in a plane with a translation and a tilt, continuous in displacement at a
hinge. A support fixes the displacement at its node: a bearing stiff in the plane (``kxx`` for
x, ``kyy`` for y), a pinned or clamped end; a clamped end fixes the tilt too. A piece is held
when it has two fixed points at distinct nodes, or a clamped end; a held piece fixes the hinge
it shares with its neighbour. Repeating that until nothing changes finds every held piece: along
a chain of pieces this decides what the rank of the support conditions does, with no tolerance.
"""

from __future__ import annotations

from .driveline import Driveline
from .elements import EndCondition, Hinge

#: A hinge whose bending stiffness k lies below this share of the shaft's EI / L (its stiffest segment's
#: bending stiffness, its overall length) folds as a free one: the mode its spring gives a shaft that
#: is otherwise a mechanism lies so near zero that double precision does not resolve it (on a
#: pinned-pinned 1 m tube, EI = 5.6e4 N.m2, with a hinge at 0.4 m, the finite-element check's
#: frequency of that mode was round-off for k = 1e-9 to 3e-6 N.m/rad, k L / EI 1.8e-14 to 5.3e-11, and
#: the two cores accepted or refused it apart); resolved from 5e-6 N.m/rad (8.9e-11): the rule keeps
#: a margin of two orders of magnitude above that.
RESOLVED_HINGE_SHARE = 1e-8
MECHANISM_HINGE = ("the hinge joints[{index}] at node {node} leaves the shaft a mechanism with a zero-frequency mode: "
                   "too few supports hold the pieces it joins against folding about it (add a bearing, or give the "
                   "hinge a bending_stiffness of at least {least} N.m/rad, " + f"{RESOLVED_HINGE_SHARE:g}"
                   + " EI/L of the shaft: a softer spring's mode lies below what double precision resolves)")
MECHANISM_RIGID = ("the supports leave the shaft free to move as a rigid body, a zero-frequency mode (it needs two "
                   "bearings or supported ends, or a clamped end)")


def _unheld_piece(n_nodes: int, hinges: list[int], points: set[int], clamped: set[int]) -> int | None:
    """The first piece between ``hinges`` (sorted distinct inner nodes) that the fixed ``points``
    and ``clamped`` nodes do not hold, or None."""
    bounds = [0, *hinges, n_nodes - 1]
    pieces = list(zip(bounds[:-1], bounds[1:]))
    held = [False] * len(pieces)
    changed = True
    while changed:
        changed = False
        for p, (a, b) in enumerate(pieces):
            if held[p]:
                continue
            fixed = {k for k in points if a <= k <= b}
            if p > 0 and held[p - 1]:
                fixed.add(a)
            if p + 1 < len(pieces) and held[p + 1]:
                fixed.add(b)
            if len(fixed) >= 2 or any(a <= k <= b for k in clamped):
                held[p] = changed = True
    return next((p for p, h in enumerate(held) if not h), None)


def least_resolved_stiffness(driveline: Driveline) -> float:
    """The bending stiffness [N.m/rad] below which a hinge folds as a free one: RESOLVED_HINGE_SHARE EI / L."""
    return RESOLVED_HINGE_SHARE * max(s.bending_stiffness for s in driveline.segments) / driveline.length


def mechanism_error(driveline: Driveline) -> str | None:
    """Why the supports leave ``driveline`` a mechanism (naming the hinge), or None when they hold it.
    A hinge counts as free below :func:`least_resolved_stiffness`."""
    n_nodes = len(driveline.segments) + 1
    least = least_resolved_stiffness(driveline)
    free = [(i, j.node) for i, j in enumerate(driveline.joints) if isinstance(j, Hinge) and j.bending_stiffness < least]
    hinges = sorted({node for _, node in free})
    ends = ((0, driveline.left), (n_nodes - 1, driveline.right))
    clamped = {node for node, end in ends if end == EndCondition.CLAMPED}
    supported = {node for node, end in ends if end != EndCondition.FREE}
    for stiffness in (lambda b: b.kxx, lambda b: b.k_yy):
        points = supported | {b.node for b in driveline.bearings if stiffness(b) > 0.0}
        piece = _unheld_piece(n_nodes, hinges, points, clamped)
        if piece is None:
            continue
        if not hinges:
            return MECHANISM_RIGID
        node = hinges[piece - 1] if piece > 0 else hinges[0]
        index = next(i for i, at in free if at == node)
        return MECHANISM_HINGE.format(index=index, node=node, least=f"{least:.6g}")
    return None
