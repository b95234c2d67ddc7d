"""TOML driveline descriptions and the one-piece propshaft constructor.

File layout (SI units; all tables except ``segments`` optional)::

    name = "two-piece propshaft"
    left_end = "free"            # free | pinned | clamped
    right_end = "free"

    [materials.steel]
    youngs_modulus = 2.1e11      # Pa
    density = 7850.0             # kg/m3

    [[segments]]                 # in axial order, node k is the start of segment k
    length = 0.7                 # m
    outer_diameter = 0.0762      # m   (or outer_radius)
    wall_thickness = 0.00165     # m   (or inner_diameter / inner_radius; default solid)
    material = "steel"           # or youngs_modulus and density in the segment
    # rotary_inertia = true, gyroscopic = true
    # shear = true, poisson_ratio = 0.3  (Timoshenko beam, Cowper's shear coefficient;
    #                                     shear = false: Rayleigh beam)

    [[masses]]
    node = 0
    mass = 2.5                   # kg
    polar_inertia = 0.004        # kg m2
    diametral_inertia = 0.002    # kg m2

    [[bearings]]
    node = 0
    stiffness = 1.0e7            # N/m, isotropic; or kxx and kyy
    # damping = 500.0            # N s/m, isotropic; or cxx and cyy (default: undamped)
    # kxy = 0.0, kyx = 0.0, cxy = 0.0, cyx = 0.0   cross-coupling (damped analyses only)

    [[unbalances]]               # excitation of the unbalance response
    position = 0.7               # m from the left end (or node)
    amount = 1.0e-4              # kg m (mass x eccentricity)
    # phase = 0.0                # rad

    [[hinges]]                   # moment-free joint at an inner node (universal, tripod)
    position = 0.8               # m from the left end, instead of a node: the loader cuts the
                                 # segment there (masses and bearings too)
    # bending_stiffness = 0.0    # N m/rad; > 0 makes it a rotational spring

Every problem raises :class:`ValueError` naming the table, entry and key. A description is
read only from a regular file of at most :data:`MAX_FILE_BYTES` (a FIFO, a device or a
directory is refused without reading from it), nests at most :data:`MAX_NESTING` brackets
deep and has at most :data:`MAX_SEGMENTS` segments and :data:`MAX_POINT_ELEMENTS` masses,
bearings, hinges and unbalances each: bounds on the work and memory a description can demand.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from pathlib import Path
from typing import Any

from ..layout_files import MAX_FILE_BYTES, MAX_NESTING, counted as _counted, number as _number, parse, read_layout
from ..layout_files import shipped_path, unknown as _unknown
from .driveline import Driveline
from .elements import Bearing, ConcentratedMass, EndCondition, Hinge, ShaftSegment, Unbalance

__all__ = ["example_path", "load_driveline", "loads_driveline", "one_piece_shaft"]

#: Segments of one description; the analysis cost grows with their number.
MAX_SEGMENTS = 100
#: Masses, bearings, hinges and unbalances of one description, each.
MAX_POINT_ELEMENTS = 2 * (MAX_SEGMENTS + 1)

_TOP_KEYS = {"name", "left_end", "right_end", "materials", "segments", "masses", "bearings", "hinges", "unbalances"}
_MATERIAL_KEYS = {"youngs_modulus", "density"}
_SEGMENT_KEYS = {
    "length", "outer_diameter", "outer_radius", "inner_diameter", "inner_radius",
    "wall_thickness", "material", "youngs_modulus", "density", "rotary_inertia",
    "gyroscopic", "shear", "poisson_ratio", "label",
}
_MASS_KEYS = {"node", "position", "mass", "polar_inertia", "diametral_inertia", "label"}
_BEARING_KEYS = {"node", "position", "stiffness", "kxx", "kyy", "damping", "cxx", "cyy",
                 "kxy", "kyx", "cxy", "cyx", "label"}
_CROSS_KEYS = ("kxy", "kyx", "cxy", "cyx")
_UNBALANCE_KEYS = {"node", "position", "amount", "phase", "label"}
_HINGE_KEYS = {"node", "position", "bending_stiffness", "label"}


def _node(where: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise ValueError(f"{where}.node must be an integer >= 0, got {value!r}")
    return value


def _flag(where: str, key: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ValueError(f"{where}.{key} must be true or false, got {value!r}")
    return value


def _materials(data: dict[str, Any]) -> dict[str, tuple[float, float]]:
    mats = data.get("materials", {})
    if not isinstance(mats, dict):
        raise ValueError("materials must be a table of named materials ([materials.NAME])")
    out = {}
    for name, t in mats.items():
        where = f"materials.{name}"
        if not isinstance(t, dict):
            raise ValueError(f"{where} must be a table")
        _unknown(where, t, _MATERIAL_KEYS)
        for k in sorted(_MATERIAL_KEYS):
            if k not in t:
                raise ValueError(f"{where}: missing key {k!r}")
        out[name] = (
            _number(where, "youngs_modulus", t["youngs_modulus"], positive=True),
            _number(where, "density", t["density"], positive=True),
        )
    return out


def _segment(i: int, t: dict[str, Any], mats: dict[str, tuple[float, float]]) -> ShaftSegment:
    where = f"segments[{i}]"
    _unknown(where, t, _SEGMENT_KEYS)
    if "length" not in t:
        raise ValueError(f"{where}: missing key 'length'")
    length = _number(where, "length", t["length"], positive=True)
    outer = [k for k in ("outer_diameter", "outer_radius") if k in t]
    if len(outer) != 1:
        raise ValueError(f"{where}: give exactly one of 'outer_diameter' or 'outer_radius'")
    d_out = _number(where, outer[0], t[outer[0]], positive=True) * (2.0 if outer[0] == "outer_radius" else 1.0)
    inner = [k for k in ("inner_diameter", "inner_radius", "wall_thickness") if k in t]
    if len(inner) > 1:
        raise ValueError(f"{where}: give at most one of 'inner_diameter', 'inner_radius', 'wall_thickness'")
    d_in = 0.0
    if inner:
        key = inner[0]
        v = _number(where, key, t[key])
        if key == "wall_thickness":
            if v <= 0.0:
                raise ValueError(f"{where}.wall_thickness must be > 0, got {t[key]!r}")
            if 2.0 * v > d_out:
                raise ValueError(
                    f"{where}.wall_thickness = {t[key]!r} exceeds half the outer diameter ({d_out / 2!r})"
                )
            d_in = max(d_out - 2.0 * v, 0.0)
        else:
            d_in = v * (2.0 if key == "inner_radius" else 1.0)
            if d_in >= d_out:
                raise ValueError(
                    f"{where}.{key} = {t[key]!r} must be smaller than the outer size "
                    f"({outer[0]} = {t[outer[0]]!r})"
                )
    E = rho = None
    if "material" in t:
        name = t["material"]
        if not isinstance(name, str) or name not in mats:
            known = ", ".join(sorted(mats)) or "none defined"
            raise ValueError(f"{where}.material {name!r} is not a defined material ({known})")
        E, rho = mats[name]
    if "youngs_modulus" in t:
        E = _number(where, "youngs_modulus", t["youngs_modulus"], positive=True)
    if "density" in t:
        rho = _number(where, "density", t["density"], positive=True)
    for key, v in (("youngs_modulus", E), ("density", rho)):
        if v is None:
            raise ValueError(f"{where}: missing key {key!r} (or a 'material')")
    flags = {"shear": True} | {k: _flag(where, k, t[k]) for k in ("rotary_inertia", "gyroscopic", "shear") if k in t}
    if "poisson_ratio" in t:
        nu = t["poisson_ratio"]
        if isinstance(nu, bool) or not isinstance(nu, (int, float)) or not -1.0 < nu < 0.5:
            raise ValueError(f"{where}.poisson_ratio must be a number in (-1, 0.5), got {nu!r}")
        flags["poisson_ratio"] = float(nu)
    return ShaftSegment(length, d_out, d_in, E, rho, **flags)


#: A position closer than this to a node [m] is that node (no sliver segment is cut).
NODE_SNAP = 1e-9


def _station(where: str, t: dict[str, Any], n_nodes: int) -> tuple[str, float]:
    """``("node", k)`` or ``("position", z)`` of a point-element table (exactly one is given)."""
    if ("node" in t) == ("position" in t):
        raise ValueError(f"{where}: give exactly one of 'node' or 'position'")
    if "node" in t:
        node = _node(where, t["node"])
        if node >= n_nodes:
            raise ValueError(f"{where}.node = {node} is out of range: nodes are 0..{n_nodes - 1}")
        return "node", node
    return "position", _number(where, "position", t["position"])


def _cut(segments: list[ShaftSegment], stations: dict[str, list[tuple[str, float]]]
         ) -> tuple[list[ShaftSegment], dict[str, list[int]]]:
    """Split the segments at every position that is not a node; return them and every table's node."""
    ends = [0.0]
    for seg in segments:
        ends.append(ends[-1] + seg.length)
    cuts: list[set[float]] = [set() for _ in segments]
    for kind, entries in stations.items():
        for i, (how, value) in enumerate(entries):
            if how != "position":
                continue
            if value > ends[-1] + NODE_SNAP:
                raise ValueError(f"{kind}[{i}].position = {value!r} m lies beyond the right end ({ends[-1]!r} m)")
            k = min(range(len(segments)), key=lambda j: 0.0 if ends[j] <= value <= ends[j + 1] else math.inf)
            if min(value - ends[k], ends[k + 1] - value) > NODE_SNAP:
                cuts[k].add(value)
    new_segments: list[ShaftSegment] = []
    node_of_old, new_ends = [0], [0.0]
    for seg, start, stop, inner in zip(segments, ends, ends[1:], cuts):
        points = [start, *sorted(inner), stop]
        for left, right in zip(points, points[1:]):
            new_segments.append(seg if not inner else dataclasses.replace(seg, length=right - left))
            new_ends.append(right)
        node_of_old.append(len(new_segments))
    nodes: dict[str, list[int]] = {}
    for kind, entries in stations.items():
        nodes[kind] = [
            node_of_old[int(value)] if how == "node"
            else min(range(len(new_ends)), key=lambda j: abs(new_ends[j] - value))
            for how, value in entries
        ]
    return new_segments, nodes


