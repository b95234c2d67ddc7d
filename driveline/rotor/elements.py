"""Driveline elements and their transfer matrices (complex whirl coordinates).

Lateral motion is written as ``u = x + i y`` with ``u(z, t) = U(z) exp(i w t)`` in
the *stationary* frame. ``w`` is the signed whirl frequency: ``w > 0`` is forward
whirl (same sense as the spin ``Omega``), ``w < 0`` backward whirl. For an isotropic
rotor every coefficient is then real and one 4x4 real transfer matrix per element
carries both planes (seed paper, Eqs. 3-7, where the 8x8 matrix is block-diagonal
with two equal blocks).

State vector at a station (SI units)::

    s = [U, psi, M, V],   psi = U',   M = EI U'',   V = EI U''' + c U'

``V`` is the transverse force *including* the rotary-inertia and gyroscopic couple
``c U'`` with ``c = rho I (w**2 - 2 Omega w)``; with this choice the segment law is
``s' = A s`` with ``V' = rho A w**2 U`` and free ends are exactly ``M = V = 0``
(the seed carries ``EI U'''`` instead, which breaks the free-end condition and the
force balance between segments of different section).

Every element provides, behind one interface (as ROSS's elements provide their
matrices to its rotor assembly):

* ``transfer_matrix(w, spin)``: the 4x4 matrix for one circular whirl component at
  the signed frequency ``w`` (isotropic rotor);
* ``transfer_matrix_pair(w, spin)``: the 8x8 matrix acting on the forward and backward
  components ``[s_a, s_b]`` of a mode at ``w > 0`` (anisotropic rotor); an element
  with rotational symmetry acts on each component alone, ``diag(T(w), T(-w))``;
* ``fe_matrices(...)``: its stiffness, mass and gyroscopic matrices for the
  finite-element check (:mod:`driveline.rotor.fem`).

All matrix builders are vectorised: ``w`` and ``spin`` broadcast to a common shape
``(n,)`` and the result has shape ``(n, 4, 4)`` or ``(n, 8, 8)``.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

__all__ = [
    "Bearing",
    "ConcentratedMass",
    "EndCondition",
    "Hinge",
    "PointElement",
    "ShaftSegment",
    "Unbalance",
]


def _positive(name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v) or v <= 0.0:
        raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    return v


def _non_negative(name: str, value: float) -> float:
    v = float(value)
    if not math.isfinite(v) or v < 0.0:
        raise ValueError(f"{name} must be a finite number >= 0, got {value!r}")
    return v


def _node(value: int) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise ValueError(f"node must be an integer >= 0, got {value!r}")
    return int(value)


class EndCondition(str, Enum):
    """Support at either end of the driveline.

    ``FREE``: ``M = V = 0`` (use with :class:`Bearing` elements, as in the seed's
    Fig. 2); ``PINNED``: ``U = M = 0`` (rigid simple support); ``CLAMPED``:
    ``U = psi = 0``.
    """

    FREE = "free"
    PINNED = "pinned"
    CLAMPED = "clamped"

    @property
    def zero_components(self) -> tuple[int, int]:
        """Indices of the state components that vanish at this end."""
        return {"free": (2, 3), "pinned": (0, 2), "clamped": (0, 1)}[self.value]

    @property
    def free_components(self) -> tuple[int, int]:
        """Indices of the state components left unknown at this end."""
        z = self.zero_components
        i, j = (k for k in range(4) if k not in z)
        return i, j


# ---------------------------------------------------------------------------
# Stable auxiliary functions for the closed-form field matrix
# ---------------------------------------------------------------------------
_SERIES_LIMIT = 0.1  # below this argument the Taylor series is exact to ~1e-16


def _sinh_minus_x_over_x3(x: FloatArray) -> FloatArray:
    """(sinh x - x)/x**3, -> 1/6 at x = 0, without cancellation."""
    small = x < _SERIES_LIMIT
    xs = np.where(small, 1.0, x)
    direct = (np.sinh(xs) - xs) / xs**3
    x2 = x * x
    series = 1 / 6 + x2 * (1 / 120 + x2 * (1 / 5040 + x2 / 362880))
    return np.where(small, series, direct)


def _x_minus_sin_over_x3(y: FloatArray) -> FloatArray:
    """(y - sin y)/y**3, -> 1/6 at y = 0, without cancellation."""
    small = y < _SERIES_LIMIT
    ys = np.where(small, 1.0, y)
    direct = (ys - np.sin(ys)) / ys**3
    y2 = y * y
    series = 1 / 6 - y2 * (1 / 120 - y2 * (1 / 5040 - y2 / 362880))
    return np.where(small, series, direct)


def _cosh_minus_1_over_x2(x: FloatArray) -> FloatArray:
    """(cosh x - 1)/x**2 = 2 sinh(x/2)**2/x**2, -> 1/2 at x = 0."""
    h = 0.5 * x
    hs = np.where(h == 0.0, 1.0, h)
    r = np.where(h == 0.0, 1.0, np.sinh(hs) / hs)
    return 0.5 * r * r


def _1_minus_cos_over_y2(y: FloatArray) -> FloatArray:
    """(1 - cos y)/y**2 = 2 sin(y/2)**2/y**2, -> 1/2 at y = 0."""
    r = np.sinc(y / (2.0 * np.pi))
    return 0.5 * r * r


def _betas(a: FloatArray, b: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Squared wave numbers of ``U'''' + a U'' - b U = 0`` (b >= 0).

    ``beta1**2 = r - a/2`` (hyperbolic), ``beta2**2 = r + a/2`` (trigonometric),
    ``r = sqrt(a**2/4 + b)``; seed Eqs. (22)-(23). The smaller one is formed as
    ``b / larger`` to avoid cancellation.
    """
    r = np.sqrt(0.25 * a * a + b)
    big2 = np.where(a >= 0.0, r + 0.5 * a, r - 0.5 * a)
    safe = np.where(big2 > 0.0, big2, 1.0)
    small2 = np.where(big2 > 0.0, b / safe, 0.0)
    b1sq = np.where(a >= 0.0, small2, big2)
    b2sq = np.where(a >= 0.0, big2, small2)
    return b1sq, b2sq


