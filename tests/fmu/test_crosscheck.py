"""The FMI Cross-Check reference files: every FMU, Python and native, re-run from its _in.csv and
_ref.opt alone (fmpy's simulate_fmu) reproduces its _ref.csv."""

from __future__ import annotations

import numpy as np
from fmpy import read_model_description

from fmu_harness.checks import crosscheck
from fmu_harness.packaging import native


def test_rerun_from_the_reference_files_matches(model_name, fmi, fmu_path, tmp_path):
    rerun_matches(fmu_path(model_name, fmi), model_name, tmp_path)


def test_native_rerun_from_the_reference_files_matches(model_name, fmi, native_dir, tmp_path):
    rerun_matches(native.fmu_path(native_dir, model_name, fmi), model_name, tmp_path)


def rerun_matches(built, model_name, tmp_path):
    fmu = tmp_path / built.name
    fmu.write_bytes(built.read_bytes())
    written = {path.name for path in crosscheck.write(fmu)}
    has_inputs = any(v.causality == "input" for v in read_model_description(str(fmu)).modelVariables)
    assert written == {f"{model_name}_ref.csv", f"{model_name}_ref.opt"} | ({f"{model_name}_in.csv"} if has_inputs else set())
    reference, result = crosscheck.rerun(fmu)
    assert 2 <= len(reference.dtype.names) <= 11 and reference.dtype.names[0] == "time"
    np.testing.assert_allclose(result["time"], reference["time"], rtol=0, atol=1e-12)
    # The same code on the same inputs; only the hosts' time grids differ (our harness adds
    # the step size up, fmpy multiplies it), which moves interpolated inputs by ~1 ulp.
    for name in reference.dtype.names[1:]:
        scale = np.abs(reference[name]).max() or 1.0
        np.testing.assert_allclose(result[name], reference[name], rtol=0, atol=crosscheck.REL_TOL * scale, err_msg=name)
