"""A rebuild of the same sources gives the same FMUs byte for byte, Python and native (this
machine's binary; the five platforms' in tests/native/test_native_platforms.py): fixed entry times,
sorted entries, tokens from the contents, no build time in a binary."""

from __future__ import annotations

import zipfile
from pathlib import Path

from fmu_harness.packaging import archive, fmu, native

MODEL = "SpeedSource"  # the quickest to build; every model goes through the same packing


def build_twice(tmp_path: Path) -> list[tuple[Path, Path]]:
    built = []
    for dest in (tmp_path / "first", tmp_path / "second"):
        built.append([fmu.build(MODEL, dest, version) for version in ("2", "3")]
                     + native.build_all(dest, [MODEL], ("2", "3"), release=False))
    return list(zip(*built))


def test_a_rebuild_gives_the_same_fmus_byte_for_byte(tmp_path):
    pairs = build_twice(tmp_path)
    assert len(pairs) == 4
    for first, second in pairs:
        assert first.read_bytes() == second.read_bytes(), first.relative_to(tmp_path / "first")
        with zipfile.ZipFile(first) as built:
            entries = built.infolist()
        assert [entry.filename for entry in entries] == sorted(entry.filename for entry in entries)
        assert {entry.date_time for entry in entries} == {archive.FIXED_TIME}
        with zipfile.ZipFile(first) as built:
            assert b"generationDateAndTime" not in built.read("modelDescription.xml")


def test_the_token_follows_the_contents(tmp_path):
    """Another model description (another model of the same name) gets another token."""
    def token(path: Path) -> bytes:
        with zipfile.ZipFile(path) as built:
            description = built.read("modelDescription.xml")
        return description.split(b'guid="')[1].split(b'"')[0]

    speed_source = fmu.build(MODEL, tmp_path / "a")
    tripod = fmu.build("TripodCoupling", tmp_path / "b")
    assert token(speed_source) != token(tripod) and len(token(speed_source)) == 36
