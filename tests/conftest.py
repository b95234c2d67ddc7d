"""Shared fixtures: every FMU of the project (FMI 2.0 and 3.0), built once per test session."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest
from fmpy import extract

from fmu_harness import build
from fmu_harness.build import native
from fmu_harness.runner import FmuInstance

FmuPath = Callable[..., Path]


@pytest.fixture(scope="session")
def fmu_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding freshly built FMUs of all models (FMI 3.0 ones in ``fmi3/``)."""
    dest = tmp_path_factory.mktemp("models")
    build.build_all(dest)
    return dest


@pytest.fixture(scope="session")
def native_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding the freshly built native FMUs (``native/``, ``native/fmi3/``)."""
    dest = tmp_path_factory.mktemp("native_models")
    native.build_all(dest)
    return dest


@pytest.fixture(scope="session")
def fmu_path(fmu_dir: Path) -> FmuPath:
    """``fmu_path(name, version="2")``: the built FMU of catalog model ``name`` for FMI 2.0 or 3.0."""
    return lambda name, version="2": build.fmu_path(fmu_dir, name, version)


@pytest.fixture(scope="session")
def fmu_unzipdir(fmu_path: FmuPath, tmp_path_factory: pytest.TempPathFactory) -> FmuPath:
    """``fmu_unzipdir(name, version="2")``: the FMU extracted once per session (for ``FmuInstance``)."""
    extracted: dict[tuple[str, str], Path] = {}

    def unzipdir(name: str, version: str = "2") -> Path:
        if (name, version) not in extracted:
            target = tmp_path_factory.mktemp(f"{name}_fmi{version}")
            extracted[name, version] = Path(extract(str(fmu_path(name, version)), unzipdir=str(target)))
        return extracted[name, version]

    return unzipdir


@pytest.fixture(scope="session")
def open_fmu(fmu_path: FmuPath, fmu_unzipdir: FmuPath) -> Callable[..., FmuInstance]:
    """``open_fmu(name, version="2", instance_name="instance")``: a new :class:`FmuInstance` of the
    session's extracted copy (use it as a context manager)."""
    return lambda name, version="2", instance_name="instance": FmuInstance(
        fmu_path(name, version), instance_name, unzipdir=str(fmu_unzipdir(name, version))
    )


@pytest.fixture(scope="session")
def tripod_fmu(fmu_path: FmuPath) -> Path:
    return fmu_path("TripodCoupling")


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    """A test taking ``model_name`` runs for every catalog model, one taking ``fmi`` for every
    FMI version the build makes ("2", "3")."""
    from driveline.catalog import MODELS

    if "model_name" in metafunc.fixturenames:
        metafunc.parametrize("model_name", list(MODELS))
    if "fmi" in metafunc.fixturenames:
        metafunc.parametrize("fmi", list(build.FMI_VERSIONS))
