"""Shared fixtures and the suite's markers.

FMUs are built on demand, once per test session (per worker with pytest-xdist), into one
folder: FMI 2.0 in it, FMI 3.0 in its ``fmi3/``. Markers are assigned here, from what a test
uses, so that test files carry none:

* ``fmu``: the test uses a built FMU, Python or native (a fixture of this file);
* ``importers``: its module drives the external importers (imports ``fmu_harness.importers``
  or ``fmu_harness.interop``: libcosim, Ecos, fmutool);
* ``core``: neither, the FMI-free core and tools;
* ``slow``: listed in :data:`SLOW` (over about 5 s each on two busy cores), and the FMU tests
  run for every model when the model is ``CriticalSpeeds`` (its analysis costs about a second
  per instance).

``--fmi 2`` (or ``3``) builds and tests one FMI version only. ``--quick`` is the core and the
FMI 2.0 FMUs without the slow and importer tests (``-m "not slow and not importers" --fmi 2``),
and does not even import the modules that hold slow tests only (ROSS takes seconds to import):
``python -m pytest -q -n 2 --quick``.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path

import pytest
from fmpy import extract

from driveline.catalog import MODELS
from fmu_harness import build
from fmu_harness.build import native, toolchain
from fmu_harness.runner import FmuInstance

FmuPath = Callable[..., Path]

FMU_FIXTURES = {"fmu_store", "native_dir", "release_dir"}
IMPORTER_MODULES = ("fmu_harness.importers", "fmu_harness.interop")
VERSION_PARAMETERS = ("fmi", "version")
SLOW_MODEL = "CriticalSpeeds"
SLOW = (
    "tests/test_tripod_moving_bearing.py",
    "tests/test_analysis_work.py::test_the_worst_inputs_the_limits_allow_stay_within_the_budgets",
    "tests/test_coupling_comparison.py::test_two_cardan_joints_cancel_when_phased_and_double_when_not",
    "tests/test_critical_speeds_model.py::test_a_layout_brings_its_own_unbalance_and_damping",
    "tests/test_critical_speeds_model.py::test_analysis_runs_only_when_the_structure_changes",
    "tests/test_critical_speeds_model.py::test_fmu_follows_a_speed_ramp_and_refuses_overspeed",
    "tests/test_critical_speeds_model.py::test_shear_parameter_selects_the_beam_theory",
    "tests/test_critical_speeds_model.py::test_shipped_layout_by_name",
    "tests/test_host_environment.py",
    "tests/test_install.py::test_installed_wheel_builds_every_fmu_and_both_systems",
    "tests/test_install.py::test_wheel_carries_what_the_native_build_needs",
    "tests/test_interop.py",
    "tests/test_packaging.py::test_different_fmus_alive_at_once_in_one_host",
    "tests/test_packaging.py::test_markers_follow_what_the_tests_use",
    "tests/test_native_platforms.py",
    "tests/test_native_static_link.py",
    "tests/test_robustness.py",
    "tests/test_rotor_hinge.py::test_fmu_analyses_a_hinged_layout",
    "tests/test_rotor_hinge.py::test_hinged_two_piece_matches_finite_elements",
    "tests/test_rotor_hinge.py::test_spring_hinge_matches_finite_elements",
    "tests/test_rotor_roots.py::test_random_drivelines_match_finite_elements",
    "tests/test_rotor_roots.py::test_root_count_matches_finite_elements",
    "tests/test_rotor_ross.py",
    "tests/test_rotor_shear.py::test_shear_tube_matches_finite_elements",
    "tests/test_sweep.py",
)


QUICK_VERSIONS = ["2"]


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--fmi", action="append", choices=sorted(build.FMI_VERSIONS),
                     help="FMI version to build and test (repeat for several; default: all)")
    parser.addoption("--quick", action="store_true",
                     help='the quick run: -m "not slow and not importers" --fmi 2, slow-only modules not imported')


def selected_versions(config: pytest.Config) -> list[str]:
    return config.getoption("fmi") or (QUICK_VERSIONS if config.getoption("quick") else list(build.FMI_VERSIONS))


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """With ``--quick``, a module whose tests are all slow is not imported."""
    if config.getoption("quick") and f"tests/{collection_path.name}" in SLOW:
        return True
    return None


@pytest.fixture(scope="session")
def fmu_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The session's folder of built FMUs (built by :func:`fmu_path` when first asked for)."""
    return tmp_path_factory.mktemp("models")


