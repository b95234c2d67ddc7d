"""Shared fixtures: every FMU of the project, built once per test session."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import build_fmu  # noqa: E402


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding freshly built FMUs of all models."""
    dest = tmp_path_factory.mktemp("models")
    build_fmu.build_all(dest)
    return dest


@pytest.fixture(scope="session")
def tripod_fmu(fmu_dir: Path) -> Path:
    return fmu_dir / "TripodCoupling.fmu"