def _mass(i: int, t: dict[str, Any], node: int) -> ConcentratedMass:
    where = f"masses[{i}]"
    _unknown(where, t, _MASS_KEYS)
    if "mass" not in t:
        raise ValueError(f"{where}: missing key 'mass'")
    return ConcentratedMass(
        node,
        _number(where, "mass", t["mass"]),
        _number(where, "polar_inertia", t.get("polar_inertia", 0.0)),
        _number(where, "diametral_inertia", t.get("diametral_inertia", 0.0)),
    )


def _pair(where: str, t: dict[str, Any], key: str, xx: str, yy: str, positive: bool) -> tuple[float, float | None]:
    """``(xx, yy)`` of a bearing from the isotropic ``key`` or from ``xx`` [+ ``yy``]."""
    if key in t:
        if xx in t or yy in t:
            raise ValueError(f"{where}: give either {key!r} or {xx!r}/{yy!r}, not both")
        return _number(where, key, t[key], positive=positive), None
    if xx not in t:
        if positive:
            raise ValueError(f"{where}: missing key {key!r} (or {xx!r})")
        if yy in t:
            raise ValueError(f"{where}: {yy!r} needs {xx!r}")
        return 0.0, None
    return (_number(where, xx, t[xx], positive=positive),
            _number(where, yy, t[yy], positive=positive) if yy in t else None)


