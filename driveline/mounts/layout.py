"""TOML layouts of a powertrain on its mounts (read with :mod:`driveline.layout_files`).

File layout (SI units, ISO 8855 vehicle axes: x forward, y left, z up)::

    name = "transverse front-wheel-drive powertrain"
    mass = 200.0                           # kg
    centre_of_gravity = [0.12, -0.05, 0.15]  # m
    inertia = [11.0, 8.0, 10.0, 0.3, 1.0, 0.4]  # kg m2: Ixx, Iyy, Izz, Ixy, Ixz, Iyz about the CG
    # loss_factor_frequency = 12.0         # Hz, needed when a mount gives a loss factor

    [[mounts]]                             # 1 to MAX_MOUNTS of them
    label = "engine mount"                 # optional
    position = [0.15, -0.45, 0.33]         # m
    stiffness = [1.5e5, 1.0e5, 2.5e5]      # N/m along the mount's axes 1, 2, 3
    # orientation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]  rows: the mount's axes 1, 2, 3 in vehicle
    #                                                  axes (a rotation; default aligned)
    # damping = [150.0, 100.0, 250.0]      # N s/m along the mount's axes (default none), or
    # loss_factor = 0.1                    # c_i = loss_factor k_i / (2 pi loss_factor_frequency), or with
    # dynamic_ratio = 1.4                  # rubber's constant loss factor in (0, 1) by Maxwell branches
    #                                      # (:mod:`.rubber`), no loss_factor_frequency needed
    # gap = [0.004, 0.004, 0.003]          # m, snubber gap along each axis (both ways), with
    # stop_rate = [1e6, 1e6, 1e6]          # N/m, the rate the stop adds beyond it, and
    # stop_blend = 0.002                   # m, the length over which it builds up (default STOP_BLEND);
    #                                      # the law: :mod:`.characteristic`

Products of inertia are the integrals ``Ixy = int x y dm`` (positive for mass in the first
quadrant): the inertia tensor about the centre of gravity is
``[[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]]``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from ..layout_files import counted, number, parse, read_layout, shipped_path, unknown
from .rubber import fit_branches, fit_error

__all__ = ["Layout", "Mount", "load_layout", "loads_layout", "shipped_layout"]

#: Mounts of one layout.
MAX_MOUNTS = 8
#: How far ``orientation`` may be from a rotation: ``max |R R^T - I|`` and ``|det R - 1|``.
ROTATION_TOLERANCE = 1e-9

_TOP_KEYS = {"name", "mass", "centre_of_gravity", "inertia", "loss_factor_frequency", "mounts"}
_MOUNT_KEYS = {"label", "position", "stiffness", "orientation", "damping", "loss_factor", "dynamic_ratio", "gap",
               "stop_rate", "stop_blend"}
#: The blend length of a stop that gives none [m].
STOP_BLEND = 0.002


@dataclass(frozen=True)
class Mount:
    """A rubber mount: ``axes`` (rows: its axes 1, 2, 3 in vehicle axes), the linear rate
    (``stiffness`` [N/m]) and viscous damping [N s/m] along each; a snubber along each (``gap`` [m],
    ``stop_rate`` [N/m], ``stop_blend`` [m]: :mod:`.characteristic`; ``stop_rate`` 0: none); the
    Maxwell branches' weights (``branches``, relative to the linear rate, :mod:`.rubber`; empty:
    none)."""

    position: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    axes: np.ndarray
    label: str = ""
    gap: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stop_rate: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stop_blend: float = STOP_BLEND
    branches: np.ndarray = field(default_factory=lambda: np.zeros(0))

    @property
    def progressive(self) -> bool:
        """Whether a stop makes the characteristic nonlinear."""
        return bool(np.any(self.stop_rate != 0.0))


@dataclass(frozen=True)
class Layout:
    """A rigid powertrain: mass [kg], centre of gravity [m], inertia tensor about it [kg m^2], mounts."""

    mass: float
    centre_of_gravity: np.ndarray
    inertia: np.ndarray
    mounts: tuple[Mount, ...]
    name: str = ""

    @cached_property
    def maps(self) -> tuple[np.ndarray, ...]:
        """Each mount's ``A_i T(p_i)`` (3 x 6): the deflections along its axes from ``q``."""
        return tuple(m.axes @ point_map(m.position, self.centre_of_gravity) for m in self.mounts)


