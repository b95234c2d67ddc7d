"""Shared fixtures and the suite's markers, for the tests in ``core/``, ``fmu/``, ``native/`` and
``project/`` (what they share besides fixtures is in ``support/``, imported as ``support``).

FMUs are built on demand, once per test session (per worker with pytest-xdist), into one
folder: FMI 2.0 in it, FMI 3.0 in its ``fmi3/``. A test taking ``family`` runs on the Python FMUs
and on the native ones (:class:`support.families.Family`). Markers are assigned here, from what a
test uses, so that test files carry none:

* ``fmu``: the test uses a built FMU, Python or native (a fixture of this file);
* ``importers``: its module drives the external importers (imports ``fmu_harness.checks.importers``,
  ``fmu_harness.checks.interop`` or ``fmu_harness.checks.engine_refusals``: libcosim, Ecos, fmutool);
* ``core``: neither, the FMI-free core and tools;
* ``slow``: measured at :data:`SLOW_SECONDS` of CPU time or more in ``tests/durations.json``
  (:func:`pytest_runtest_call`: the test's call and fixtures, with the subprocesses they waited
  for; not the FMU builds every FMU test shares), and the FMU tests run for
  every model when the model is ``CriticalSpeeds`` (its analysis costs about a second per
  instance), and the tests of the five-platform build (``release_dir``: what it costs depends on
  ziglang's cache). ``python -m pytest -p no:randomly --update-durations [TESTS]`` measures the tests it
  runs and writes their times into the file (the others' stay); without ``-n`` and without
  ``TESTS`` (``--collect-only`` will do) it also drops the tests no longer collected.

``--cpu-total`` prints the CPU seconds the file holds for the selected tests (with ``--collect-only``, what
a run of them costs without running it).

``--fmi 2`` (or ``3``) builds and tests one FMI version only. ``--quick`` is the core and the
FMI 2.0 FMUs without the slow and importer tests (``-m "not slow and not importers" --fmi 2``),
and does not even import the modules that hold slow tests only (ROSS takes seconds to import):
``python -m pytest -q -n 2 --quick``.

Property tests (hypothesis) run the ``ci`` profile: derandomised, so every machine draws the same
cases and a run is repeatable; ``--hypothesis-profile explore`` draws new cases on every run and keeps
the failing ones in ``.hypothesis/`` (docs/development.md: a failure found so becomes an explicit case).

With ``-n`` (pytest-xdist's default ``load`` distribution), a worker takes a whole work unit at a
time (:func:`work_unit`: a test file, or the part of it for one family of FMUs), the costliest unit
left first by ``tests/durations.json`` (:func:`pytest_xdist_make_scheduler`): a module's fixtures
are set up on one worker only, and the run does not end on a long unit started last. Linear
algebra runs on one thread per process (:data:`ONE_THREAD`): the workers already use every core.
"""

from __future__ import annotations

import os

#: Set before numpy loads (here, in the workers, which inherit it, and in the processes tests
#: start): OpenBLAS's own threads, competing with the other worker for two cores, cost five to
#: fifteen times the CPU time of one thread (measured 2026-11-27, load 13: numpy eigvals of
#: 200 x 200, 1.39 s of CPU against 0.09 s; two rotor test files, 45 s against 19 s).
ONE_THREAD = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
for _variable in ONE_THREAD:
    os.environ.setdefault(_variable, "1")

import json  # noqa: E402 (after the thread count is set)
import resource  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from collections.abc import Callable  # noqa: E402
from datetime import datetime, timezone  # noqa: E402
from pathlib import Path  # noqa: E402

import pytest  # noqa: E402
from hypothesis import settings  # noqa: E402

from driveline.catalog import MODELS  # noqa: E402
from fmu_harness import packaging  # noqa: E402
from fmu_harness.packaging import native, toolchain  # noqa: E402
from support.families import Family, NativeFamily, PythonFamily  # noqa: E402

FmuPath = Callable[..., Path]

FMU_FIXTURES = {"fmu_store", "native_dir", "release_dir", "family"}
IMPORTER_MODULES = ("fmu_harness.checks.importers", "fmu_harness.checks.interop", "fmu_harness.checks.engine_refusals")
VERSION_PARAMETERS = ("fmi", "version")
SLOW_MODEL = "CriticalSpeeds"
#: The ids of the family parameters: the session's ``family`` and the robustness suite's (robustness.FAMILIES).
FAMILY_IDS = (PythonFamily.name, NativeFamily.name)
DURATIONS = Path(__file__).with_name("durations.json")
SLOW_SECONDS = 0.5  # CPU seconds of a test at which it is slow
RELEASE_FIXTURE = "release_dir"  # the five-platform build: its cost depends on ziglang's cache
#: The session's FMU builds, which every FMU test shares, and the sanitized builds of the native FMUs that a
#: module's tests share: charged to no test when measuring.
SHARED_BUILDS = {"fmu_store", "fmu_path", "fmu_dir", "tripod_fmu", "native_dir", "family", "sanitized"}


