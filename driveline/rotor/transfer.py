"""Overall transfer and the scaled frequency determinant (seed Eqs. 5-8, 28-31).

Instead of multiplying the full 4x4 matrices (seed Eq. 6) and taking the 2x2 minor
``p31 p42 - p32 p41`` (seed Eq. 30 for free-free ends), the two columns of
``P B_L`` (``B_L`` selects the unknown left-end components) are propagated through
the chain and re-orthonormalised after every short piece (``Y_k R_k = H Y_{k-1}``,
Gram-Schmidt with a positive diagonal). The classical determinant is then::

    det(C_R P B_L) = det(C_R Y_N) * prod(det R_k)

with the product kept as a sum of logarithms, so nothing overflows and no digits
are lost to the ``cosh(beta1 l)`` growth that ruins the plain product at high
frequency. The returned value divides out the smooth factor ``exp(sum beta1 l)``;
it has exactly the zeros and signs of the classical determinant and, being an
entire function of ``w`` times a smooth positive factor, no poles. Segments are
cut into pieces with ``beta1 l <= 2``; this is exact (``H(l) = H(l/p)^p``), not a
mesh.

For anisotropic bearings the forward (``a``) and backward (``b``) circular
components ``u = a exp(i w t) + b exp(-i w t)`` are carried together in an 8x8
real state ``[s_a, s_b]`` (``w > 0``) with four propagated columns; every element
then contributes its ``transfer_matrix_pair`` instead of its ``transfer_matrix``.
The determinant and the mode shape run the same propagation (:func:`_propagate`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import budget
from .elements import EndCondition, PointElement, ShaftSegment

FloatArray = NDArray[np.float64]

#: Largest ``beta1 * piece_length`` per propagation step (growth ``e**2`` per step).
MAX_PIECE_PHASE = 2.0
#: Bound of the accumulated log scale put back into the determinant (exp stays finite).
LOG_SCALE_CLIP = 700.0
#: The relative rounding of a double.
EPS = float(np.finfo(float).eps)


@dataclass(frozen=True)
class Chain:
    """The elements in propagation order: node 0, segment 0, node 1, ..., node N.

    ``points[k]`` holds the point elements at node ``k`` in the order given.
    """

    segments: tuple[ShaftSegment, ...]
    points: tuple[tuple[PointElement, ...], ...]
    left: EndCondition
    right: EndCondition
    isotropic: bool
    # Non-dimensional scaling of the state: [U/L0, psi, M L0/EI0, V L0^2/EI0].
    scale: FloatArray = field(repr=False)

    @classmethod
    def build(
        cls, segments: Sequence[ShaftSegment], points: Sequence[PointElement], left: EndCondition, right: EndCondition
    ) -> Chain:
        at_node: list[list[PointElement]] = [[] for _ in range(len(segments) + 1)]
        for element in points:
            at_node[element.node].append(element)
        L0 = sum(s.length for s in segments) / len(segments)
        EI0 = segments[0].bending_stiffness
        scale = np.array([1.0 / L0, 1.0, L0 / EI0, L0 * L0 / EI0])
        isotropic = all(element.isotropic for element in points)
        return cls(tuple(segments), tuple(map(tuple, at_node)), left, right, isotropic, scale)

    @property
    def stations(self) -> int:
        """Nodes and point elements: the work model's stations, the steps of a propagation besides the
        segments' pieces (:mod:`.budget`)."""
        return len(self.points) + sum(len(node) for node in self.points)


