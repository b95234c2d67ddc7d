"""The FMU archive, the same bytes for the same members: entries sorted by name, each with one
fixed time (1980-01-01, the first a zip file can hold), permissions and compression, so that
rebuilding unchanged sources gives the same FMU byte for byte. An FMU's token (FMI 2.0 ``guid``,
FMI 3.0 ``instantiationToken``) is a name-based UUID in :data:`TOKEN_NAMESPACE` of its contents."""

from __future__ import annotations

import hashlib
import uuid
import zipfile
from collections.abc import Mapping
from pathlib import Path

TOKEN_NAMESPACE = uuid.UUID("6f3b1d52-8a0e-4c59-9a57-1f0e2f4c7d10")
FIXED_TIME = (1980, 1, 1, 0, 0, 0)
FILE_MODE = 0o100644  # a regular file, rw-r--r--
FOLDER_MODE = 0o040755  # a folder entry (a name ending in "/"), rwxr-xr-x


def write_zip(target: Path, members: Mapping[str, bytes]) -> None:
    """Write ``members`` (name -> bytes) to ``target`` as a deflated zip file."""
    target.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(members):
            entry = zipfile.ZipInfo(name, FIXED_TIME)
            entry.compress_type = zipfile.ZIP_DEFLATED
            entry.external_attr = (FOLDER_MODE if name.endswith("/") else FILE_MODE) << 16
            archive.writestr(entry, members[name])


def content_token(description: bytes, others: Mapping[str, bytes]) -> str:
    """An FMU's token from its model description without one and its other members (name -> bytes)."""
    digest = hashlib.sha256(repr((description, sorted(others.items()))).encode())
    return str(uuid.uuid5(TOKEN_NAMESPACE, digest.hexdigest()))