QUICK_VERSIONS = ["2"]


#: The suite's profile: the same cases everywhere, no example database between runs.
settings.register_profile("ci", derandomize=True, database=None, print_blob=True)
#: On demand (``--hypothesis-profile explore``): new cases each run, failures kept and replayed first.
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile("ci")


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--fmi", action="append", choices=sorted(packaging.FMI_VERSIONS),
                     help="FMI version to build and test (repeat for several; default: all)")
    parser.addoption("--quick", action="store_true",
                     help='the quick run: -m "not slow and not importers" --fmi 2, slow-only modules not imported')
    parser.addoption("--update-durations", action="store_true",
                     help=f"measure the tests run and write their CPU times into {DURATIONS.name}")
    parser.addoption("--cpu-total", action="store_true",
                     help=f"print the CPU seconds {DURATIONS.name} holds for the selected tests (with --collect-only: "
                          "what a run of them costs, without running it)")


def measured() -> dict[str, float]:
    """CPU seconds of each test's call, by node id, as last measured (``--update-durations``)."""
    return json.loads(DURATIONS.read_text())["cpu_seconds"] if DURATIONS.exists() else {}


def slow_modules(durations: dict[str, float]) -> set[str]:
    """Test files all of whose measured tests are slow."""
    by_file: dict[str, list[float]] = {}
    for nodeid, seconds in durations.items():
        by_file.setdefault(nodeid.split("::")[0], []).append(seconds)
    return {path for path, times in by_file.items() if min(times) >= SLOW_SECONDS}


