"""The versions tested: constraints/ci.txt pins every requirement the project names, at a version its
bounds admit, and the README's commands and the CI job install with it."""

from __future__ import annotations

import tomllib
from pathlib import Path

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[2]
LOCK = ROOT / "constraints" / "ci.txt"
INSTALL_FLAG = "-c constraints/ci.txt"


def pins() -> dict[str, str]:
    lines = [line.strip() for line in LOCK.read_text().splitlines()]
    entries = [line for line in lines if line and not line.startswith("#")]
    assert all(line.count("==") == 1 for line in entries), [e for e in entries if e.count("==") != 1]
    return {canonicalize_name(name): version for name, version in (line.split("==") for line in entries)}


def test_every_requirement_is_pinned_within_its_bounds():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    named = [*project["dependencies"], *project["optional-dependencies"]["test"],
             *project["optional-dependencies"]["interop"]]
    locked = pins()
    for requirement in map(Requirement, named):
        version = locked.get(canonicalize_name(requirement.name))
        assert version is not None, f"{requirement.name} is not in {LOCK.name}"
        assert requirement.specifier.contains(version, prereleases=True), f"{requirement} excludes {version}"


def test_the_readme_and_the_ci_job_install_the_locked_versions():
    readme = (ROOT / "README.md").read_text()
    assert f'pip install {INSTALL_FLAG} -e ".[test,interop]" && python -m pytest -q -n 2' in readme
    assert f"pip install {INSTALL_FLAG} -e . && python build_fmu.py" in readme
    ci = (ROOT / ".ci" / "run").read_text()
    assert f'pip install --quiet {INSTALL_FLAG} -e ".[test,interop]"' in ci and "python -m pytest -q -n 2" in ci