def _bearing(i: int, t: dict[str, Any], node: int) -> Bearing:
    where = f"bearings[{i}]"
    _unknown(where, t, _BEARING_KEYS)
    kxx, kyy = _pair(where, t, "stiffness", "kxx", "kyy", positive=True)
    cxx, cyy = _pair(where, t, "damping", "cxx", "cyy", positive=False)
    cross = {k: _number(where, k, t[k], signed=True) for k in _CROSS_KEYS if k in t}
    return Bearing(node, kxx, kyy, cxx, cyy, **cross)


def _unbalance(i: int, t: dict[str, Any], ends: list[float]) -> Unbalance:
    where = f"unbalances[{i}]"
    _unknown(where, t, _UNBALANCE_KEYS)
    how, value = _station(where, t, len(ends))
    position = ends[int(value)] if how == "node" else value
    if position > ends[-1] + NODE_SNAP:
        raise ValueError(f"{where}.position = {value!r} m lies beyond the right end ({ends[-1]!r} m)")
    if "amount" not in t:
        raise ValueError(f"{where}: missing key 'amount'")
    return Unbalance(min(position, ends[-1]), _number(where, "amount", t["amount"]),
                     _number(where, "phase", t.get("phase", 0.0), signed=True))


def _hinge(i: int, t: dict[str, Any], node: int, n_nodes: int) -> Hinge:
    where = f"hinges[{i}]"
    _unknown(where, t, _HINGE_KEYS)
    if not 0 < node < n_nodes - 1:
        at = f"node = {t['node']}" if "node" in t else f"position = {t['position']!r} m"
        raise ValueError(f"{where}.{at} must be an inner node (1..{n_nodes - 2}), not an end")
    return Hinge(node, _number(where, "bending_stiffness", t.get("bending_stiffness", 0.0)))


