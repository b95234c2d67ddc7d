"""Reading layout descriptions (TOML) safely: the rules every model's layout files share.

A description is read only from a regular file of at most :data:`MAX_FILE_BYTES` (a FIFO, a
device or a directory is refused without reading from it) and nests at most :data:`MAX_NESTING`
brackets deep: bounds on the work and memory a file can demand. Every problem raises
:class:`ValueError` naming the file, table, entry and key. The CriticalSpeeds layouts
(:mod:`driveline.rotor.loader`) and the PowertrainMounts layouts (:mod:`driveline.mounts.layout`)
are read with these functions.
"""

from __future__ import annotations

import math
import os
import re
import stat
from importlib import resources
from pathlib import Path
from typing import Any

import tomllib

#: A description of the largest layout accepted is a few kilobytes.
MAX_FILE_BYTES = 64 * 1024
#: Brackets open at once (arrays, inline tables, table headers count one level each).
MAX_NESTING = 16


def unknown(where: str, table: dict[str, Any], allowed: set[str]) -> None:
    """Refuse a key of ``table`` that is not ``allowed``, naming it and the allowed ones."""
    extra = sorted(set(table) - allowed)
    if extra:
        raise ValueError(f"{where}: unknown key {extra[0]!r} (allowed: {', '.join(sorted(allowed))})")


def number(where: str, key: str, value: Any, *, positive: bool = False, signed: bool = False) -> float:
    """``value`` as a finite float, > 0 if ``positive``, >= 0 unless ``signed``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ValueError(f"{where}.{key} must be a number, got {value!r}")
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{where}.{key} must be finite, got {value!r}")
    if positive and v <= 0.0:
        raise ValueError(f"{where}.{key} must be > 0, got {value!r}")
    if v < 0.0 and not signed:
        raise ValueError(f"{where}.{key} must be >= 0, got {value!r}")
    return v


def table_list(data: dict[str, Any], key: str) -> list[dict[str, Any]]:
    """The array of tables ``[[key]]`` (empty when absent)."""
    items = data.get(key, [])
    if not isinstance(items, list) or not all(isinstance(t, dict) for t in items):
        raise ValueError(f"{key} must be an array of tables ([[{key}]])")
    return items


def counted(data: dict[str, Any], key: str, limit: int) -> list[dict[str, Any]]:
    """:func:`table_list`, refused beyond ``limit`` tables."""
    items = table_list(data, key)
    if len(items) > limit:
        raise ValueError(f"{len(items)} [[{key}]] tables are more than the {limit} accepted")
    return items


def nesting_errors(text: str, source: str) -> None:
    """Refuse text whose brackets nest deeper than MAX_NESTING (brackets inside strings count
    too: a conservative bound that keeps the TOML parser's recursion shallow)."""
    depth = deepest = 0
    for match in re.finditer(r"[\[{\]}]", text):
        depth = depth + 1 if match.group() in "[{" else max(depth - 1, 0)
        deepest = max(deepest, depth)
        if deepest > MAX_NESTING:
            raise ValueError(f"{source}: brackets nest deeper than {MAX_NESTING} levels")


def parse(text: str, source: str) -> dict[str, Any]:
    """The TOML ``text`` as a table, after the nesting check; malformed TOML is a ValueError."""
    nesting_errors(text, source)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{source}: malformed TOML: {exc}") from None


def read_layout(path: str | Path, what: str, loads: Any) -> Any:
    """``loads(text, source)`` of the file at ``path`` (relative: to the working directory), the
    file called ``what`` in messages ("driveline file"); messages name it by its absolute path."""
    p = Path(path).absolute()
    try:
        raw = read_regular_file(p, what)
    except OSError as exc:
        raise ValueError(f"cannot read {what} {str(p)!r}: {exc.strerror}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ValueError(f"{what} {str(p)!r} is not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    try:
        return loads(text, str(p))
    except ValueError as exc:
        message = str(exc)
        raise ValueError(message if message.startswith(str(p)) else f"{p}: {message}") from None


def read_regular_file(path: Path, what: str) -> bytes:
    """The bytes of ``path``, opened without blocking; only a regular file of at most MAX_FILE_BYTES."""
    descriptor = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0))
    try:
        if not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise ValueError(f"{what} {str(path)!r} is not a regular file")
        data = b""
        while len(data) <= MAX_FILE_BYTES and (chunk := os.read(descriptor, MAX_FILE_BYTES + 1 - len(data))):
            data += chunk
    finally:
        os.close(descriptor)
    if len(data) > MAX_FILE_BYTES:
        raise ValueError(f"{what} {str(path)!r} is larger than {MAX_FILE_BYTES} bytes")
    return data


def shipped_path(package: str, name: str, what: str) -> Path:
    """Path of the description ``data/<name>.toml`` shipped with ``package``, called ``what``
    in messages ("example")."""
    if not re.fullmatch(r"\w{1,64}", name, re.ASCII):
        raise ValueError(f"no shipped {what} named {name[:80]!r} (names are letters, digits and '_')")
    p = Path(str(resources.files(package).joinpath("data", f"{name}.toml")))
    if not p.is_file():
        raise ValueError(f"no shipped {what} named {name!r}")
    return p
