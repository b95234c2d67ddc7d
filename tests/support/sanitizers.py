"""The native FMUs' carried sources built with a fuzzing host (``sanitizer_fuzz.c`` beside this file) under
AddressSanitizer and UndefinedBehaviorSanitizer (gcc's, Debian's libasan and libubsan), and its runs: each
in a process of its own with a time limit and a limit on resident memory."""

from __future__ import annotations

import functools
import os
import re
import subprocess
import tempfile
from pathlib import Path

from fmpy import extract

from fmu_harness.packaging import native, toolchain

FUZZ_SOURCE = Path(__file__).with_name("sanitizer_fuzz.c")
#: -fno-sanitize-recover: the first report ends the run with a non-zero exit; float-cast-overflow is not part
#: of gcc's -fsanitize=undefined.
SANITIZE = ("-fsanitize=address,undefined,float-cast-overflow", "-fno-sanitize-recover=all", "-fno-omit-frame-pointer")
#: The FMUs are built warning-free by zig's clang (fmu_harness.packaging.toolchain); gcc's -pedantic and
#: -Wtype-limits find more in them, which is no sanitizer's business here.
FLAGS = ("-std=c99", "-O1", "-g", "-ffp-contract=off")
ENVIRONMENT = {"ASAN_OPTIONS": "detect_leaks=1:halt_on_error=1:hard_rss_limit_mb=1024:allocator_may_return_null=1",
               "UBSAN_OPTIONS": "halt_on_error=1:print_stacktrace=1"}
TIME_LIMIT = 300.0  # s: a run takes a few seconds


@functools.cache
def available() -> str | None:
    """Why sanitizer builds cannot run here, or None: a C compiler that links both sanitizers' runtimes."""
    compiler = toolchain.system_compiler()
    if compiler is None:
        return "no system C compiler (Debian: apt-get install gcc)"
    with tempfile.TemporaryDirectory() as folder:
        probe = Path(folder) / "probe.c"
        probe.write_text("int main(void) { return 0; }\n")
        done = subprocess.run([compiler, *SANITIZE, str(probe), "-o", str(Path(folder) / "probe")],
                              capture_output=True, text=True)
        if done.returncode:
            return f"{compiler} cannot link ASan and UBSan (Debian: apt-get install libasan8 libubsan1)"
    return None


def build(fmu: Path, fmi: str, folder: Path) -> tuple[Path, Path]:
    """The fuzzing host linked with ``fmu``'s sources, and the FMU's resources folder."""
    unzipdir = Path(extract(str(fmu), unzipdir=str(folder / "fmu")))
    executable = folder / "sanitizer_fuzz"
    sources = sorted(str(path) for path in (unzipdir / "sources").rglob("*.c"))
    done = subprocess.run([toolchain.system_compiler(), *FLAGS, *SANITIZE, f"-DFMI_VERSION={fmi}",
                           "-I", str(unzipdir / "sources"), "-isystem", str(native.fmi_headers()), *sources,
                           str(FUZZ_SOURCE), "-o", str(executable), "-lm"], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"the sanitized build of {fmu.name} failed:\n{done.stderr[-4000:]}")
    return executable, unzipdir / "resources"


def run(executable: Path, resources: Path, mode: str, seed: int = 0, cases: int = 0) -> tuple[int, str, dict[str, int]]:
    """A run of the fuzzing host: its exit code, what it and the sanitizers printed, and its counts of calls and
    cases (empty if it did not end normally); with mode "targets", each target's cases as "target <function>"."""
    command = [str(executable), mode, str(seed), str(cases), str(resources)]
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=TIME_LIMIT,
                              env={**os.environ, **ENVIRONMENT})
    except subprocess.TimeoutExpired:
        return -1, f"no end within {TIME_LIMIT} s", {}
    words = done.stdout.split()
    counts = {}
    if done.returncode == 0 and words[-4:-3] == ["calls"]:
        counts = {"calls": int(words[-3]), "cases": int(words[-1])}
        counts.update((f"target {name}", int(n)) for name, n in re.findall(r"^target (\w+) cases (\d+)$",
                                                                           done.stdout, re.MULTILINE))
    return done.returncode, done.stdout[-3000:] + done.stderr[-6000:], counts