def loads_driveline(text: str, source: str = "<string>") -> Driveline:
    """Build a :class:`Driveline` from TOML text (see the module docstring for the layout)."""
    data = parse(text, source)
    _unknown(source, data, _TOP_KEYS)
    name = data.get("name", "")
    if not isinstance(name, str):
        raise ValueError(f"{source}: name must be a string, got {name!r}")
    conditions = []
    for key in ("left_end", "right_end"):
        v = data.get(key, "free")
        allowed = [e.value for e in EndCondition]
        if v not in allowed:
            raise ValueError(f"{key} = {v!r} is not one of: {', '.join(allowed)}")
        conditions.append(EndCondition(v))
    left, right = conditions
    mats = _materials(data)
    seg_tables = _counted(data, "segments", MAX_SEGMENTS)
    if not seg_tables:
        raise ValueError(f"{source}: at least one [[segments]] table is required")
    segments = [_segment(i, t, mats) for i, t in enumerate(seg_tables)]
    ends = [0.0, *itertools.accumulate(seg.length for seg in segments)]
    unbalances = [_unbalance(i, t, ends) for i, t in enumerate(_counted(data, "unbalances", MAX_POINT_ELEMENTS))]
    tables = {kind: _counted(data, kind, MAX_POINT_ELEMENTS) for kind in ("masses", "bearings", "hinges")}
    stations = {kind: [_station(f"{kind}[{i}]", t, len(segments) + 1) for i, t in enumerate(items)]
                for kind, items in tables.items()}
    segments, nodes = _cut(segments, stations)
    masses = [_mass(i, t, node) for i, (t, node) in enumerate(zip(tables["masses"], nodes["masses"]))]
    bearings = [_bearing(i, t, node) for i, (t, node) in enumerate(zip(tables["bearings"], nodes["bearings"]))]
    hinges = [_hinge(i, t, node, len(segments) + 1)
              for i, (t, node) in enumerate(zip(tables["hinges"], nodes["hinges"]))]
    return Driveline(segments, masses, bearings, left, right, name, hinges, unbalances)


def load_driveline(path: str | Path) -> Driveline:
    """Read a TOML driveline description from ``path`` (relative: to the working directory).

    Messages name the file by its absolute path."""
    return read_layout(path, "driveline file", loads_driveline)


def example_path(name: str = "two_piece_propshaft") -> Path:
    """Path of a shipped example description (``data/<name>.toml``)."""
    return shipped_path(__package__, name, "example")


def one_piece_shaft(
    L_shaft: float,
    D_outer: float,
    D_inner: float,
    E: float,
    density: float,
    m_joint: float,
    Jp_joint: float,
    Jd_joint: float,
    k_bearing: float,
    c_bearing: float = 0.0,
    shear: bool = True,
) -> Driveline:
    """One-piece tube propshaft: a joint mass and an isotropic bearing at each end.

    SI units: lengths [m], ``E`` [Pa], ``density`` [kg/m3], ``m_joint`` [kg],
    ``Jp_joint``/``Jd_joint`` [kg m2], ``k_bearing`` [N/m], ``c_bearing`` [N s/m]; free ends
    (the bearings carry the shaft, as in the seed's Fig. 2); a Timoshenko tube unless ``shear``
    is false (Rayleigh). Errors name the offending parameter.
    """
    vals = {
        "L_shaft": L_shaft, "D_outer": D_outer, "D_inner": D_inner, "E": E, "density": density,
        "m_joint": m_joint, "Jp_joint": Jp_joint, "Jd_joint": Jd_joint, "k_bearing": k_bearing,
        "c_bearing": c_bearing,
    }
    for k, v in vals.items():
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(float(v)):
            raise ValueError(f"{k} must be a finite number, got {v!r}")
    for k in ("L_shaft", "D_outer", "E", "density", "k_bearing"):
        if vals[k] <= 0.0:
            raise ValueError(f"{k} must be > 0, got {vals[k]!r}")
    for k in ("D_inner", "m_joint", "Jp_joint", "Jd_joint", "c_bearing"):
        if vals[k] < 0.0:
            raise ValueError(f"{k} must be >= 0, got {vals[k]!r}")
    if D_inner >= D_outer:
        raise ValueError(f"D_inner ({D_inner!r}) must be smaller than D_outer ({D_outer!r})")
    seg = ShaftSegment(float(L_shaft), float(D_outer), float(D_inner), float(E), float(density), shear=bool(shear))
    masses = [ConcentratedMass(n, float(m_joint), float(Jp_joint), float(Jd_joint)) for n in (0, 1)]
    bearings = [Bearing(n, float(k_bearing), cxx=float(c_bearing)) for n in (0, 1)]
    return Driveline([seg], masses, bearings, EndCondition.FREE, EndCondition.FREE, "one-piece propshaft")
