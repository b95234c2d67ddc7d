"""Every FMU, Python and native, in the real importers (fmpy validate, fmutool -check, libcosimpy,
ecospy) through ``fmu_harness.checks.interop``, and the interoperability page's matrix matches what they
give here."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

from driveline.catalog import MODELS
from fmu_harness import packaging
from fmu_harness.checks import interop
from fmu_harness.packaging import native
from fmu_harness.doc_pages.sections import section
from fmu_harness.runs import system

PAGE = Path(__file__).resolve().parents[2] / "docs" / "interoperability.md"


@pytest.fixture(scope="module")
def matrix(fmu_dir: Path, native_dir: Path, fmi_versions: list[str]) -> interop.Table:
    if set(fmi_versions) != set(packaging.FMI_VERSIONS):
        pytest.skip("the importer matrix holds every FMI version (a run without --fmi)")
    missing = [i.package for i in interop.IMPORTERS if importlib.util.find_spec(i.package) is None]
    if missing:
        pytest.skip(f"importers not installed on this platform: {', '.join(missing)} (pip install '.[interop]')")
    for made in system.systems():  # the packages as one FMU, as the build writes them
        system.write_ssp(made, native_dir, native_dir)
        for version in packaging.FMI_VERSIONS:
            system.write_container(made, native_dir, version)
    return interop.matrix(fmu_dir, native_dir)


def test_every_fmu_passes_every_importer_that_supports_its_fmi_version(matrix):
    """Engines run the standard scenario; a pass means every output within
    interop.TOLERANCE (1e-9) of its largest magnitude in fmpy's run of the Python FMU (measured:
    at most 1.4e-13, from the hosts' different time grids; a native FMU's deviations are its
    Python FMU's; a container's are from fmpy's run of it). Model Exchange: the native FMUs only, not the
    packages as one FMU (the container steps its components' co-simulation)."""
    families = ([(name, "Python") for name in MODELS] + [(name, "native") for name in native.native_models()]
                + [(name, "container") for name in interop.CONTAINERS])
    assert set(matrix) == {(name, family, version) for name, family in families for version in ("2.0", "3.0")}
    for (name, family, version), row in matrix.items():
        for importer in interop.IMPORTERS:
            result = row[importer.name]
            model_exchange = family == "native" and not MODELS[name].co_simulation_only
            supported = version in importer.versions and (model_exchange or not importer.model_exchange_only)
            expected = "pass" if supported else "unsupported"
            assert result.status == expected, f"{name} {family} FMI {version} in {importer.name}: {result}"


def test_docs_hold_the_generated_matrix(matrix):
    assert section(PAGE, "interop") == interop.markdown(matrix), (
        "regenerate: python -m fmu_harness.checks.interop --update docs/interoperability.md"
    )