@pytest.fixture(scope="session")
def fmu_path(fmu_store: Path, pytestconfig: pytest.Config) -> FmuPath:
    """``fmu_path(name, version="2")``: the FMU of catalog model ``name`` for FMI 2.0 or 3.0,
    built the first time it is asked for; a test asking for an FMI version not selected
    (``--fmi``) is skipped."""
    versions = selected_versions(pytestconfig)

    def path(name: str, version: str = "2") -> Path:
        if version not in versions:
            pytest.skip(f"FMI {version}.0 is not among the selected versions (--fmi)")
        built = build.fmu_path(fmu_store, name, version)
        if not built.exists():
            build.build(name, fmu_store, version)
        return built

    return path


@pytest.fixture(scope="session")
def native_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder holding the freshly built native FMUs (``native/``, ``native/fmi3/``), with the
    binary of this machine's platform alone."""
    dest = tmp_path_factory.mktemp("native_models")
    native.build_all(dest, release=False)
    return dest


@pytest.fixture(scope="session")
def release_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The native FMUs as released: a binary for each of the five platforms (needs ziglang)."""
    if not toolchain.release_available():
        pytest.skip("the five-platform build needs ziglang (pip install ziglang)")
    dest = tmp_path_factory.mktemp("release_models")
    native.build_all(dest, release=True)
    return dest


@pytest.fixture(scope="session")
def fmu_dir(fmu_store: Path, fmu_path: FmuPath, pytestconfig: pytest.Config) -> Path:
    """The folder holding the FMUs of all models in the selected FMI versions (FMI 3.0 ones in ``fmi3/``)."""
    for version in selected_versions(pytestconfig):
        for name in MODELS:
            fmu_path(name, version)
    return fmu_store


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
    selected FMI version ("2", "3")."""
    if "model_name" in metafunc.fixturenames:
        metafunc.parametrize("model_name", list(MODELS))
    if "fmi" in metafunc.fixturenames:
        metafunc.parametrize("fmi", selected_versions(metafunc.config))


@pytest.hookimpl(tryfirst=True)  # before ``-m`` selects by these markers
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark every test (see the module docstring); with ``--fmi``, deselect the other versions'
    variants of tests parametrized by ``fmi`` or ``version``; a whole-suite collection refuses
    :data:`SLOW` entries that name no test any more."""
    if config.args_source == pytest.Config.ArgsSource.TESTPATHS and not config.getoption("quick"):
        stale = [entry for entry in SLOW if not any(item.nodeid.startswith(entry) for item in items)]
        if stale:
            raise pytest.UsageError(f"tests/conftest.py SLOW names no collected test: {stale}")
    versions = selected_versions(config)
    kept, dropped = [], []
    for item in items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if any(name in params and str(params[name]) not in versions for name in VERSION_PARAMETERS):
            dropped.append(item)
            continue
        kept.append(item)
        names = vars(item.module).values() if item.module else ()
        if any(value is sys.modules.get(m) or getattr(value, "__module__", None) == m
               for value in names for m in IMPORTER_MODULES):
            item.add_marker(pytest.mark.importers)
        if FMU_FIXTURES & set(item.fixturenames) or item.get_closest_marker("fmu"):
            item.add_marker(pytest.mark.fmu)
        elif not item.get_closest_marker("importers"):
            item.add_marker(pytest.mark.core)
        if item.nodeid.startswith(SLOW) or (item.get_closest_marker("fmu") and SLOW_MODEL in params.values()):
            item.add_marker(pytest.mark.slow)
    if config.getoption("quick"):
        left_out = {item for item in kept if item.get_closest_marker("slow") or item.get_closest_marker("importers")}
        dropped += left_out
        kept = [item for item in kept if item not in left_out]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = kept