def work_unit(nodeid: str) -> str:
    """The tests a worker runs in a row with ``-n``: those of one file, or of one file and one
    family of FMUs where its tests take one (a ``python`` or ``native`` parameter): the robustness
    suite's fixtures run every case of a family once."""
    path, _, name = nodeid.partition("::")
    family = next((p for p in name.partition("[")[2].rstrip("]").split("-") if p in FAMILY_IDS), "")
    return f"{path}[{family}]" if family else path


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log):
    """pytest-xdist's ``load`` distribution by :func:`work_unit`, the costliest unit left first
    (its tests' CPU seconds summed from ``tests/durations.json``; an unmeasured test counts 0)."""
    if config.getvalue("dist") != "load":
        return None
    from xdist.scheduler import LoadScopeScheduling

    costs: dict[str, float] = {}
    for nodeid, seconds in measured().items():
        costs[work_unit(nodeid)] = costs.get(work_unit(nodeid), 0.0) + seconds

    class CostliestUnitFirst(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

        def _assign_work_unit(self, node) -> None:
            """The costliest unit left; a node holding fewer than two tests then gets the next unit too, or is told
            to stop after them: a worker waits for a second test before it runs its first (pytest-xdist 1327)."""
            self.workqueue.move_to_end(max(self.workqueue, key=lambda unit: costs.get(unit, 0.0)), last=False)
            super()._assign_work_unit(node)
            if self._pending_of(self.assigned_work[node]) < 2:
                if self.workqueue:
                    self._assign_work_unit(node)
                else:
                    node.shutdown()

        def remove_node(self, node) -> str | None:
            """xdist's, but after a crash only the node's unfinished work units go back on the queue, the test
            it crashed on marked done (xdist reports it failed): xdist 3.8 re-queues the finished units too,
            which come back empty, and the run then waits for ever (pytest-xdist issues 1323 and 1378)."""
            workload = self.assigned_work.pop(node)
            crashed = next((nodeid for unit in workload.values() for nodeid, done in unit.items() if not done), None)
            if crashed is None:
                return None
            for unit in workload.values():
                if crashed in unit:
                    unit[crashed] = True
            self.workqueue.update({scope: unit for scope, unit in workload.items() if not all(unit.values())})
            for other in self.assigned_work:
                self._reschedule(other)
            return crashed

    return CostliestUnitFirst(config, log)


def selected_versions(config: pytest.Config) -> list[str]:
    return config.getoption("fmi") or (QUICK_VERSIONS if config.getoption("quick") else list(packaging.FMI_VERSIONS))


def skip_unless_selected(version: str, versions: list[str]) -> None:
    """Skip the test asking for an FMU of FMI ``version`` when the run did not select it (``--fmi``)."""
    if version not in versions:
        pytest.skip(f"FMI {version}.0 is not among the selected versions (--fmi)")


def pytest_ignore_collect(collection_path: Path, config: pytest.Config) -> bool | None:
    """With ``--quick``, a module whose tests are all slow is not imported."""
    if config.getoption("quick") and collection_path.relative_to(config.rootpath).as_posix() in slow_modules(measured()):
        return True
    return None


@pytest.fixture(scope="session")
def fmi_versions(pytestconfig: pytest.Config) -> list[str]:
    """The FMI versions the run builds and tests (``--fmi``; all by default, "2" with ``--quick``)."""
    return selected_versions(pytestconfig)


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
        skip_unless_selected(version, versions)
        built = packaging.fmu_path(fmu_store, name, version)
        if not built.exists():
            packaging.build(name, fmu_store, version)
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


@pytest.fixture(scope="session", params=[PythonFamily, NativeFamily], ids=lambda family: family.name)
def family(request: pytest.FixtureRequest, fmu_path: FmuPath, tmp_path_factory: pytest.TempPathFactory) -> Family:
    """A test taking ``family`` runs on the Python FMUs and on the native ones (built when first
    asked for); a model without a C port, or an FMI version not selected, skips the native run."""
    if request.param is PythonFamily:
        return PythonFamily(fmu_path, tmp_path_factory.mktemp("python_family"))
    native_dir = request.getfixturevalue("native_dir")
    versions, ported = selected_versions(request.config), native.native_models()

    def path(name: str, version: str = "2") -> Path:
        skip_unless_selected(version, versions)
        if name not in ported:
            pytest.skip(f"{name} has no C port")
        return native.fmu_path(native_dir, name, version)

    return NativeFamily(path, tmp_path_factory.mktemp("native_family"))


@pytest.fixture(scope="session")
def fmu_dir(fmu_store: Path, fmu_path: FmuPath, fmi_versions: list[str]) -> Path:
    """The folder holding the FMUs of all models in the selected FMI versions (FMI 3.0 ones in ``fmi3/``)."""
    for version in fmi_versions:
        for name in MODELS:
            fmu_path(name, version)
    return fmu_store


@pytest.fixture(scope="session")
def fmi2_dir(fmu_dir: Path, fmi_versions: list[str]) -> Path:
    """:func:`fmu_dir` for a test that runs the FMI 2.0 FMUs in it (``<model>.fmu``, a system of
    them); skipped when FMI 2.0 is not selected."""
    skip_unless_selected("2", fmi_versions)
    return fmu_dir


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
    variants of tests parametrized by ``fmi`` or ``version``; a whole-suite collection of every
    FMI version warns of a durations file that names tests no longer collected."""
    durations = measured()
    whole_suite = config.args_source == pytest.Config.ArgsSource.TESTPATHS and not config.getoption("quick")
    if whole_suite and not config.getoption("fmi"):  # --fmi leaves the other version's variants uncollected
        stale = sorted(set(durations) - {item.nodeid for item in items})
        if stale and config.getoption("update_durations") and not hasattr(config, "workerinput"):
            _write_durations({n: s for n, s in durations.items() if n not in stale})
        elif stale:
            warnings.warn(pytest.PytestWarning(
                f"tests/{DURATIONS.name} names {len(stale)} tests no longer collected, e.g. {stale[0]}: drop them "
                "with python -m pytest -q --collect-only --update-durations"))
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
        if durations.get(item.nodeid, 0.0) >= SLOW_SECONDS or RELEASE_FIXTURE in item.fixturenames or (
                item.get_closest_marker("fmu") and SLOW_MODEL in params.values()):
            item.add_marker(pytest.mark.slow)
    if config.getoption("quick"):
        left_out = {item for item in kept if item.get_closest_marker("slow") or item.get_closest_marker("importers")}
        dropped += left_out
        kept = [item for item in kept if item not in left_out]
    if dropped:
        config.hook.pytest_deselected(items=dropped)
        items[:] = kept


def pytest_collection_finish(session: pytest.Session) -> None:
    """With ``--cpu-total``, the selected tests' CPU seconds as last measured: the number the docs quote
    for the quick run and the whole suite, generated (the session's FMU builds and collection are no
    test's, so a run costs more; its wall time depends on the load and the workers)."""
    if not session.config.getoption("cpu_total") or hasattr(session.config, "workerinput"):
        return
    durations = measured()
    by_file: dict[str, float] = {}
    for item in session.items:
        path = item.nodeid.split("::")[0]
        by_file[path] = by_file.get(path, 0.0) + durations.get(item.nodeid, 0.0)
    unmeasured = sum(item.nodeid not in durations for item in session.items)
    costliest = sorted(by_file.items(), key=lambda found: -found[1])[:3]
    updated = json.loads(DURATIONS.read_text())["updated"] if DURATIONS.exists() else "never"
    session.config.get_terminal_writer().line(
        f"cpu total: {sum(by_file.values()):.0f} s of CPU for {len(session.items)} tests ({unmeasured} not measured; "
        f"tests/{DURATIONS.name} of {updated}); costliest files: "
        + ", ".join(f"{path} {seconds:.0f} s" for path, seconds in costliest))


def _cpu_seconds() -> float:
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    return time.process_time() + children.ru_utime + children.ru_stime


_MEASURED: dict[str, float] = {}
_FIXTURE_COSTS: dict[tuple[str, str], float] = {}  # (node id of the fixture's scope, name) -> CPU seconds
_NESTED: list[float] = []  # CPU seconds of the fixtures set up within each fixture being set up


@pytest.hookimpl(hookwrapper=True)
def pytest_fixture_setup(fixturedef: pytest.FixtureDef, request: pytest.FixtureRequest):
    """With ``--update-durations``, the CPU time of each fixture's own setup (without the fixtures
    it asks for); the :data:`SHARED_BUILDS` are charged to no test."""
    if not request.config.getoption("update_durations"):
        yield
        return
    start = _cpu_seconds()
    _NESTED.append(0.0)
    yield
    total = _cpu_seconds() - start
    own = total - _NESTED.pop()
    if _NESTED:
        _NESTED[-1] += total
    if fixturedef.argname not in SHARED_BUILDS:  # set up again (another parameter upstream): the new one's cost
        _FIXTURE_COSTS[request.node.nodeid, fixturedef.argname] = own


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item: pytest.Item):
    """With ``--update-durations``, a test's cost: its call's CPU time (this process and the
    subprocesses it waited for) and the setup of every fixture it uses but the shared FMU builds,
    a module's or the session's fixture counted for each of its tests (each needs it when run
    alone). It travels with the report, also from pytest-xdist workers."""
    start = _cpu_seconds()
    yield
    if item.config.getoption("update_durations"):
        fixtures = sum(cost for (node, name), cost in _FIXTURE_COSTS.items()
                       if name in item.fixturenames and (not node or node == item.nodeid
                                                         or item.nodeid.startswith((f"{node}::", f"{node}/"))))
        item.user_properties.append(("cpu_seconds", _cpu_seconds() - start + fixtures))
        for key in [key for key in _FIXTURE_COSTS if key[0] == item.nodeid]:
            del _FIXTURE_COSTS[key]


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    if report.when == "call":
        _MEASURED.update((report.nodeid, value) for name, value in report.user_properties if name == "cpu_seconds")


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    """With ``--update-durations``, merge this session's measurements into the durations file
    (once, in the controlling process); keep the session's status for :func:`pytest_unconfigure`."""
    session.config.stash[EXIT_STATUS] = int(exitstatus)
    if session.config.getoption("update_durations") and not hasattr(session.config, "workerinput") and _MEASURED:
        _write_durations({**measured(), **{nodeid: round(seconds, 3) for nodeid, seconds in _MEASURED.items()}})


EXIT_STATUS = pytest.StashKey[int]()


@pytest.hookimpl(trylast=True)
def pytest_unconfigure(config: pytest.Config) -> None:
    """The session's process has loaded Python FMUs, whose wrappers use freed memory at exit and
    may abort it after every test passed (wrapper defect 10, docs/robustness.md): once everything
    is reported, the session leaves with its own status and no exit handlers. xdist workers end
    as xdist ends them."""
    if EXIT_STATUS in config.stash and not hasattr(config, "workerinput"):
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(config.stash[EXIT_STATUS])


def _write_durations(durations: dict[str, float]) -> None:
    DURATIONS.write_text(json.dumps({
        "updated": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "what": "CPU seconds of each test: its call and its fixtures but the session's, with the subprocesses waited for",
        "cpu_seconds": dict(sorted(durations.items())),
    }, indent=1) + "\n")