def _krylov(a: FloatArray, b: FloatArray, z: float) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Fundamental solutions ``C0..C3`` of ``y'''' + a y'' - b y = 0`` at ``z`` (``C_k^(j)(0) = delta_jk``).

    For every root ``lam`` of ``lam**4 + a lam**2 - b`` they give ``exp(lam z) =
    C0 + C1 lam + C2 lam**2 + C3 lam**3``, hence ``expm(A z) = C0 + C1 A + C2 A**2 + C3 A**3``
    for any 4x4 ``A`` with that characteristic polynomial. ``b < 0`` (a shear beam
    above its cut-off) turns ``beta1**2`` negative: the hyperbolic functions of
    ``beta1`` then become trigonometric ones of ``|beta1|`` (the same entire functions).
    """
    b1sq, b2sq = _betas(a, b)
    x = np.sqrt(np.abs(b1sq)) * z
    y = np.sqrt(b2sq) * z
    s = b1sq + b2sq
    pos = s > 0.0
    s_safe = np.where(pos, s, 1.0)
    w1 = np.where(pos, b1sq / s_safe, 0.5)
    w2 = np.where(pos, b2sq / s_safe, 0.5)
    b_over_s = np.where(pos, b / s_safe, 0.0)
    g1, g2 = _sinh_minus_x_over_x3(x), _x_minus_sin_over_x3(y)
    h1, h2 = _cosh_minus_1_over_x2(x), _1_minus_cos_over_y2(y)
    trigonometric = b1sq < 0.0
    if np.any(trigonometric):
        g1 = np.where(trigonometric, _x_minus_sin_over_x3(x), g1)
        h1 = np.where(trigonometric, _1_minus_cos_over_y2(x), h1)
    z2, z3 = z * z, z**3
    C0 = 1.0 + b_over_s * z2 * (h1 - h2)
    C1 = z + b_over_s * z3 * (g1 - g2)
    C2 = z2 * (w1 * h1 + w2 * h2)
    C3 = z3 * (w1 * g1 + w2 * g2)
    return C0, C1, C2, C3


def beam_field_matrix(
    length: float, EI: float, mass_per_length: float, c: FloatArray, w: FloatArray
) -> FloatArray:
    """Exact transfer matrix ``s(l) = H s(0)`` of ``EI U'''' + c U'' - m' w^2 U = 0``.

    Closed form of ``expm(A l)`` with ``A = [[0,1,0,0],[0,0,1/EI,0],[0,-c,0,1],
    [m' w^2,0,0,0]]`` built from the four Krylov functions
    ``C0..C3`` (seed Eqs. 16-20, corrected). Arrays ``c`` and ``w`` share shape (n,).
    """
    z = float(length)
    a = c / EI
    b = mass_per_length * w * w / EI
    C0, C1, C2, C3 = _krylov(a, b, z)
    C1a = C1 - a * C3  # = C2'
    C0a = C0 - a * C2  # = C2''
    # Fundamental matrix of the derivatives d = [U, U', U'', U'''].
    phi = np.empty(np.shape(w) + (4, 4))
    phi[..., 0, :] = np.stack([C0, C1, C2, C3], axis=-1)
    phi[..., 1, :] = np.stack([b * C3, C0, C1a, C2], axis=-1)
    phi[..., 2, :] = np.stack([b * C2, b * C3, C0a, C1a], axis=-1)
    phi[..., 3, :] = np.stack([b * C1a, b * C2, b * C3 - a * C1a, C0a], axis=-1)
    # Physical state s = S d with S = [[1,0,0,0],[0,1,0,0],[0,0,EI,0],[0,c,0,EI]].
    H = np.empty_like(phi)
    H[..., 0, :] = phi[..., 0, :]
    H[..., 1, :] = phi[..., 1, :]
    H[..., 2, :] = EI * phi[..., 2, :]
    H[..., 3, :] = EI * phi[..., 3, :] + c[..., None] * phi[..., 1, :]
    # ... times S^-1 = [[1,0,0,0],[0,1,0,0],[0,0,1/EI,0],[0,-c/EI,0,1/EI]].
    H[..., :, 1] -= (c / EI)[..., None] * H[..., :, 3]
    H[..., :, 2] /= EI
    H[..., :, 3] /= EI
    return H


def shear_beam_field_matrix(
    length: float, EI: float, mass_per_length: float, shear_stiffness: float, c: FloatArray, w: FloatArray
) -> FloatArray:
    """Exact transfer matrix of a spinning Timoshenko beam (shear stiffness ``kappa G A``).

    ``s' = A s`` with ``psi`` the rotation of the cross-section and ``V = -Q``::

        U' = psi - V / (kappa G A),  psi' = M / EI,  M' = V - c psi,  V' = m' w^2 U

    Its characteristic polynomial is ``lam**4 + a lam**2 - b`` with ``a = c/EI + m' w^2 /
    (kappa G A)`` and ``b = m' w^2 (1 - c / (kappa G A)) / EI``, so ``H = expm(A l) =
    C0 + C1 A + C2 A**2 + C3 A**3`` with the Krylov functions of :func:`_krylov`.
    """
    a, b = _shear_wave_coefficients(EI, mass_per_length, shear_stiffness, c, w)
    C = _krylov(a, b, float(length))
    A = np.zeros(np.shape(w) + (4, 4))
    A[..., 0, 1] = 1.0
    A[..., 0, 3] = -1.0 / shear_stiffness
    A[..., 1, 2] = 1.0 / EI
    A[..., 2, 1] = -c
    A[..., 2, 3] = 1.0
    A[..., 3, 0] = mass_per_length * w * w
    H = C[0][..., None, None] * np.eye(4)
    power = np.broadcast_to(np.eye(4), A.shape)
    for Ck in C[1:]:
        power = power @ A
        H = H + Ck[..., None, None] * power
    return H


def _shear_wave_coefficients(
    EI: float, mass_per_length: float, shear_stiffness: float, c: FloatArray, w: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """``a``, ``b`` of ``lam**4 + a lam**2 - b`` for the Timoshenko beam (Rayleigh: ``kappa G A -> inf``)."""
    inertia = mass_per_length * w * w
    return c / EI + inertia / shear_stiffness, inertia * (1.0 - c / shear_stiffness) / EI


def _broadcast(w: ArrayLike, spin: ArrayLike) -> tuple[FloatArray, FloatArray]:
    w_arr, s_arr = np.broadcast_arrays(
        np.atleast_1d(np.asarray(w, dtype=float)), np.atleast_1d(np.asarray(spin, dtype=float))
    )
    return w_arr, s_arr


def _pair(forward: FloatArray, backward: FloatArray) -> FloatArray:
    """Block-diagonal 8x8 matrices ``diag(forward, backward)`` from two (n, 4, 4) stacks."""
    out = np.zeros(forward.shape[:-2] + (8, 8))
    out[..., :4, :4] = forward
    out[..., 4:, 4:] = backward
    return out


def _identity(shape: tuple[int, ...]) -> FloatArray:
    return np.broadcast_to(np.eye(4), shape + (4, 4)).copy()


@dataclass(frozen=True)
class ShaftSegment:
    """Uniform hollow (or solid) shaft segment, Rayleigh beam (seed Fig. 1).

    Parameters are SI: ``length`` [m], ``outer_diameter`` / ``inner_diameter`` [m]
    (inner 0 for a solid shaft), ``youngs_modulus`` [Pa], ``density`` [kg/m3].
    ``rotary_inertia`` and ``gyroscopic`` switch the two Rayleigh terms (both on by
    default; off gives an Euler-Bernoulli beam). ``shear`` adds shear deformation
    (Timoshenko beam) with Cowper's shear coefficient of a hollow circle and
    ``G = E / (2 (1 + poisson_ratio))``.
    """

    length: float
    outer_diameter: float
    inner_diameter: float = 0.0
    youngs_modulus: float = 2.1e11
    density: float = 7850.0
    rotary_inertia: bool = True
    gyroscopic: bool = True
    shear: bool = False
    poisson_ratio: float = 0.3

    def __post_init__(self) -> None:
        _positive("length", self.length)
        _positive("outer_diameter", self.outer_diameter)
        _non_negative("inner_diameter", self.inner_diameter)
        if self.inner_diameter >= self.outer_diameter:
            raise ValueError(
                f"inner_diameter ({self.inner_diameter!r}) must be smaller than "
                f"outer_diameter ({self.outer_diameter!r})"
            )
        _positive("youngs_modulus", self.youngs_modulus)
        _positive("density", self.density)
        if not -1.0 < float(self.poisson_ratio) < 0.5:
            raise ValueError(f"poisson_ratio must lie in (-1, 0.5), got {self.poisson_ratio!r}")

    @property
    def shear_coefficient(self) -> float:
        """Cowper's ``kappa`` of a hollow circle: ``6 (1 + nu) (1 + m^2)^2 / ((7 + 6 nu) (1 + m^2)^2
        + (20 + 12 nu) m^2)``, ``m = D_inner / D_outer`` (``6 (1 + nu) / (7 + 6 nu)`` solid)."""
        nu = self.poisson_ratio
        m2 = (self.inner_diameter / self.outer_diameter) ** 2
        r12 = (1.0 + m2) ** 2
        return 6.0 * (1.0 + nu) * r12 / ((7.0 + 6.0 * nu) * r12 + (20.0 + 12.0 * nu) * m2)

    @property
    def shear_stiffness(self) -> float:
        """``kappa G A`` [N]."""
        return self.shear_coefficient * self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio)) * self.area

    @property
    def area(self) -> float:
        """Cross-section area [m2]."""
        return math.pi / 4.0 * (self.outer_diameter**2 - self.inner_diameter**2)

    @property
    def second_moment(self) -> float:
        """Diametral second moment of area ``J`` of seed Eq. (21) [m4]."""
        return math.pi / 64.0 * (self.outer_diameter**4 - self.inner_diameter**4)

    @property
    def bending_stiffness(self) -> float:
        """``EI`` [N m2]."""
        return self.youngs_modulus * self.second_moment

    @property
    def mass_per_length(self) -> float:
        """``rho A`` [kg/m]."""
        return self.density * self.area

    def _couple(self, w: FloatArray, spin: FloatArray) -> FloatArray:
        """``c = rho I w^2 - rho Ip Omega w`` per unit length, with ``Ip = 2 I``."""
        rI = self.density * self.second_moment
        c = np.zeros_like(w)
        if self.rotary_inertia:
            c = c + rI * w * w
        if self.gyroscopic:
            c = c - 2.0 * rI * spin * w
        return c

    def beta1(self, w: FloatArray, spin: FloatArray) -> FloatArray:
        """Hyperbolic wave number ``beta1`` (seed Eq. 22) [1/m], elementwise."""
        EI = self.bending_stiffness
        if self.shear:
            a, b = _shear_wave_coefficients(EI, self.mass_per_length, self.shear_stiffness, self._couple(w, spin), w)
        else:
            a = self._couple(w, spin) / EI
            b = self.mass_per_length * w * w / EI
        b1sq, _ = _betas(a, b)
        return np.sqrt(np.maximum(b1sq, 0.0))

    def transfer_matrix(self, w: ArrayLike, spin: ArrayLike = 0.0, length: float | None = None) -> FloatArray:
        """Field matrix ``H`` (shape (n, 4, 4)) over ``length`` (default: whole segment)."""
        w_arr, s_arr = _broadcast(w, spin)
        z = self.length if length is None else length
        c = self._couple(w_arr, s_arr)
        if self.shear:
            return shear_beam_field_matrix(z, self.bending_stiffness, self.mass_per_length, self.shear_stiffness, c, w_arr)
        return beam_field_matrix(z, self.bending_stiffness, self.mass_per_length, c, w_arr)

    def transfer_matrix_pair(self, w: ArrayLike, spin: ArrayLike = 0.0, length: float | None = None) -> FloatArray:
        """``diag(H(w), H(-w))`` (shape (n, 8, 8)): the segment is axisymmetric."""
        w_arr, s_arr = _broadcast(w, spin)
        return _pair(self.transfer_matrix(w_arr, s_arr, length), self.transfer_matrix(-w_arr, s_arr, length))

    def fe_matrices(self, n_elements: int) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``K, M, G`` of ``n_elements`` equal beam elements, dofs ``[U, psi]`` per node.

        Cubic Hermite elements (Rayleigh) or, with ``shear``, Timoshenko elements with the
        shear parameter ``phi = 12 EI / (kappa G A h^2)`` (Przemieniecki's stiffness,
        translational and rotary mass matrices; ``phi = 0`` gives the Hermite ones).
        Translational mass ``Mt``, rotary inertia ``Mr`` (if ``rotary_inertia``) and
        gyroscopic ``G = 2 Mr`` (if ``gyroscopic``, ``Ip = 2 I``), each of size
        ``2 (n_elements + 1)``.
        """
        h = self.length / n_elements
        phi = 12.0 * self.bending_stiffness / (self.shear_stiffness * h * h) if self.shear else 0.0
        if phi == 0.0:
            k = self.bending_stiffness / h**3 * np.array(
                [[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                 [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]]
            )
            mt = self.mass_per_length * h / 420 * np.array(
                [[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                 [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]]
            )
            mr = self.density * self.second_moment / (30 * h) * np.array(
                [[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
                 [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]]
            )
        else:
            k, mt, mr = _shear_element(h, phi, self.bending_stiffness, self.mass_per_length,
                                       self.density * self.second_moment)
        m = mt + mr if self.rotary_inertia else mt + 0.0 * mr
        g = 2.0 * mr if self.gyroscopic else 0.0 * mr
        n_dof = 2 * (n_elements + 1)
        K, M, G = np.zeros((n_dof, n_dof)), np.zeros((n_dof, n_dof)), np.zeros((n_dof, n_dof))
        for e in range(n_elements):
            block = slice(2 * e, 2 * e + 4)
            K[block, block] += k
            M[block, block] += m
            G[block, block] += g
        return K, M, G


def _symmetric_element(d11: float, d12: float, d13: float, d14: float, d22: float, d23: float, d24: float
                       ) -> FloatArray:
    """4x4 beam-element matrix on ``[U1, psi1, U2, psi2]`` from its independent entries."""
    return np.array([[d11, d12, d13, d14], [d12, d22, d23, d24], [d13, d23, d11, -d12], [d14, d24, -d12, d22]])


def _shear_element(h: float, phi: float, EI: float, rhoA: float, rhoI: float
                   ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Stiffness, translational and rotary mass matrices of a Timoshenko element of length ``h``."""
    k = EI / ((1 + phi) * h**3) * _symmetric_element(
        12, 6 * h, -12, 6 * h, (4 + phi) * h * h, -6 * h, (2 - phi) * h * h)
    p2 = phi * phi
    mt = rhoA * h / (1 + phi) ** 2 * _symmetric_element(
        13 / 35 + 7 * phi / 10 + p2 / 3,
        (11 / 210 + 11 * phi / 120 + p2 / 24) * h,
        9 / 70 + 3 * phi / 10 + p2 / 6,
        -(13 / 420 + 3 * phi / 40 + p2 / 24) * h,
        (1 / 105 + phi / 60 + p2 / 120) * h * h,
        (13 / 420 + 3 * phi / 40 + p2 / 24) * h,
        -(1 / 140 + phi / 60 + p2 / 120) * h * h,
    )
    mr = rhoI / ((1 + phi) ** 2 * h) * _symmetric_element(
        6 / 5,
        (1 / 10 - phi / 2) * h,
        -6 / 5,
        (1 / 10 - phi / 2) * h,
        (2 / 15 + phi / 6 + p2 / 3) * h * h,
        -(1 / 10 - phi / 2) * h,
        (-1 / 30 - phi / 6 + p2 / 6) * h * h,
    )
    return k, mt, mr


class PointElement(ABC):
    """An element acting at one node: a jump of the state vector across the node.

    Subclasses are frozen dataclasses with a ``node`` field. ``freedoms`` names the
    degrees of freedom the element adds to the rotor (each may add one root to the
    frequency determinant; the root search sizes its grid by them).
    """

    node: int

    @property
    def isotropic(self) -> bool:
        """True when the element acts on each circular whirl component alone."""
        return True

    @property
    def freedoms(self) -> frozenset[str]:
        return frozenset()

    @abstractmethod
    def transfer_matrix(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        """Point matrix for one whirl component at signed ``w`` (shape (n, 4, 4))."""

    def transfer_matrix_pair(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        """Point matrix on ``[s_a, s_b]`` at ``w > 0`` (shape (n, 8, 8)); axisymmetric by default."""
        w_arr, s_arr = _broadcast(w, spin)
        return _pair(self.transfer_matrix(w_arr, s_arr), self.transfer_matrix(-w_arr, s_arr))

    @abstractmethod
    def fe_matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``K, M, G`` (2x2 each) on the dofs ``[U, psi]`` of the element's node.

        An element with ``splits_slope`` gives 3x3 matrices on ``[U, psi_in, psi_out]``:
        the segment to its right then starts from the new slope ``psi_out``.
        """

    splits_slope = False

    def propagate(
        self, Y: FloatArray, w: FloatArray, spin: FloatArray, ratio: FloatArray, pair: bool
    ) -> tuple[FloatArray, FloatArray | None, FloatArray | None]:
        """Carry the basis ``Y`` (n, 4 or 8, columns) of the scaled state across the element.

        Returns ``(Y_after, T, sign)``: the coefficients of the basis before are
        ``T q_after`` (``T = None``: unchanged) and the frequency determinant gains the
        factor ``sign`` (``None``: 1). A point matrix ``P`` gives ``(P Y, None, None)``;
        ``ratio[i, j] = sc_i / sc_j`` scales a physical matrix to the scaled state.
        """
        P = self.transfer_matrix_pair(w, spin) if pair else self.transfer_matrix(w, spin)
        return (P * ratio) @ Y, None, None


@dataclass(frozen=True)
class ConcentratedMass(PointElement):
    """Rigid concentrated mass at station ``node`` (universal joint, bearing carrier).

    ``mass`` [kg], ``polar_inertia`` Jp and ``diametral_inertia`` Jd [kg m2].
    Point matrix (seed Eq. 25, corrected for any Jp/Jd ratio)::

        M+ = M- - (Jd w^2 - Jp Omega w) psi,   V+ = V- + m w^2 U
    """

    node: int
    mass: float
    polar_inertia: float = 0.0
    diametral_inertia: float = 0.0

    def __post_init__(self) -> None:
        _node(self.node)
        _non_negative("mass", self.mass)
        _non_negative("polar_inertia", self.polar_inertia)
        _non_negative("diametral_inertia", self.diametral_inertia)

    @property
    def freedoms(self) -> frozenset[str]:
        """Translation if ``mass > 0``, tilt if either moment of inertia is."""
        out = set()
        if self.mass > 0:
            out.add("translation")
        if self.diametral_inertia > 0 or self.polar_inertia > 0:
            out.add("tilt")
        return frozenset(out)

    def transfer_matrix(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        w_arr, s_arr = _broadcast(w, spin)
        P = _identity(w_arr.shape)
        P[..., 2, 1] = -(self.diametral_inertia * w_arr * w_arr - self.polar_inertia * s_arr * w_arr)
        P[..., 3, 0] = self.mass * w_arr * w_arr
        return P

    def fe_matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        return (np.zeros((2, 2)), np.diag([self.mass, self.diametral_inertia]),
                np.diag([0.0, self.polar_inertia]))


@dataclass(frozen=True)
class Bearing(PointElement):
    """Linear bearing at station ``node``: stiffness ``kxx`` [N/m], ``kyy`` (default ``kxx``) and
    damping ``cxx`` [N s/m], ``cyy`` (default ``cxx``), optionally cross-coupled (``kxy``, ``kyx``,
    ``cxy``, ``cyx``). The force on the shaft is ``-(K [x, y] + C [x', y'])``.

    In the complex coordinate ``u = x + i y`` that force is ``-(k_a u + k_b conj(u)) - (c_a u' +
    c_b conj(u'))`` with :attr:`stiffness_components` ``k_a = (kxx + kyy)/2 + i (kyx - kxy)/2``,
    ``k_b = (kxx - kyy)/2 + i (kyx + kxy)/2`` (the same for ``c``). On a forward component ``a``
    and the conjugate backward component ``conj(b)`` of a whirl at ``w`` the point matrix is::

        V_a -= (k_a + i w c_a) U_a + (k_b + i w c_b) U_b',
        V_b' -= (conj(k_b) + i w conj(c_b)) U_a + (conj(k_a) + i w conj(c_a)) U_b'

    (:meth:`damped_transfer_matrix_pair`, ``b' = conj(b)``). The undamped transfer matrices (seed
    Eq. 27: ``V+ = V- - k U``; ``k_b = dk = (kxx - kyy)/2`` couples the components) take no
    damping, which only the damped analyses (:mod:`driveline.rotor.damped`) see, and no
    cross-coupled stiffness.
    """

    node: int
    kxx: float
    kyy: float | None = None
    cxx: float = 0.0
    cyy: float | None = None
    kxy: float = 0.0
    kyx: float = 0.0
    cxy: float = 0.0
    cyx: float = 0.0

    def __post_init__(self) -> None:
        _node(self.node)
        _non_negative("kxx", self.kxx)
        if self.kyy is not None:
            _non_negative("kyy", self.kyy)
        _non_negative("cxx", self.cxx)
        if self.cyy is not None:
            _non_negative("cyy", self.cyy)
        for name in ("kxy", "kyx", "cxy", "cyx"):
            if not math.isfinite(float(getattr(self, name))):
                raise ValueError(f"{name} must be a finite number, got {getattr(self, name)!r}")

    @property
    def k_yy(self) -> float:
        """Stiffness in y [N/m]."""
        return self.kxx if self.kyy is None else float(self.kyy)

    @property
    def c_yy(self) -> float:
        """Damping in y [N s/m]."""
        return self.cxx if self.cyy is None else float(self.cyy)

    @property
    def isotropic(self) -> bool:
        return self.kyy is None or float(self.kyy) == float(self.kxx)

    @property
    def stiffness_components(self) -> tuple[complex, complex]:
        """``(k_a, k_b)``: the stiffness acting on ``u`` and on ``conj(u)``."""
        return _components(self.kxx, self.k_yy, self.kxy, self.kyx)

    @property
    def damping_components(self) -> tuple[complex, complex]:
        """``(c_a, c_b)``: the damping acting on ``u'`` and on ``conj(u')``."""
        return _components(self.cxx, self.c_yy, self.cxy, self.cyx)

    def _undamped_stiffness(self) -> float:
        if self.kxy != 0.0 or self.kyx != 0.0:
            raise ValueError("cross-coupled bearing stiffness (kxy, kyx) enters the damped analyses only, "
                             "not the undamped transfer matrices")
        return 0.5 * (self.kxx + self.k_yy)

    def transfer_matrix(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        """Point matrix of one whirl component, with the mean stiffness ``kbar``."""
        w_arr, _ = _broadcast(w, spin)
        P = _identity(w_arr.shape)
        P[..., 3, 0] = -self._undamped_stiffness()
        return P

    def transfer_matrix_pair(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        P = super().transfer_matrix_pair(w, spin)
        dk = 0.5 * (self.kxx - self.k_yy)
        P[..., 3, 4] = -dk
        P[..., 7, 0] = -dk
        return P

    def damped_transfer_matrix_pair(self, w: ArrayLike) -> NDArray[np.complex128]:
        """Complex point matrix on ``[s_a, conj(s_b)]`` at the (complex) whirl frequency ``w``, shape (n, 8, 8)."""
        w_arr = np.atleast_1d(np.asarray(w, dtype=complex))
        (ka, kb), (ca, cb) = self.stiffness_components, self.damping_components
        P = np.broadcast_to(np.eye(8, dtype=complex), w_arr.shape + (8, 8)).copy()
        P[..., 3, 0] = -(ka + 1j * w_arr * ca)
        P[..., 3, 4] = -(kb + 1j * w_arr * cb)
        P[..., 7, 0] = -(np.conj(kb) + 1j * w_arr * np.conj(cb))
        P[..., 7, 4] = -(np.conj(ka) + 1j * w_arr * np.conj(ca))
        return P

    def fe_matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The undamped stiffness ``kxx`` (the damped assembly takes the components instead)."""
        if not self.isotropic:
            raise ValueError("the finite-element check covers isotropic bearings only")
        return np.diag([self._undamped_stiffness(), 0.0]), np.zeros((2, 2)), np.zeros((2, 2))


def _components(xx: float, yy: float, xy: float, yx: float) -> tuple[complex, complex]:
    """Coefficients of ``u`` and ``conj(u)`` of the complex force ``f_x + i f_y`` of ``[[xx, xy], [yx, yy]] [x, y]``."""
    return complex(0.5 * (xx + yy), 0.5 * (yx - xy)), complex(0.5 * (xx - yy), 0.5 * (yx + xy))


@dataclass(frozen=True)
class Hinge(PointElement):
    """Joint at an inner ``node`` that transmits no bending moment (universal or tripod joint).

    With ``bending_stiffness`` ``k`` [N m/rad] > 0 it is a rotational spring::

        psi+ = psi- + M / k,    U, M, V continuous,

    and ``k = 0`` (default) is a free hinge, ``M = 0`` at the joint with a free slope
    jump. Masses and bearings at the same node act on its left side. The frequency
    determinant carries the factor ``k**r`` (``r`` = 1 whirl component, 2 in the
    anisotropic state), so that it stays an entire function of ``w`` down to ``k = 0``
    (see :meth:`propagate`).
    """

    node: int
    bending_stiffness: float = 0.0

    splits_slope = True

    def __post_init__(self) -> None:
        _node(self.node)
        _non_negative("bending_stiffness", self.bending_stiffness)

    @property
    def freedoms(self) -> frozenset[str]:
        """The relative tilt of the two sides."""
        return frozenset({"hinge"})

    def transfer_matrix(self, w: ArrayLike, spin: ArrayLike = 0.0) -> FloatArray:
        """Point matrix ``psi+ = psi- + M / k``; a free hinge (``k = 0``) has none."""
        if self.bending_stiffness == 0.0:
            raise ValueError("a free hinge has no transfer matrix: the propagation applies M = 0 instead")
        w_arr, _ = _broadcast(w, spin)
        P = _identity(w_arr.shape)
        P[..., 1, 2] = 1.0 / self.bending_stiffness
        return P

    def fe_matrices(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """A rotational spring ``k`` between ``psi_in`` and ``psi_out`` (3x3 on ``[U, psi_in, psi_out]``)."""
        k = self.bending_stiffness
        K = np.array([[0.0, 0.0, 0.0], [0.0, k, -k], [0.0, -k, k]])
        return K, np.zeros((3, 3)), np.zeros((3, 3))

    def propagate(
        self, Y: FloatArray, w: FloatArray, spin: FloatArray, ratio: FloatArray, pair: bool
    ) -> tuple[FloatArray, FloatArray | None, FloatArray | None]:
        """New basis ``Y_after = P Y T`` scaled by ``k``, finite down to ``k = 0``.

        With ``m = Y[M rows]`` (r x c) and the full QR ``m^T = [Q1 Q2] [R1; 0]``:
        ``T = [Q2, k Q1]`` gives ``P Y T = [Y Q2, k Y Q1 + E R1^T]`` (``E``: the slope
        rows), in which ``k`` only multiplies. ``Y Q2`` are the states with ``M = 0``
        at the joint, ``E R1^T`` the slope jumps. ``det T = k**r det[Q2 Q1]``, and
        ``det[Q2 Q1] = +-1`` is returned as the sign; ``k**r`` is left in the determinant.
        """
        components = (0, 4) if pair else (0,)
        moment_rows = [c + 2 for c in components]
        slope_rows = [c + 1 for c in components]
        r, cols = len(components), Y.shape[-1]
        k = self.bending_stiffness / ratio[1, 2]  # scaled: psi~ jumps by M~ ratio[1, 2] / k
        Q, R = np.linalg.qr(np.swapaxes(Y[:, moment_rows, :], 1, 2), mode="complete")
        T = np.concatenate([Q[:, :, r:], k * Q[:, :, :r]], axis=2)
        Y_after = Y @ T
        for i, row in enumerate(slope_rows):
            Y_after[:, row, cols - r:] += R[:, :r, i]
        sign = np.sign(np.linalg.det(Q)) * (-1.0) ** (r * (cols - r))
        return Y_after, T, sign


@dataclass(frozen=True)
class Unbalance:
    """Unbalance ``amount`` = mass x eccentricity [kg m] at ``position`` [m from the left end], at the
    angle ``phase`` [rad] from the x axis at time 0: the rotating force ``amount Omega^2 exp(i (Omega t +
    phase))`` on the shaft."""

    position: float
    amount: float
    phase: float = 0.0

    def __post_init__(self) -> None:
        _non_negative("position", self.position)
        _non_negative("amount", self.amount)
        if not math.isfinite(float(self.phase)):
            raise ValueError(f"phase must be a finite angle in rad, got {self.phase!r}")
