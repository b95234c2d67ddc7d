"""Damped whirl and unbalance response of a driveline, by finite elements.

The model is that of :func:`fem.assemble_damped` in the complex whirl coordinate ``u = x + i y``::

    M u'' + (C - i Omega G) u' + C_b conj(u') + K u + K_b conj(u) = f.

A bearing with ``kxx != kyy`` or cross-coupling (``K_b``, ``C_b`` non-zero) couples ``u`` and
``conj(u)``; taking ``p = u`` and ``q = conj(u)`` as independent unknowns doubles the system::

    M2 x'' + (C2 + Omega Gv) x' + K2 x = f2,   x = [p, q],
    K2 = [[K, K_b], [conj(K_b), conj(K)]],  C2 likewise,  Gv = diag(-i G, i G),  M2 = diag(M, M).

With axisymmetric bearings ``q`` decouples (it is the conjugate of ``p``) and only ``p`` is kept.

* **Damped whirl**: the eigenvalues ``lam = -sigma + i w_d`` of ``x = X exp(lam t)``. A mode is
  reported once, with ``w_d >= 0``; its forward share is ``sum |p_U|^2 / sum (|p_U|^2 + |q_U|^2)``
  over the translations (the backward circle of ``u`` is ``conj(q)``). Damping ratio
  ``zeta = sigma / |lam|``, logarithmic decrement ``2 pi sigma / w_d``.
* **Unbalance response**: an unbalance ``U exp(i phi)`` at spin ``Omega`` is the force
  ``U Omega^2 exp(i (Omega t + phi))``; with ``x = X exp(i Omega t)``::

      (K2 + i Omega (C2 + Omega Gv) - Omega^2 M2) X = Omega^2 [F, 0],

  and ``u = A exp(i Omega t) + B exp(-i Omega t)`` with ``A = X_p``, ``B = conj(X_q)``: the
  orbit is an ellipse with major semi-axis ``|A| + |B|`` and minor semi-axis ``||A| - |B||``.
  A bearing transmits ``F_a = (k_a + i Omega c_a) A + (k_b + i Omega c_b) conj(B)`` forward and
  ``conj(F_q)``, ``F_q = (conj(k_b) + i Omega conj(c_b)) A + (conj(k_a) + i Omega conj(c_a)) conj(B)``,
  backward: major semi-axis ``|F_a| + |F_q|``.

Forces and displacements between beam nodes use the cubic Hermite shape functions. The
beam elements converge as ``h**4`` (Rayleigh) or ``h**2`` (Timoshenko).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy import sparse
from scipy.linalg.lapack import zgbsv
from scipy.sparse.linalg import LinearOperator, eigs, splu

from . import fem
from .driveline import Driveline
from .elements import Unbalance

FloatArray = NDArray[np.float64]
ComplexArray = NDArray[np.complex128]

#: Eigenvalues computed beyond ``2 n`` for the first ``n`` modes (room for overdamped ones).
EXTRA_EIGENVALUES = 6
#: Largest first-order system solved densely for the first modes (above: shift-invert Arnoldi).
DENSE_SIZE = 160
#: Shift of the Arnoldi iteration [1/s]: off zero, where a free rotor has its rigid-body modes.
SHIFT = -1.0
#: Smallest whirl frequency of a mode, as a share of the largest eigenvalue: below it the mode is
#: overdamped or static and whirls not.
WHIRL_SHARE = 1e-9



@dataclass(frozen=True)
class DampedMode:
    """One damped whirl mode: ``eigenvalue = -sigma + i w_d`` (``w_d >= 0``) and the share of its
    forward circular component in ``sum |U|^2`` (1 forward whirl, 0 backward)."""

    eigenvalue: complex
    forward_share: float

    @property
    def frequency(self) -> float:
        """Damped whirl frequency ``w_d`` [rad/s]."""
        return self.eigenvalue.imag

    @property
    def damping_ratio(self) -> float:
        """``zeta = sigma / |lam|`` (negative: the mode grows)."""
        return -self.eigenvalue.real / abs(self.eigenvalue)

    @property
    def log_decrement(self) -> float:
        """Logarithmic decrement ``2 pi sigma / w_d`` per whirl period."""
        return -2.0 * np.pi * self.eigenvalue.real / self.eigenvalue.imag

    @property
    def whirl(self) -> Literal["forward", "backward"]:
        """The dominant whirl sense."""
        return "forward" if self.forward_share >= 0.5 else "backward"


@dataclass(frozen=True)
class UnbalanceResponse:
    """Synchronous response ``u = A exp(i Omega t) + B exp(-i Omega t)`` at ``positions`` [m] for
    each of ``spins`` [rad/s]: ``forward`` = ``A``, ``backward`` = ``B`` [m], arrays (spins,
    positions); ``bearing_forces`` [N] (spins, bearings), the major semi-axis of each bearing's
    force orbit (0 for a bearing on a pinned or clamped end)."""

    spins: FloatArray
    positions: FloatArray
    forward: ComplexArray
    backward: ComplexArray
    bearing_forces: FloatArray

    @property
    def major(self) -> FloatArray:
        """Major semi-axis of the orbit ``|A| + |B|`` [m]: the largest displacement."""
        return np.abs(self.forward) + np.abs(self.backward)

    @property
    def minor(self) -> FloatArray:
        """Minor semi-axis ``||A| - |B||`` [m]."""
        return np.abs(np.abs(self.forward) - np.abs(self.backward))


def _hermite(xi: FloatArray, h: FloatArray) -> FloatArray:
    """Cubic Hermite shape functions on ``[U1, psi1, U2, psi2]`` at ``xi`` in [0, 1], shape (n, 4)."""
    x2, x3 = xi * xi, xi**3
    return np.stack([1 - 3 * x2 + 2 * x3, h * (xi - 2 * x2 + x3), 3 * x2 - 2 * x3, h * (x3 - x2)], axis=-1)


def _band_storage(matrix: ComplexArray, lower: int, upper: int) -> ComplexArray:
    """LAPACK ``gbsv`` band storage: ``ab[lower + upper + i - j, j] = matrix[i, j]`` below ``lower`` rows
    of room for the factorisation's fill-in."""
    n = matrix.shape[0]
    ab = np.zeros((2 * lower + upper + 1, n), dtype=complex)
    for k in range(-lower, upper + 1):
        ab[lower + upper - k, max(k, 0): n + min(k, 0)] = np.diagonal(matrix, k)
    return ab


