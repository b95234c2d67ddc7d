"""A real install builds everything: the wheel carries the C sources, doc pages and data the build
needs, and ``driveline-fmus build`` in an empty folder of a fresh environment writes every FMU and
both SSP systems. Without a C compiler the build says what to install in one line and builds the
Python FMUs and the Python system; it fails only when native FMUs were asked for (``--native``)."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from driveline.catalog import MODELS
from fmu_harness import build_command
from fmu_harness.packaging import fmu_path, native, toolchain
from fmu_harness.runs import system

ROOT = Path(__file__).resolve().parents[2]
PROGRESS = re.compile(r".+ \[\d+/\d+\]( |$)")  # a progress line (fmu_harness.console.Progress)
PROJECT = ("pyproject.toml", "README.md", "LICENSE", "driveline", "fmu_src", "fmu_harness", "docs")


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The project's wheel, built once for the module from a copy of its tree (setuptools writes
    build/ into the tree)."""
    folder = tmp_path_factory.mktemp("wheel")
    tree = folder / "tree"
    for name in PROJECT:
        source = ROOT / name
        if source.is_dir():
            shutil.copytree(source, tree / name, symlinks=True, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            (tree / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, tree / name)
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--quiet", "--no-deps", "--wheel-dir", str(folder / "dist"),
                    str(tree)], check=True, capture_output=True, text=True, timeout=600)
    return next((folder / "dist").glob("driveline_fmus-*.whl"))


def _environment(folder: Path, wheel: Path) -> Path:
    """A fresh virtual environment with the wheel installed (no dependencies: those of this
    environment are on its path, through a .pth file, so the test needs no index)."""
    venv = folder / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    python = venv / ("Scripts/python.exe" if sys.platform == "win32" else "bin/python")
    site = subprocess.run([str(python), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    installed = [entry for entry in sys.path if Path(entry).name in ("site-packages", "dist-packages")]
    (Path(site) / "dependencies.pth").write_text("".join(f"{entry}\n" for entry in installed))
    subprocess.run([sys.executable, "-m", "pip", "--python", str(python), "install", "--quiet", "--no-deps",
                    "--no-index", str(wheel)], check=True, capture_output=True, text=True, timeout=300)
    return python


def test_wheel_carries_what_the_native_build_needs(wheel):
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
    sources = {f"fmu_src/native/{path.relative_to(native.NATIVE_SRC).as_posix()}"
               for path in native.NATIVE_SRC.rglob("*") if path.suffix in (".c", ".h")}
    pages = {f"fmu_src/docs/{native.snake_case(name)}.md" for name in MODELS}
    assert sources and sources | pages | {"fmu_src/LICENSE", "driveline/rotor/data/two_piece_propshaft.toml"} <= names


def test_installed_wheel_builds_every_fmu_and_both_systems(wheel, tmp_path):
    python = _environment(tmp_path, wheel)
    work = tmp_path / "empty"
    work.mkdir()
    where = subprocess.run([str(python), "-c", "import driveline, fmu_src; print(driveline.__file__, fmu_src.__file__)"],
                           capture_output=True, text=True, check=True, cwd=work).stdout.split()
    assert all(Path(path).is_relative_to(tmp_path / "venv") for path in where)  # the wheel's, not this tree's
    script = python.parent / ("driveline-fmus.exe" if sys.platform == "win32" else "driveline-fmus")
    run = subprocess.run([str(script), "build", "--no-references", *["--all-platforms"] * toolchain.release_available()],
                         capture_output=True, text=True, timeout=1200, cwd=work)
    assert run.returncode == 0, run.stderr[-3000:]
    models = work / "models"
    expected = {fmu_path(models, name, fmi) for name in MODELS for fmi in ("2", "3")}
    expected |= {native.fmu_path(models, name, fmi) for name in native.native_models() for fmi in ("2", "3")}
    expected |= {system.container_path(s, models, fmi) for s in system.systems() for fmi in ("2", "3")}
    assert set(models.rglob("*.fmu")) == expected
    packages = {path.relative_to(models).as_posix() for path in models.rglob("*.ssp")}
    assert {f"{s.name}.ssp" for s in system.systems()} | {"native/Driveline.ssp"} <= packages
    platforms = {"binaries/x86_64-linux", "binaries/x86_64-windows", "binaries/aarch64-linux",
                 "binaries/x86_64-darwin", "binaries/aarch64-darwin"} if toolchain.release_available() else set()
    with zipfile.ZipFile(native.fmu_path(models, "CriticalSpeeds", "3")) as archive:
        assert platforms <= {str(Path(name).parent) for name in archive.namelist()}


def _no_compiler(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setattr(toolchain, "zig", lambda: None)
    monkeypatch.setattr(toolchain, "system_compiler", lambda: None)


def test_without_a_compiler_the_python_fmus_and_system_are_built(tmp_path, monkeypatch, capsys):
    _no_compiler(monkeypatch)
    build_command.main(["--dest", str(tmp_path), "--fmi", "2", "--no-references"])
    errors = [line for line in capsys.readouterr().err.splitlines() if not PROGRESS.match(line)]
    assert errors[0] == f"native FMUs not built: {toolchain.NO_COMPILER}" and "pip install ziglang" in errors[0]
    assert len(errors) == 1
    assert set(tmp_path.rglob("*.fmu")) == {fmu_path(tmp_path, name) for name in MODELS}
    assert {path.name for path in tmp_path.rglob("*.ssp")} == {system.ssp_path(s, tmp_path).name for s in system.systems()}


def test_without_a_compiler_asking_for_native_fmus_fails(tmp_path, monkeypatch, capsys):
    _no_compiler(monkeypatch)
    with pytest.raises(SystemExit) as stopped:
        build_command.main(["--dest", str(tmp_path), "--fmi", "2", "--no-references", "--native", "SpeedSource"])
    assert stopped.value.code == 1
    assert "pip install ziglang" in capsys.readouterr().err
    assert set(tmp_path.rglob("*.fmu")) == {fmu_path(tmp_path, "SpeedSource")}
