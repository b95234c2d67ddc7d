"""The rotor library's own complex type (``models/critical_speeds/cplx.h``, standard C99 that MSVC also
compiles) rounds every operation as the C99 complex arithmetic it replaced did on the reference
platform (gcc's operators and libgcc's division, glibc's csqrt, cexp and cabs on x86_64 Linux): the
native CriticalSpeeds FMU's results stay bit for bit those of before, and are the same on every
platform. ``tests/native/native_complex_check.c`` compares both on random operands of every magnitude and
on the special values."""

from __future__ import annotations

import platform
import shutil
import subprocess
from pathlib import Path

import pytest

from fmu_harness.packaging import native

CHECK_SOURCE = Path(__file__).with_name("native_complex_check.c")
REFERENCE = platform.system() == "Linux" and platform.machine() == "x86_64" and platform.libc_ver()[0] == "glibc"
GCC = shutil.which("gcc")


@pytest.mark.skipif(not REFERENCE, reason="the reference platform of the C99 complex arithmetic is x86_64 Linux, glibc")
@pytest.mark.skipif(GCC is None, reason="the reference compiler is gcc (libgcc's complex division); Debian: apt-get install gcc")
def test_the_own_complex_type_rounds_as_c99_complex_arithmetic(tmp_path):
    executable = tmp_path / "native_complex_check"
    # C11 for CMPLX (exact operands with infinite or NaN parts); the header itself is C99
    subprocess.run([GCC, "-std=c11", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2",
                    "-I", str(native.model_folder("CriticalSpeeds")), str(CHECK_SOURCE), "-o", str(executable), "-lm"],
                   check=True, capture_output=True, text=True)
    done = subprocess.run([str(executable), "400000"], capture_output=True, text=True)
    mismatches = {name: int(count) for name, count in (line.split() for line in done.stdout.splitlines())}
    assert set(mismatches) == {"div", "sqrt", "expi", "abs", "mul", "scale", "div_real", "add_real"}
    assert mismatches == dict.fromkeys(mismatches, 0)
    assert done.returncode == 0
