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
real state ``[s_a, s_b]`` (``w > 0``): segments and masses act on ``s_a`` at ``+w``
and on ``s_b`` at ``-w``; a bearing adds ``-kbar U_a - dk U_b`` to ``V_a`` and
``-dk U_a - kbar U_b`` to ``V_b`` (``kbar = (kxx+kyy)/2``, ``dk = (kxx-kyy)/2``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .elements import Bearing, ConcentratedMass, EndCondition, ShaftSegment

FloatArray = NDArray[np.float64]

#: Largest ``beta1 * piece_length`` per propagation step (growth ``e**2`` per step).
MAX_PIECE_PHASE = 2.0


@dataclass(frozen=True)
class Station:
    """Point elements lumped at one node (masses and bearings commute)."""

    mass: float = 0.0
    polar_inertia: float = 0.0
    diametral_inertia: float = 0.0
    k_mean: float = 0.0
    k_diff: float = 0.0

    @property
    def is_empty(self) -> bool:
        return not (self.mass or self.polar_inertia or self.diametral_inertia or self.k_mean or self.k_diff)


@dataclass(frozen=True)
class Chain:
    """Compiled element chain: station 0, segment 0, station 1, ..., station N."""

    segments: tuple[ShaftSegment, ...]
    stations: tuple[Station, ...]
    left: EndCondition
    right: EndCondition
    isotropic: bool
    # Non-dimensional scaling of the state: [U/L0, psi, M L0/EI0, V L0^2/EI0].
    scale: FloatArray = field(repr=False)

    @classmethod
    def build(
        cls,
        segments: tuple[ShaftSegment, ...],
        masses: tuple[ConcentratedMass, ...],
        bearings: tuple[Bearing, ...],
        left: EndCondition,
        right: EndCondition,
    ) -> Chain:
        n_nodes = len(segments) + 1
        acc = [[0.0] * 5 for _ in range(n_nodes)]
        for m in masses:
            acc[m.node][0] += m.mass
            acc[m.node][1] += m.polar_inertia
            acc[m.node][2] += m.diametral_inertia
        for b in bearings:
            acc[b.node][3] += b.k_mean
            acc[b.node][4] += b.k_diff
        stations = tuple(Station(*a) for a in acc)
        L0 = sum(s.length for s in segments) / len(segments)
        EI0 = segments[0].bending_stiffness
        scale = np.array([1.0 / L0, 1.0, L0 / EI0, L0 * L0 / EI0])
        isotropic = all(st.k_diff == 0.0 for st in stations)
        return cls(tuple(segments), stations, left, right, isotropic, scale)

    @property
    def dim(self) -> int:
        """State dimension: 4 (isotropic, signed ``w``) or 8 (anisotropic, ``w > 0``)."""
        return 4 if self.isotropic else 8


def _orthonormalize2(Y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Gram-Schmidt on the two columns of ``Y`` (n, 4, 2); returns ``Q`` and ``log det R``."""
    y1 = Y[:, :, 0]
    n1 = np.sqrt(np.einsum("ij,ij->i", y1, y1))
    q1 = y1 / n1[:, None]
    y2 = Y[:, :, 1]
    y2 = y2 - np.einsum("ij,ij->i", q1, y2)[:, None] * q1
    n2 = np.sqrt(np.einsum("ij,ij->i", y2, y2))
    q2 = y2 / n2[:, None]
    out = np.empty_like(Y)
    out[:, :, 0] = q1
    out[:, :, 1] = q2
    return out, np.log(n1 * n2)


def _orthonormalize(Y: FloatArray) -> tuple[FloatArray, FloatArray]:
    """QR with a positive diagonal of ``R``: ``Y = Q R`` (orientation kept)."""
    Q, R = np.linalg.qr(Y)
    d = np.sign(np.einsum("...ii->...i", R))
    d[d == 0] = 1.0
    return Q * d[..., None, :], R * d[..., :, None]


def _orthonormalize_log(Y: FloatArray) -> tuple[FloatArray, FloatArray]:
    Q, R = _orthonormalize(Y)
    return Q, np.sum(np.log(np.einsum("...ii->...i", R)), axis=-1)


def _apply_station_iso(Y: FloatArray, st: Station, w: FloatArray, spin: FloatArray, sc: FloatArray) -> None:
    """In place: ``M += -(Jd w^2 - Jp Omega w) psi``, ``V += (m w^2 - k) U`` (scaled state)."""
    if st.is_empty:
        return
    rot = st.diametral_inertia * w * w - st.polar_inertia * spin * w
    tra = st.mass * w * w - st.k_mean
    # scaled: s~_i = sc_i s_i  ->  entry (i, j) scales by sc_i / sc_j
    Y[:, 2, :] -= (rot * (sc[2] / sc[1]))[:, None] * Y[:, 1, :]
    Y[:, 3, :] += (tra * (sc[3] / sc[0]))[:, None] * Y[:, 0, :]


def _apply_station_aniso(Y: FloatArray, st: Station, w: FloatArray, spin: FloatArray, sc: FloatArray) -> None:
    if st.is_empty:
        return
    ka, kd = st.k_mean * sc[3] / sc[0], st.k_diff * sc[3] / sc[0]
    Ua = Y[:, 0, :].copy()
    Ub = Y[:, 4, :].copy()
    for off, ww in ((0, w), (4, -w)):
        rot = st.diametral_inertia * ww * ww - st.polar_inertia * spin * ww
        Y[:, off + 2, :] -= (rot * (sc[2] / sc[1]))[:, None] * Y[:, off + 1, :]
        Y[:, off + 3, :] += (st.mass * ww * ww * sc[3] / sc[0])[:, None] * Y[:, off, :]
    Y[:, 3, :] -= ka * Ua + kd * Ub
    Y[:, 7, :] -= kd * Ua + ka * Ub


def _segment_pieces(beta1: FloatArray, length: float) -> int:
    return max(1, math.ceil(float(np.max(beta1, initial=0.0)) * length / MAX_PIECE_PHASE))


def _scaled_field(seg: ShaftSegment, w: FloatArray, spin: FloatArray, length: float, sc: FloatArray) -> FloatArray:
    H = seg.transfer_matrix(w, spin, length)
    return H * (sc[:, None] / sc[None, :])


def _initial(chain: Chain, n: int) -> FloatArray:
    i, j = chain.left.free_components
    if chain.isotropic:
        Y = np.zeros((n, 4, 2))
        Y[:, i, 0] = 1.0
        Y[:, j, 1] = 1.0
    else:
        Y = np.zeros((n, 8, 4))
        for col, row in enumerate((i, j, 4 + i, 4 + j)):
            Y[:, row, col] = 1.0
    return Y


def _final_rows(chain: Chain) -> list[int]:
    i, j = chain.right.zero_components
    return [i, j] if chain.isotropic else [i, j, 4 + i, 4 + j]


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
    w_arr, s_arr = np.broadcast_arrays(np.atleast_1d(np.asarray(w, float)), np.atleast_1d(np.asarray(spin, float)))
    shape = w_arr.shape
    w1 = w_arr.ravel().copy()
    s1 = s_arr.ravel().copy()
    n = w1.size
    sc = chain.scale
    Y = _initial(chain, n)
    iso = chain.isotropic
    log_scale = np.zeros(n)
    for k, seg in enumerate(chain.segments):
        st = chain.stations[k]
        if iso:
            _apply_station_iso(Y, st, w1, s1, sc)
        else:
            _apply_station_aniso(Y, st, w1, s1, sc)
        b1 = seg.beta1(w1, s1)
        log_scale -= b1 * seg.length
        if not iso:  # the backward component grows with beta1(-w)
            b1m = seg.beta1(-w1, s1)
            log_scale -= b1m * seg.length
            b1 = np.maximum(b1, b1m)
        p = _segment_pieces(b1, seg.length)
        piece = seg.length / p
        Hp = _scaled_field(seg, w1, s1, piece, sc)
        if not iso:
            Hm = _scaled_field(seg, -w1, s1, piece, sc)
        for _ in range(p):
            if iso:
                Y, lr = _orthonormalize2(Hp @ Y)
            else:
                Y = np.concatenate([Hp @ Y[:, :4, :], Hm @ Y[:, 4:, :]], axis=1)
                Y, lr = _orthonormalize_log(Y)
            log_scale += lr
    st = chain.stations[-1]
    if iso:
        _apply_station_iso(Y, st, w1, s1, sc)
        Y, lr = _orthonormalize2(Y)
    else:
        _apply_station_aniso(Y, st, w1, s1, sc)
        Y, lr = _orthonormalize_log(Y)
    log_scale += lr
    rows = _final_rows(chain)
    sub = Y[:, rows, :]
    if iso:
        f = sub[:, 0, 0] * sub[:, 1, 1] - sub[:, 0, 1] * sub[:, 1, 0]
    else:
        f = np.linalg.det(sub)
    # keep the factor finite; sign and zeros are unaffected
    f = f * np.exp(np.clip(log_scale, -700.0, 700.0))
    return f.reshape(shape)


@dataclass(frozen=True)
class ModeShape:
    """Displacement amplitudes of one mode at the stations and inside segments.

    ``z`` [m] axial positions (stations appear twice: before and after their
    point elements); ``forward`` and ``backward`` the real amplitudes of the
    circular whirl components (``backward`` is zero for an isotropic forward mode,
    and vice versa), normalised to a largest magnitude of 1.
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

    The same orthonormalised propagation is run once, storing every basis ``Y_k``
    and triangular factor ``R_k``; the null vector of the end conditions is then
    mapped back with ``q_k = R_k^-1 q_{k+1}``.
    """
    wv = np.array([float(w)])
    sv = np.array([float(spin)])
    sc = chain.scale
    iso = chain.isotropic
    Y = _initial(chain, 1)
    records: list[tuple[str, float, FloatArray]] = []  # (kind, z, Y) snapshots after each op
    Rs: list[FloatArray | None] = []
    z = 0.0

    def station(k: int) -> None:
        if iso:
            _apply_station_iso(Y, chain.stations[k], wv, sv, sc)
        else:
            _apply_station_aniso(Y, chain.stations[k], wv, sv, sc)

    records.append(("node", z, Y[0].copy()))
    Rs.append(None)
    for k, seg in enumerate(chain.segments):
        station(k)
        records.append(("node", z, Y[0].copy()))
        Rs.append(None)
        b1 = np.maximum(seg.beta1(wv, sv), seg.beta1(-wv, sv))
        p = max(_segment_pieces(b1, seg.length), points_per_segment)
        piece = seg.length / p
        Hp = _scaled_field(seg, wv, sv, piece, sc)
        Hm = _scaled_field(seg, -wv, sv, piece, sc)
        for _ in range(p):
            if iso:
                Ynew = Hp @ Y
            else:
                Ynew = np.concatenate([Hp @ Y[:, :4, :], Hm @ Y[:, 4:, :]], axis=1)
            Y, R = _orthonormalize(Ynew)
            z += piece
            records.append(("piece", z, Y[0].copy()))
            Rs.append(R[0])
    station(len(chain.segments))
    records.append(("node", z, Y[0].copy()))
    Rs.append(None)
    rows = _final_rows(chain)
    _, _, vt = np.linalg.svd(Y[0][rows, :])
    q = vt[-1]
    coeffs: list[FloatArray] = [q]
    for R in reversed(Rs[1:]):
        q = np.linalg.solve(R, q) if R is not None else q
        coeffs.append(q)
    coeffs.reverse()
    zs = np.array([r[1] for r in records])
    states = np.array([rec[2] @ c for rec, c in zip(records, coeffs)])
    fwd = states[:, 0] / sc[0]
    bwd = states[:, 4] / sc[0] if not iso else np.zeros_like(fwd)
    if iso and w < 0:
        fwd, bwd = bwd, fwd
    peak = max(np.max(np.abs(fwd)), np.max(np.abs(bwd)))
    return ModeShape(float(w), float(spin), zs, fwd / peak, bwd / peak)
