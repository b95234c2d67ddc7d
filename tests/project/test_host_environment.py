"""Hosts that load the FMUs in unusual ways: without their dependencies, or several one after another."""

from __future__ import annotations

import subprocess
import sys

import pytest

HOST = """
import sys
sys.modules["scipy"] = None  # this host's Python has no scipy
from fmpy import simulate_fmu
try:
    simulate_fmu(sys.argv[1], debug_logging=True, logger=lambda *args: print("LOG", args[-1]))
except Exception as error:
    print("REFUSED", error)
"""


@pytest.mark.parametrize("version", ["2", "3"])
def test_missing_package_is_named_with_the_remedy(fmu_path, version):
    path = fmu_path("CriticalSpeeds", version)  # its transfer-matrix core needs scipy
    host = subprocess.run([sys.executable, "-c", HOST, str(path)], capture_output=True, text=True, timeout=120)
    said = host.stdout + host.stderr
    assert "REFUSED" in host.stdout  # the host process itself carried on
    assert "cannot import" in said and "scipy" in said and "requirements.txt" in said and "deploy" in said


SEQUENCE = """
import os, sys
from fmpy import simulate_fmu
for path in sys.argv[1:]:
    print(len(simulate_fmu(path)), flush=True)
os._exit(0)
"""  # os._exit: the wrappers write freed memory at a normal exit (docs/robustness.md, defect 10)


@pytest.mark.parametrize("version", ["2", "3"])
def test_different_fmus_one_after_another_in_one_host(fmu_path, tmp_path, version):
    """fmpy deletes each FMU's folder after a run; the next FMU must not depend on modules
    the previous one left cached from there (a host that has not imported the package itself)."""
    paths = [fmu_path(name, version) for name in ("CardanJoint", "CriticalSpeeds", "TripodCoupling", "CriticalSpeeds")]
    host = subprocess.run([sys.executable, "-c", SEQUENCE, *map(str, paths)], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)
    assert host.returncode == 0, host.stderr[-2000:]
    assert len([line for line in host.stdout.splitlines() if line.isdigit()]) == len(paths)  # beside log lines
