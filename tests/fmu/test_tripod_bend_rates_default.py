"""TripodCoupling's default for a host that sets only beta (beta_rate = 2, automatic), through the
FMUs of both families and both FMI versions: the bend ramp 5 -> 30 deg in 0.1 s at 2000 rpm
(beta = beta_0 + delta (s - sin 2 pi s / 2 pi), the moving-bearing tests' ramp), host step 1e-4 s
(the default experiment's), inputs set at the start of each step. The reference is the same FMU
given the ramp's exact rates (beta_rate = 0, beta_dot and beta_ddot set): the rates' own effect
is tested against the multibody model in test_tripod_moving_bearing.py."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from driveline.tripod.model import RATES_ESTIMATED
from driveline.tripod.spec import RATES_AUTOMATIC, RATES_FROM_INPUTS, SPEC
from fmu_harness.packaging import native
from support import tripod_multibody

RPM = math.pi / 30.0
STEP = SPEC.default_experiment.step_size
SMOOTH = tripod_multibody.Case(math.radians(5.0), 0.0, 2000 * RPM, beta_end=math.radians(30.0), ramp_time=0.1)
PLUNGERS = ("F_plunger1", "F_plunger2", "F_plunger3")


def linear(t: float) -> tuple[float, float, float]:
    """The bend ramp at a constant rate from its start: 250 deg/s over the 0.1 s."""
    rate = math.radians(25.0) / 0.1
    return math.radians(5.0) + rate * min(t, 0.1), rate if t < 0.1 else 0.0, 0.0


def smooth(t: float) -> tuple[float, float, float]:
    return SMOOTH.bend(t, 0.0)


def run(family, fmi: str, bend, parameters: dict, rates: bool) -> tuple[np.ndarray, list]:
    """The plungers' axial forces at the start and after each step (rows), and the log; ``rates``:
    the host sets beta_dot and beta_ddot besides beta."""
    rows = []
    with family.open("TripodCoupling", fmi) as fmu:

        def inputs(t: float) -> None:
            beta, rate, acceleration = bend(t)
            fmu.set({"beta": beta, **({"beta_dot": rate, "beta_ddot": acceleration} if rates else {})})

        fmu.enter_initialization(parameters)
        inputs(0.0)
        fmu.exit_initialization()
        rows.append(fmu.get(PLUNGERS))
        for k in range(round(0.1 / STEP)):
            inputs(k * STEP)
            fmu.step(STEP)
            rows.append(fmu.get(PLUNGERS))
        return np.array(rows), [(record.status, record.message) for record in fmu.log]


def test_the_default_is_automatic():
    assert SPEC["beta_rate"].start == RATES_AUTOMATIC


@pytest.mark.parametrize("kinematics", [0, 1])
def test_a_host_setting_only_beta_gets_the_rates_and_one_information_line(family, fmi, kinematics):
    """Measured (both families, both versions, both kinematics): the plungers' axial forces within
    0.012 N of the exact rates' over the whole ramp (peak 136 N), where the former default,
    beta_rate = 0 with the rates unset, was quasi-static and 21.1 N off; the log holds one information line,
    at initialisation, saying so."""
    reference, quiet = run(family, fmi, smooth, {"kinematics": kinematics, "beta_rate": RATES_FROM_INPUTS}, True)
    default, log = run(family, fmi, smooth, {"kinematics": kinematics}, False)
    quasi_static, _ = run(family, fmi, smooth, {"kinematics": kinematics, "beta_rate": RATES_FROM_INPUTS}, False)
    assert np.abs(default - reference).max() < 0.02
    assert 19.0 < np.abs(quasi_static - reference).max() < 23.0
    assert log == [("OK", RATES_ESTIMATED)] and quiet == []  # information (a default in use), not a warning


@pytest.mark.parametrize("bend", [smooth, linear], ids=["smooth", "linear"])
def test_a_host_setting_the_rates_gets_them_bit_for_bit(family, fmi, bend):
    """beta_rate = 2 takes the inputs once the host has set one non-zero: the same bits as
    beta_rate = 0, and the samples before (the smooth ramp's rates are 0 at its start, where both
    give 0). A host that sets a rate at the start is not warned."""
    given, log = run(family, fmi, bend, {"kinematics": 1}, True)
    inputs, _ = run(family, fmi, bend, {"kinematics": 1, "beta_rate": RATES_FROM_INPUTS}, True)
    np.testing.assert_array_equal(given, inputs)
    assert log == ([] if bend is linear else [("OK", RATES_ESTIMATED)])


def test_the_start_of_a_ramp_without_its_rates_is_the_samples_lead_in(family, fmi):
    """A ramp at 250 deg/s from t = 0 (no smooth start): the samples give no rate at the start and
    over the first step, as the warning says, so those two outputs are the quasi-static ones
    (measured up to 8.5 N off, the Coriolis force 2 m r sec^2(beta) beta_dot omega sin(phi)); from
    the second step the estimate is exact on the ramp, within 1e-6 N (measured 1.1e-10 N)."""
    reference, _ = run(family, fmi, linear, {"kinematics": 1, "beta_rate": RATES_FROM_INPUTS}, True)
    default, _ = run(family, fmi, linear, {"kinematics": 1}, False)
    quasi_static, _ = run(family, fmi, linear, {"kinematics": 1, "beta_rate": RATES_FROM_INPUTS}, False)
    np.testing.assert_array_equal(default[:2], quasi_static[:2])
    assert np.abs(default[2:] - reference[2:]).max() < 1e-6
    assert np.abs(default[:2] - reference[:2]).max() > 1.0


def test_the_default_is_said_only_to_a_host_that_asks_for_logging(native_dir, fmi, tmp_path):
    """fmpy's command line on the native FMU, only beta set: silent by default; with --debug-logging
    (loggingOn) the one information line, status OK."""
    fmu = native.fmu_path(native_dir, "TripodCoupling", fmi)
    command = [str(Path(sys.executable).with_name("fmpy")), "simulate", str(fmu), "--stop-time", "0.01",
               "--start-values", "beta", "0.2", "--output-file", str(tmp_path / "run.csv")]
    quiet = subprocess.run(command, capture_output=True, text=True, timeout=120)
    logged = subprocess.run([*command, "--debug-logging"], capture_output=True, text=True, timeout=120)
    assert quiet.returncode == 0 and logged.returncode == 0
    assert "beta_rate" not in quiet.stdout + quiet.stderr
    assert [line for line in logged.stdout.splitlines() if "beta_rate" in line] == [f"[OK] {RATES_ESTIMATED}"]