def cross_matrix(a: np.ndarray) -> np.ndarray:
    """``[a]x``: ``cross_matrix(a) @ b == np.cross(a, b)``."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def point_map(point: np.ndarray, centre: np.ndarray) -> np.ndarray:
    """``T(p)`` (3 x 6): the displacement of the body point ``point`` from ``q``."""
    return np.hstack([np.eye(3), -cross_matrix(np.asarray(point) - centre)])


def inertia_tensor(Ixx: float, Iyy: float, Izz: float, Ixy: float, Ixz: float, Iyz: float) -> np.ndarray:
    """The tensor of moments and products of inertia (products with the minus sign off the diagonal)."""
    return np.array([[Ixx, -Ixy, -Ixz], [-Ixy, Iyy, -Iyz], [-Ixz, -Iyz, Izz]])


def _vector(where: str, key: str, value: Any, **kind: bool) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3:
        raise ValueError(f"{where}.{key} must be an array of 3 numbers, got {value!r}")
    return np.array([number(where, f"{key}[{i}]", v, **kind) for i, v in enumerate(value)])


def _orientation(where: str, value: Any) -> np.ndarray:
    if not isinstance(value, list) or len(value) != 3:
        raise ValueError(f"{where}.orientation must be an array of 3 rows of 3 numbers, got {value!r}")
    axes = np.array([_vector(where, f"orientation[{i}]", row, signed=True) for i, row in enumerate(value)])
    deviation = float(np.max(np.abs(axes @ axes.T - np.eye(3))))
    if not (deviation <= ROTATION_TOLERANCE and abs(np.linalg.det(axes) - 1.0) <= ROTATION_TOLERANCE):
        raise ValueError(f"{where}.orientation is not a rotation: its rows must be orthonormal and right-handed "
                         f"(|R R^T - I| = {deviation:.3g}, det R = {np.linalg.det(axes):.6g})")
    return axes


def _mount(i: int, t: dict[str, Any], loss_frequency: float | None) -> Mount:
    where = f"mounts[{i}]"
    unknown(where, t, _MOUNT_KEYS)
    for key in ("position", "stiffness"):
        if key not in t:
            raise ValueError(f"{where}: missing key {key!r}")
    stiffness = _vector(where, "stiffness", t["stiffness"])
    if "damping" in t and "loss_factor" in t:
        raise ValueError(f"{where}: give either 'damping' or 'loss_factor', not both")
    branches = np.zeros(0)
    if "dynamic_ratio" in t:
        branches = _branches(where, t)
        damping = np.zeros(3)
    elif "loss_factor" in t:
        if loss_frequency is None:
            raise ValueError(f"{where}.loss_factor needs the top-level key 'loss_factor_frequency'")
        damping = number(where, "loss_factor", t["loss_factor"]) * stiffness / (2.0 * math.pi * loss_frequency)
    else:
        damping = _vector(where, "damping", t["damping"]) if "damping" in t else np.zeros(3)
    label = t.get("label", "")
    if not isinstance(label, str):
        raise ValueError(f"{where}.label must be a string, got {label!r}")
    axes = _orientation(where, t["orientation"]) if "orientation" in t else np.eye(3)
    gap, stop_rate, blend = _stop(where, t, stiffness)
    return Mount(_vector(where, "position", t["position"], signed=True), stiffness, damping, axes, label,
                 gap, stop_rate, blend, branches)


def _branches(where: str, t: dict[str, Any]) -> np.ndarray:
    """The Maxwell weights of a mount's ``loss_factor`` in (0, 1) and ``dynamic_ratio`` >= 1."""
    if "loss_factor" not in t:
        raise ValueError(f"{where}.dynamic_ratio needs the key 'loss_factor' (the loss factor its branches fit)")
    eta = number(where, "loss_factor", t["loss_factor"])
    if not 0.0 < eta < 1.0:
        raise ValueError(f"{where}.loss_factor must lie in (0, 1) for rubber damping, got {t['loss_factor']!r}")
    ratio = number(where, "dynamic_ratio", t["dynamic_ratio"])
    if not ratio >= 1.0:
        raise ValueError(f"{where}.dynamic_ratio must be >= 1 (dynamic over static rate), got {t['dynamic_ratio']!r}")
    fit = fit_branches(eta, ratio)
    reason = fit_error(where, fit, eta, ratio)
    if reason is not None:
        raise ValueError(reason)
    return fit.weights


