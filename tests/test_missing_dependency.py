"""A host whose Python lacks a dependency of the FMU gets a message saying what to install."""

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