class DampedRotor:
    """Finite-element model of ``driveline`` (``elements_per_segment`` beam elements per segment,
    one count for all or one per segment)
    with the bearings' damping and anisotropy: damped modes and unbalance response."""

    def __init__(self, driveline: Driveline, elements_per_segment: int | Sequence[int] = 40) -> None:
        self.driveline = driveline
        fe = fem.assemble_damped(driveline, elements_per_segment)
        self._fe = fe
        self.doubled = bool(np.any(fe.K_b) or np.any(fe.C_b))
        # no damping and a symmetric bearing stiffness: a conservative gyroscopic system, whose
        # eigenvalues are imaginary (the eigensolver's real parts are round-off, about 1e-13 |lam|)
        self.conservative = not (np.any(fe.C) or np.any(fe.C_b)) and all(b.kxy == b.kyx for b in driveline.bearings)
        n = fe.M.shape[0]
        if self.doubled:
            self.K = np.block([[fe.K, fe.K_b], [fe.K_b.conj(), fe.K.conj()]])
            self.C = np.block([[fe.C, fe.C_b], [fe.C_b.conj(), fe.C.conj()]])
            zero = np.zeros((n, n))
            self.M = np.block([[fe.M, zero], [zero, fe.M]])
            self.G = np.block([[-1j * fe.G, zero], [zero, 1j * fe.G]])
        else:
            self.K, self.C, self.M, self.G = fe.K, fe.C, fe.M, -1j * fe.G
        self._n = n
        # the dofs of p and q interleaved make the dynamic stiffness banded
        self._order = np.arange(2 * n).reshape(2, n).T.ravel() if self.doubled else np.arange(n)
        reordered = [matrix[np.ix_(self._order, self._order)] for matrix in (self.K, self.C, self.G, self.M)]
        rows, cols = np.nonzero(sum(np.abs(matrix) for matrix in reordered))
        self._bands = (int(np.max(rows - cols)), int(np.max(cols - rows)))
        self._banded = [_band_storage(matrix, *self._bands) for matrix in reordered]
        mesh = fe.mesh
        rows = fe.index[np.unique(mesh.elements[:, [0, 2]])]
        self._translations = rows[rows >= 0]
        self._bearing_rows = np.array([fe.index[mesh.node_u[b.node]] for b in driveline.bearings], dtype=int)
        self._bearing_coefficients = np.array(
            [[*b.stiffness_components, *b.damping_components] for b in driveline.bearings], dtype=complex
        ).reshape(-1, 4).T

    # -- building blocks -------------------------------------------------------
    def shape_rows(self, positions: ArrayLike) -> ComplexArray:
        """Rows (positions, n) interpolating ``u`` from the ``p`` unknowns (Hermite shape functions)."""
        z = np.atleast_1d(np.asarray(positions, dtype=float))
        length = self.driveline.length
        if np.any(~np.isfinite(z)) or np.any(z < 0.0) or np.any(z > length * (1 + 1e-12)):
            raise ValueError(f"positions must lie on the shaft, 0 to {length!r} m, got {z.tolist()!r}")
        mesh = self._fe.mesh
        e = np.clip(np.searchsorted(mesh.z, z, side="right") - 1, 0, len(mesh.elements) - 1)
        h = mesh.z[e + 1] - mesh.z[e]
        shape = _hermite(np.clip((z - mesh.z[e]) / h, 0.0, 1.0), h)
        rows = np.zeros((z.size, self._n), dtype=complex)
        for k in range(4):
            target = self._fe.index[mesh.elements[e, k]]
            hit = target >= 0
            np.add.at(rows, (np.flatnonzero(hit), target[hit]), shape[hit, k])
        return rows

    def load(self, unbalances: Sequence[Unbalance]) -> ComplexArray:
        """Load vector ``[F, 0]`` of the unbalances per unit ``Omega^2`` (consistent nodal loads)."""
        rows = self.shape_rows([u.position for u in unbalances]) if unbalances else np.zeros((0, self._n))
        phasors = np.array([u.amount * np.exp(1j * u.phase) for u in unbalances], dtype=complex)
        force = phasors @ rows
        return np.concatenate([force, np.zeros(self._n)]) if self.doubled else force

    def solve(self, spin: float, load: ComplexArray) -> ComplexArray:
        """Synchronous amplitudes ``X`` at ``spin``: ``(K2 + i Omega (C2 + Omega Gv) - Omega^2 M2) X =
        Omega^2 load`` (a banded LU solve, a few microseconds for a one-piece tube)."""
        k, c, g, m = self._banded
        matrix = k + (1j * spin) * c + (1j * spin * spin) * g - (spin * spin) * m
        _, _, x, info = zgbsv(*self._bands, matrix, (spin * spin) * load[self._order], overwrite_ab=1)
        if info > 0:
            raise ArithmeticError(f"the dynamic stiffness is singular at {spin!r} rad/s (an undamped resonance)")
        solution = np.empty_like(load)
        solution[self._order] = x
        return solution

    def components(self, solution: ComplexArray, rows: ComplexArray) -> tuple[ComplexArray, ComplexArray]:
        """``(A, B)`` at the positions of ``rows`` from solutions (spins, N): forward and backward circles."""
        forward = solution[:, : self._n] @ rows.T
        backward = (solution[:, self._n:] @ rows.T).conj() if self.doubled else np.zeros_like(forward)
        return forward, backward

    def bearing_forces(self, spins: FloatArray, solution: ComplexArray) -> FloatArray:
        """Major semi-axis of each bearing's force orbit [N], shape (spins, bearings)."""
        rows, held = np.maximum(self._bearing_rows, 0), self._bearing_rows >= 0
        ka, kb, ca, cb = self._bearing_coefficients
        w = 1j * np.asarray(spins, dtype=float)[:, None]
        a = solution[:, rows]
        q = solution[:, self._n + rows] if self.doubled else np.zeros_like(a)
        fa = (ka + w * ca) * a + (kb + w * cb) * q
        fq = (kb.conj() + w * cb.conj()) * a + (ka.conj() + w * ca.conj()) * q
        return np.where(held, np.abs(fa) + np.abs(fq), 0.0)

    @cached_property
    def _scale(self) -> float:
        """``s`` of ``y = [x, x'/s]``: balances stiffness and mass in the first-order form."""
        return float(np.sqrt(np.max(np.abs(np.diag(self.K))) / np.max(np.diag(self.M))))

    @cached_property
    def _dense_blocks(self) -> tuple[ComplexArray, ComplexArray, ComplexArray, ComplexArray]:
        """``B^-1 A`` of :meth:`modes` in blocks, without the spin: ``[0, s I]``, ``-M2^-1 K2 / s``,
        ``-M2^-1 C2`` and ``-M2^-1 Gv`` (the spin multiplies the last), factorised once."""
        size = self.M.shape[0]
        upper = np.hstack([np.zeros((size, size)), self._scale * np.eye(size)]).astype(complex)
        stiffness, damping, gyroscopic = (-np.linalg.solve(self.M, matrix).astype(complex)
                                          for matrix in (self.K / self._scale, self.C, self.G))
        return upper, stiffness, damping, gyroscopic

    # -- results -----------------------------------------------------------------
    def modes(self, spin: float = 0.0, n: int | None = None) -> list[DampedMode]:
        """Damped whirl modes at ``spin`` [rad/s], ascending in damped frequency (the first ``n``).

        Eigenvalues of ``A y = lam B y``, ``y = [x, x'/s]``, ``A = [[0, s I], [-K2/s, -(C2 + Omega Gv)]]``,
        ``B = diag(I, M2)`` (``s`` balances stiffness and mass): all of them (dense, also for a system
        of at most DENSE_SIZE) or, for ``n``, the ``2 n + EXTRA_EIGENVALUES`` nearest to zero by
        shift-invert Arnoldi on a sparse factorisation (conjugates and overdamped ones are among
        them and dropped).
        """
        size = self.M.shape[0]
        scale = self._scale
        count = None if n is None else 2 * n + EXTRA_EIGENVALUES
        if count is None or 2 * size <= DENSE_SIZE:  # B^-1 A: only the mass block is inverted
            upper, stiffness, damping, gyroscopic = self._dense_blocks
            dense = np.block([[upper], [stiffness, damping + spin * gyroscopic]])
            # an axisymmetric model needs no eigenvectors: the sign of Im lam is the whirl sense
            lam, vectors = np.linalg.eig(dense) if self.doubled else (np.linalg.eigvals(dense), None)
        else:
            eye = sparse.identity(size, format="csc")
            a = sparse.bmat([[None, scale * eye], [sparse.csc_matrix(-self.K / scale),
                                                   sparse.csc_matrix(-(self.C + spin * self.G))]], format="csc")
            b = sparse.block_diag([eye, sparse.csc_matrix(self.M)], format="csc")
            factor = splu((a - SHIFT * b).astype(complex).tocsc())
            operator = LinearOperator(a.shape, matvec=lambda v: factor.solve(b @ v), dtype=complex)
            nu, vectors = eigs(operator, k=count, which="LM") if self.doubled else (
                eigs(operator, k=count, which="LM", return_eigenvectors=False), None)
            lam = SHIFT + 1.0 / nu
        if self.conservative:
            lam = 1j * lam.imag
        whirling = np.isfinite(lam) & (np.abs(lam.imag) > WHIRL_SHARE * np.max(np.abs(lam)))  # not overdamped or static
        if not self.doubled:  # u = p exp(lam t): Im lam < 0 whirls backward
            out = [DampedMode(complex(v.real, abs(v.imag)), float(v.imag > 0)) for v in lam[whirling]]
        else:  # each mode also appears conjugated, at -w_d
            t = self._translations
            out = []
            for value, vector in zip(lam[whirling & (lam.imag > 0)], vectors.T[whirling & (lam.imag > 0)]):
                fwd = float(np.sum(np.abs(vector[t]) ** 2))
                bwd = float(np.sum(np.abs(vector[self._n + t]) ** 2))
                out.append(DampedMode(complex(value), fwd / (fwd + bwd)))
        out.sort(key=lambda mode: mode.frequency)
        return out if n is None else out[:n]

    def unbalance_response(
        self, spins: ArrayLike, unbalances: Sequence[Unbalance] | None = None, positions: ArrayLike | None = None
    ) -> UnbalanceResponse:
        """Synchronous response to ``unbalances`` (default: the driveline's) at ``positions`` [m]
        (default: its nodes) for every speed of ``spins`` [rad/s]."""
        spin_arr = np.atleast_1d(np.asarray(spins, dtype=float))
        if positions is None:
            positions = np.concatenate([[0.0], np.cumsum([s.length for s in self.driveline.segments])])
        z = np.atleast_1d(np.asarray(positions, dtype=float))
        rows = self.shape_rows(z)
        load = self.load(self.driveline.unbalances if unbalances is None else unbalances)
        solution = np.array([self.solve(spin, load) for spin in spin_arr]).reshape(spin_arr.size, load.size)
        forward, backward = self.components(solution, rows)
        return UnbalanceResponse(spin_arr, z, forward, backward, self.bearing_forces(spin_arr, solution))
