"""Model states as bytes that can only describe values: the encoding of a serialised FMU state.

Layout (format 1)::

    MAGIC | UTF-8 JSON {"format": 1, "model": <spec name>, "spec": <spec digest>, "state": <value>} | SHA-256

The digest at the end covers everything before it, so truncated or altered bytes are refused
before they are parsed. Every value is a tagged pair: ``["f", float.hex()]`` (exact, NaN and
infinities included), ``["i", int]``, ``["b", bool]``, ``["s", str]``, ``["n", null]``,
``["t", [values]]`` (tuple) and ``["d", [[key, value], ...]]`` (dict with string keys).
Decoding builds nothing but these types, so no byte sequence can make it run code; whatever
does not fit raises :class:`StateRefused` with the reason.
"""

from __future__ import annotations

import hashlib
import json
from typing import Any

from driveline.variables import ModelSpec

MAGIC = b"driveline-fmus state\n"
FORMAT = 1
#: Refused unread above this size; a model state is a few kilobytes.
MAX_BYTES = 1 << 20
#: Nesting of tuples and dicts; model states nest two or three levels.
MAX_DEPTH = 8
_CHECKSUM = hashlib.sha256().digest_size


class StateRefused(ValueError):
    """Bytes that are not a state of this model, with the reason."""


def spec_digest(spec: ModelSpec) -> str:
    """Fingerprint of a model's interface: a state saved by another interface is refused."""
    interface = [spec.name, [(v.name, v.type, v.causality, v.effective_variability) for v in spec.variables]]
    return hashlib.sha256(json.dumps(interface).encode()).hexdigest()


def _tag(value: Any, depth: int) -> list[Any]:
    if depth > MAX_DEPTH:
        raise StateRefused(f"a state nests deeper than {MAX_DEPTH} levels")
    if isinstance(value, bool):
        return ["b", value]
    if isinstance(value, int):
        return ["i", int(value)]
    if isinstance(value, float):
        return ["f", float(value).hex()]
    if isinstance(value, str):
        return ["s", value]
    if value is None:
        return ["n", None]
    if isinstance(value, tuple):
        return ["t", [_tag(item, depth + 1) for item in value]]
    if isinstance(value, dict) and all(isinstance(key, str) for key in value):
        return ["d", [[key, _tag(item, depth + 1)] for key, item in value.items()]]
    raise StateRefused(f"a state holds a {type(value).__name__}, which has no plain encoding")


def _untag(item: Any, depth: int) -> Any:
    if depth > MAX_DEPTH:
        raise StateRefused(f"the state nests deeper than {MAX_DEPTH} levels")
    if not (isinstance(item, list) and len(item) == 2 and item[0] in _DECODERS):
        raise StateRefused(f"malformed value {str(item)[:60]!r}")
    return _DECODERS[item[0]](item[1], depth)


def _float(payload: Any, depth: int) -> float:
    try:
        return float.fromhex(payload)
    except (TypeError, ValueError, OverflowError):
        raise StateRefused(f"malformed float {str(payload)[:40]!r}") from None


def _typed(kind: type):
    def decode(payload: Any, depth: int) -> Any:
        if type(payload) is not kind:
            raise StateRefused(f"expected a {kind.__name__}, got {str(payload)[:40]!r}")
        return payload

    return decode


def _none(payload: Any, depth: int) -> None:
    if payload is not None:
        raise StateRefused(f"expected null, got {str(payload)[:40]!r}")


def _tuple(payload: Any, depth: int) -> tuple[Any, ...]:
    if not isinstance(payload, list):
        raise StateRefused("a tuple must be a list of values")
    return tuple(_untag(item, depth + 1) for item in payload)


def _dict(payload: Any, depth: int) -> dict[str, Any]:
    if not (isinstance(payload, list) and all(isinstance(p, list) and len(p) == 2 and isinstance(p[0], str) for p in payload)):
        raise StateRefused("a dict must be a list of [name, value] pairs")
    return {key: _untag(item, depth + 1) for key, item in payload}


_DECODERS = {"f": _float, "i": _typed(int), "b": _typed(bool), "s": _typed(str), "n": _none, "t": _tuple, "d": _dict}


def encode(spec: ModelSpec, state: dict[str, Any]) -> bytes:
    """The bytes of ``state`` (plain values only) of a model with interface ``spec``."""
    document = {"format": FORMAT, "model": spec.name, "spec": spec_digest(spec), "state": _tag(state, 0)}
    body = MAGIC + json.dumps(document, separators=(",", ":"), allow_nan=False).encode("utf-8")
    return body + hashlib.sha256(body).digest()


def decode(spec: ModelSpec, data: bytes) -> dict[str, Any]:
    """The state in ``data``; raises :class:`StateRefused` unless it is an intact format-1 state
    saved by a model with this interface."""
    if len(data) > MAX_BYTES:
        raise StateRefused(f"{len(data)} bytes is more than a state of {spec.name} can hold ({MAX_BYTES})")
    if not data.startswith(MAGIC):
        raise StateRefused(f"these {len(data)} bytes are not a serialised state of a driveline-fmus FMU")
    body, checksum = data[:-_CHECKSUM], data[-_CHECKSUM:]
    if len(data) < len(MAGIC) + _CHECKSUM or hashlib.sha256(body).digest() != checksum:
        raise StateRefused("the serialised state is truncated or corrupt (checksum mismatch)")
    try:
        document = json.loads(body[len(MAGIC):].decode("utf-8"), parse_constant=_no_constant)
    except (ValueError, RecursionError) as error:
        raise StateRefused(f"the serialised state is malformed ({type(error).__name__})") from None
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        found = document.get("format") if isinstance(document, dict) else None
        raise StateRefused(f"state format {found!r} is not supported (this FMU reads format {FORMAT})")
    if document.get("model") != spec.name:
        raise StateRefused(f"the state was saved by model {str(document.get('model'))[:60]!r}, not {spec.name!r}")
    if document.get("spec") != spec_digest(spec):
        raise StateRefused(f"the state was saved by another version of {spec.name} (its variables differ)")
    state = _untag(document.get("state"), 0)
    if not isinstance(state, dict):
        raise StateRefused("the saved state is not a table of values")
    return state


def _no_constant(name: str) -> float:
    raise ValueError(f"JSON constant {name} is not used by the format")

