"""``--cpu-total``: the CPU seconds the durations file holds for the selected tests, the number
docs/development.md quotes for the quick run and the whole suite, generated without running them."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TESTS = "tests/core/test_cardan_core.py"


def test_the_cpu_total_is_the_durations_files_sum_over_the_selected_tests():
    run = subprocess.run([sys.executable, "-m", "pytest", "-q", "--collect-only", "--cpu-total", "-p", "no:randomly",
                          "-p", "no:cacheprovider", TESTS], capture_output=True, text=True, cwd=ROOT, check=True)
    lines = run.stdout.splitlines()
    collected = [line for line in lines if line.startswith(f"{TESTS}::")]
    durations = json.loads((ROOT / "tests" / "durations.json").read_text())["cpu_seconds"]
    total = sum(durations.get(nodeid, 0.0) for nodeid in collected)
    unmeasured = sum(nodeid not in durations for nodeid in collected)
    (line,) = [line for line in lines if line.startswith("cpu total: ")]
    assert collected and line.startswith(f"cpu total: {total:.0f} s of CPU for {len(collected)} tests "
                                         f"({unmeasured} not measured; tests/durations.json of ")
    assert line.endswith(f"costliest files: {TESTS} {total:.0f} s")