def _stop(where: str, t: dict[str, Any], stiffness: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """A mount's snubber: ``gap`` >= 0 and ``stop_rate`` given together, the characteristic monotonic."""
    given = [key for key in ("gap", "stop_rate") if key in t]
    if len(given) == 1:
        other = "stop_rate" if given[0] == "gap" else "gap"
        raise ValueError(f"{where}.{given[0]} needs the key {other!r} (a snubber has both)")
    blend = number(where, "stop_blend", t["stop_blend"], positive=True) if "stop_blend" in t else STOP_BLEND
    if not given:
        return np.zeros(3), np.zeros(3), blend
    gap = _vector(where, "gap", t["gap"])
    stop_rate = _vector(where, "stop_rate", t["stop_rate"], signed=True)
    for k in range(3):
        if stiffness[k] + stop_rate[k] < 0.0:
            raise ValueError(f"{where}.stop_rate[{k}] {float(stop_rate[k])!r} makes the characteristic not monotonic: "
                             f"stiffness[{k}] + stop_rate[{k}] = {float(stiffness[k] + stop_rate[k])!r} < 0 beyond "
                             "the gap")
    return gap, stop_rate, blend


def loads_layout(text: str, source: str = "<string>") -> Layout:
    """Build a :class:`Layout` from TOML text (see the module docstring)."""
    data = parse(text, source)
    unknown(source, data, _TOP_KEYS)
    for key in ("mass", "centre_of_gravity", "inertia"):
        if key not in data:
            raise ValueError(f"{source}: missing key {key!r}")
    name = data.get("name", "")
    if not isinstance(name, str):
        raise ValueError(f"{source}: name must be a string, got {name!r}")
    mass = number(source, "mass", data["mass"], positive=True)
    inertia = data["inertia"]
    if not isinstance(inertia, list) or len(inertia) != 6:
        raise ValueError(f"{source}: inertia must be an array of 6 numbers [Ixx, Iyy, Izz, Ixy, Ixz, Iyz], "
                         f"got {inertia!r}")
    values = [number(source, f"inertia[{i}]", v, signed=True) for i, v in enumerate(inertia)]
    tensor = inertia_tensor(*values)
    if not np.all(np.linalg.eigvalsh(tensor) > 0.0):
        raise ValueError(f"{source}: inertia {values!r} is not positive definite (principal moments "
                         f"{', '.join(f'{v:.6g}' for v in np.linalg.eigvalsh(tensor))} kg m2)")
    loss_frequency = (number(source, "loss_factor_frequency", data["loss_factor_frequency"], positive=True)
                      if "loss_factor_frequency" in data else None)
    tables = counted(data, "mounts", MAX_MOUNTS)
    if not tables:
        raise ValueError(f"{source}: at least one [[mounts]] table is required")
    mounts = tuple(_mount(i, t, loss_frequency) for i, t in enumerate(tables))
    return Layout(mass, _vector(source, "centre_of_gravity", data["centre_of_gravity"], signed=True), tensor,
                  mounts, name)


def load_layout(path: str | Path) -> Layout:
    """Read a layout from ``path`` (relative: to the working directory); messages name the file."""
    return read_layout(path, "layout file", loads_layout)


def shipped_layout(name: str) -> Path:
    """Path of a layout shipped with the model (``data/<name>.toml``)."""
    return shipped_path(__package__, name, "layout")
