"""The native FMUs in a host with no Python in the process: ``tests/support/native_host.c``, compiled here,
loads each FMU's shared library (dlopen), runs the model's standard scenario against the Python
FMU's results (two instances side by side, a state stored, serialized and restored half way, a
refused step at the end), and does so again under valgrind: no invalid read or write, no leak."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from driveline.catalog import MODELS
from fmu_harness.packaging import native, toolchain
from support.native_host import HOST_SOURCE, RUNS, host_command, host_tolerance

VALGRIND = ("valgrind", "--error-exitcode=99", "--leak-check=full", "--show-leak-kinds=definite,indirect,possible",
            "--errors-for-leak-kinds=definite,indirect,possible")


@pytest.fixture(scope="module")
def host(tmp_path_factory: pytest.TempPathFactory) -> Path:
    executable = tmp_path_factory.mktemp("host") / "native_host"
    subprocess.run([*toolchain.host_compiler(), "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2",
                    "-isystem", str(native.fmi_headers()), str(HOST_SOURCE), "-o", str(executable), "-ldl", "-lm"],
                   check=True, capture_output=True, text=True)
    return executable


@pytest.mark.parametrize("name, parameters", RUNS)
def test_host_runs_the_standard_scenario_like_the_python_fmu(host, native_dir, fmu_path, tmp_path, name, parameters,
                                                              fmi):
    done = subprocess.run([str(host), *host_command(native_dir, fmu_path, name, fmi, tmp_path, parameters)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "checks passed" in done.stdout
    assert float(re.search(r"deviation (\S+),", done.stdout).group(1)) <= host_tolerance(name)
    reason = "is not finite" if MODELS[name].spec.of("input") else "step size must be positive"
    assert reason in done.stderr  # the refused step's reason reached the host's logger


@pytest.mark.skipif(shutil.which("valgrind") is None, reason="valgrind is not installed (Debian: apt-get install valgrind)")
@pytest.mark.parametrize("name, parameters", RUNS)
def test_host_under_valgrind_has_no_memory_errors_or_leaks(host, native_dir, fmu_path, tmp_path, name, parameters,
                                                           fmi):
    done = subprocess.run([*VALGRIND, str(host), *host_command(native_dir, fmu_path, name, fmi, tmp_path,
                                                                parameters)],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr[-3000:]
    assert "ERROR SUMMARY: 0 errors from 0 contexts" in done.stderr
    assert "definitely lost" not in done.stderr or re.search(r"definitely lost: 0 bytes", done.stderr)