def _orthonormalize(Y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``Y = Q R`` with orthonormal columns ``Q`` and a positive diagonal of ``R`` (orientation kept).

    Two columns (isotropic chains): Gram-Schmidt in closed form; four: Householder QR.
    """
    if Y.shape[-1] == 2:
        y1 = Y[:, :, 0]
        n1 = np.sqrt(np.einsum("ij,ij->i", y1, y1))
        q1 = y1 / n1[:, None]
        r12 = np.einsum("ij,ij->i", q1, Y[:, :, 1])
        y2 = Y[:, :, 1] - r12[:, None] * q1
        n2 = np.sqrt(np.einsum("ij,ij->i", y2, y2))
        Q = np.empty_like(Y)
        Q[:, :, 0] = q1
        Q[:, :, 1] = y2 / n2[:, None]
        R = np.zeros(Y.shape[:1] + (2, 2))
        R[:, 0, 0], R[:, 0, 1], R[:, 1, 1] = n1, r12, n2
        return Q, R
    Q, R = np.linalg.qr(Y)
    d = np.sign(np.einsum("...ii->...i", R))
    d[d == 0] = 1.0
    return Q * d[..., None, :], R * d[..., :, None]


def _log_det(R: FloatArray) -> FloatArray:
    """``log det R`` of triangular factors with a positive diagonal."""
    return np.sum(np.log(np.einsum("...ii->...i", R)), axis=-1)


def _segment_pieces(beta1: FloatArray, length: float) -> int:
    return max(1, math.ceil(float(np.max(beta1, initial=0.0)) * length / MAX_PIECE_PHASE))


def _pieces(beta1: FloatArray, length: float) -> NDArray[np.int64]:
    """The pieces each point alone would cut a segment into (the C port's count, :mod:`.budget`'s units)."""
    return np.maximum(np.ceil(beta1 * length / MAX_PIECE_PHASE), 1.0).astype(np.int64)


def _initial(chain: Chain, n: int) -> FloatArray:
    i, j = chain.left.free_components
    rows = (i, j) if chain.isotropic else (i, j, 4 + i, 4 + j)
    Y = np.zeros((n, 4 * (1 if chain.isotropic else 2), len(rows)))
    for col, row in enumerate(rows):
        Y[:, row, col] = 1.0
    return Y


def _final_rows(chain: Chain) -> list[int]:
    i, j = chain.right.zero_components
    return [i, j] if chain.isotropic else [i, j, 4 + i, 4 + j]


@dataclass
class _Trace:
    """Snapshots of the propagated basis for the mode shape: ``(z, Y, map)`` after every step.

    ``map`` gives the coefficients of the previous basis from those of this one: the
    triangular factor ``R`` of an orthonormalisation (``q_prev = R^-1 q``), the matrix
    ``T`` of a point element that changes the basis (``q_prev = T q``), or ``None``
    for point matrices, which leave the coefficients unchanged.
    """

    z: list[float] = field(default_factory=list)
    bases: list[FloatArray] = field(default_factory=list)
    maps: list[tuple[str, FloatArray] | None] = field(default_factory=list)

    def add(self, z: float, Y: FloatArray, kind: str = "", matrix: FloatArray | None = None) -> None:
        self.z.append(z)
        self.bases.append(Y[0].copy())
        self.maps.append(None if matrix is None else (kind, matrix[0]))

    def coefficients(self, q: FloatArray) -> list[FloatArray]:
        """Coefficients of every snapshot's basis, from ``q`` of the last one."""
        out = [q]
        for entry in reversed(self.maps[1:]):
            if entry is not None:
                kind, matrix = entry
                q = np.linalg.solve(matrix, q) if kind == "solve" else matrix @ q
            out.append(q)
        return out[::-1]


def _propagate(
    chain: Chain, w: FloatArray, spin: FloatArray, min_pieces: int = 1, trace: _Trace | None = None,
    extra_pieces: int = 0
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Propagate the left-end basis through every element: ``Y_N``, its log scale and sign.

    ``extra_pieces`` cuts every segment into that many more pieces than it needs: the same result in exact
    arithmetic (``H(l) = H(l/p)^p``), other round-off.

    ``Y_N`` is orthonormal; the classical ``C_R P B_L`` equals ``sign * C_R Y_N``
    times ``exp(log_scale + sum(beta1 l))``; ``log_scale`` already holds
    ``-sum(beta1 l)`` (for an anisotropic chain the forward and backward components
    both grow), ``sign`` the factors of point elements that change the basis.
    """
    pair = not chain.isotropic
    per_step = budget.ANISOTROPIC_STEP if pair else 1
    budget.charge(per_step * chain.stations * w.size)
    sc = np.tile(chain.scale, 2) if pair else chain.scale
    ratio = sc[:, None] / sc[None, :]  # s~_i = sc_i s_i: entry (i, j) scales by sc_i / sc_j
    Y = _initial(chain, w.size)
    log_scale = np.zeros(w.size)
    sign = np.ones(w.size)
    fields: dict[tuple[ShaftSegment, float], FloatArray] = {}
    z = 0.0
    if trace is not None:
        trace.add(z, Y)

    def points(k: int) -> tuple[FloatArray, FloatArray | None]:
        """The basis after the point elements at node ``k``, and the product of their ``T``."""
        nonlocal sign
        Yk, T = Y, None
        for element in chain.points[k]:
            Yk, Te, se = element.propagate(Yk, w, spin, ratio, pair)
            if Te is not None:
                T = Te if T is None else T @ Te
            if se is not None:
                sign = sign * se
        return Yk, T

    for k, seg in enumerate(chain.segments):
        Y, T = points(k)
        if trace is not None:
            trace.add(z, Y, "multiply", T)
        growth = seg.beta1(w, spin)
        log_scale -= growth * seg.length
        if pair:  # the backward component grows with beta1(-w)
            backward = seg.beta1(-w, spin)
            log_scale -= backward * seg.length
            growth = np.maximum(growth, backward)
        budget.charge(per_step * int((np.maximum(_pieces(growth, seg.length), min_pieces) + extra_pieces).sum()))
        p = max(_segment_pieces(growth, seg.length), min_pieces) + extra_pieces
        piece = seg.length / p
        H = fields.get((seg, piece))
        if H is None:  # equal segments (a tube cut into equal pieces) share one field matrix
            H = (seg.transfer_matrix_pair(w, spin, piece) if pair else seg.transfer_matrix(w, spin, piece)) * ratio
            fields[seg, piece] = H
        for _ in range(p):
            Y, R = _orthonormalize(H @ Y)
            log_scale += _log_det(R)
            z += piece
            if trace is not None:
                trace.add(z, Y, "solve", R)
    Y, T = points(len(chain.segments))
    if trace is not None and T is not None:
        trace.add(z, Y, "multiply", T)
    Y, R = _orthonormalize(Y)
    log_scale += _log_det(R)
    if trace is not None:
        trace.add(z, Y, "solve", R)
    return Y, log_scale, sign


def determinant(chain: Chain, w: ArrayLike, spin: ArrayLike) -> FloatArray:
    """Scaled frequency determinant ``f(w, Omega)`` for broadcast arrays ``w``, ``spin``.

    ``f = det(C_R P B_L) * exp(-sum(beta1 l))`` in the non-dimensional state: the
    classical determinant (seed Eq. 31) with its exponential growth divided out by
    a smooth positive factor. It is computed from the orthonormalised propagation
    as ``det(C_R Y_N) * exp(sum(log det R_k) - sum(beta1 l))``, so no digits are lost
    to cancellation. The smooth factor keeps the shape of ``f`` between roots (a
    close pair of roots shows as a parabolic dip), which the root search needs;
    dividing by ``prod det R_k`` alone would flatten ``f`` to about +-1 with steps.

    Isotropic chains accept signed ``w`` (forward > 0, backward < 0); anisotropic
    chains take ``w > 0`` and return the 8x8-state determinant.
    """
    return determinant_and_rounding(chain, w, spin)[0]


def determinant_and_rounding(
    chain: Chain, w: ArrayLike, spin: ArrayLike, extra_pieces: int = 0
) -> tuple[FloatArray, FloatArray]:
    """:func:`determinant` and its rounding level: ``eps`` times the sum of the magnitudes of the terms
    of the end determinant (``|a d| + |b c|`` of the 2x2, the 24 products of the 4x4) times the same
    smooth factor. Near a root the terms cancel and ``f`` is their rounding: a dip of ``f`` as deep as
    this level is no evidence of a root (a layout of extreme materials ripples there by about one level).

    The level does not see the propagation's round-off, which stiffnesses far apart amplify (issue 45:
    noise of 5e10 where the level says 1.5e-4). With ``extra_pieces`` every segment is cut into that many
    more pieces: the same ``f`` in exact arithmetic, other round-off, so the difference of two evaluations
    samples the propagation's round-off (:func:`driveline.rotor.roots.find_roots_batch` asks it at dips)."""
    w_arr, s_arr = np.broadcast_arrays(np.atleast_1d(np.asarray(w, float)), np.atleast_1d(np.asarray(spin, float)))
    w_flat, s_flat = w_arr.ravel(), s_arr.ravel()
    f, rounding = np.empty(w_flat.size), np.empty(w_flat.size)
    for start in range(0, w_flat.size, BATCH):  # memory bounded by BATCH points, whatever the grid
        part = slice(start, start + BATCH)
        f[part], rounding[part] = _determinant(chain, w_flat[part].copy(), s_flat[part].copy(), extra_pieces)
    return f.reshape(w_arr.shape), rounding.reshape(w_arr.shape)


#: Points propagated at once: a batch search evaluates every grid point of every line in one call,
#: and the propagation holds several arrays of (points, 8, 4) per station; unbatched, a layout of
#: 100 segments with 202 masses and bearings asked for 16 GB.
BATCH = 4096


#: The permutations of four columns: the terms of a 4x4 determinant.
_PERMUTATIONS = np.array(list(itertools.permutations(range(4))))


def _determinant(chain: Chain, w: FloatArray, spin: FloatArray, extra_pieces: int = 0) -> tuple[FloatArray, FloatArray]:
    """:func:`determinant_and_rounding` at the points ``w``, ``spin`` (1-D, equal sizes)."""
    Y, log_scale, sign = _propagate(chain, w, spin, extra_pieces=extra_pieces)
    sub = Y[:, _final_rows(chain), :]
    if chain.isotropic:
        f = sub[:, 0, 0] * sub[:, 1, 1] - sub[:, 0, 1] * sub[:, 1, 0]
        terms = np.abs(sub[:, 0, 0] * sub[:, 1, 1]) + np.abs(sub[:, 0, 1] * sub[:, 1, 0])
    else:
        f = np.linalg.det(sub)
        terms = np.abs(np.prod(sub[:, np.arange(4), _PERMUTATIONS], axis=2)).sum(axis=1)
    # keep the factor finite; sign and zeros are unaffected
    factor = np.exp(np.clip(log_scale, -LOG_SCALE_CLIP, LOG_SCALE_CLIP))
    return sign * f * factor, EPS * terms * factor


@dataclass(frozen=True)
class ModeShape:
    """Displacement amplitudes of one mode at the stations and inside segments.

    ``z`` [m] axial positions (stations appear twice: before and after their
    point elements); ``forward`` and ``backward`` the real amplitudes of the
    circular whirl components (``backward`` is zero for an isotropic forward mode,
    and vice versa), normalised so that the largest amplitude is +1.
    """

    w: float
    spin: float
    z: FloatArray
    forward: FloatArray
    backward: FloatArray

    @property
    def forward_fraction(self) -> float:
        """Share of the forward component in ``sum |U|^2`` (1 = pure forward whirl)."""
        ef = float(np.sum(self.forward**2))
        eb = float(np.sum(self.backward**2))
        return ef / (ef + eb) if ef + eb > 0 else float("nan")


def mode_shape(chain: Chain, w: float, spin: float, points_per_segment: int = 8) -> ModeShape:
    """Mode shape at a root ``w`` of :func:`determinant` (signed for isotropic chains).

    The propagation of :func:`determinant` is run once more, keeping every basis
    ``Y_k`` and triangular factor ``R_k``; the null vector of the end conditions is
    then mapped back with ``q_k = R_k^-1 q_{k+1}``.
    """
    trace = _Trace()
    Y, _, _ = _propagate(chain, np.array([float(w)]), np.array([float(spin)]), points_per_segment, trace)
    _, _, vt = np.linalg.svd(Y[0][_final_rows(chain), :])
    coeffs = trace.coefficients(vt[-1])
    states = np.array([Y_k @ c for Y_k, c in zip(trace.bases, coeffs)])
    fwd = states[:, 0] / chain.scale[0]
    bwd = states[:, 4] / chain.scale[0] if not chain.isotropic else np.zeros_like(fwd)
    if chain.isotropic and w < 0:
        fwd, bwd = bwd, fwd
    both = np.concatenate([fwd, bwd])
    peak = both[np.argmax(np.abs(both))]  # the largest amplitude becomes +1
    return ModeShape(float(w), float(spin), np.array(trace.z), fwd / peak, bwd / peak)
