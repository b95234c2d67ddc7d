"""The couplings side by side (the tripod as plain, single and double roller joint), and the two-joint
Cardan shaft co-simulation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from driveline.cardan.kinematics import speed_fluctuation
from fmu_harness.studies import coupling_comparison as comparison


def test_fluctuation_and_dominant_order_of_each_coupling(fmi2_dir):
    rows = {(r["coupling"], r["beta_deg"]): r for r in comparison.speed_fluctuation_table(fmi2_dir, [10.0, 30.0])}
    for beta in (10.0, 30.0):
        cardan = rows[("CardanJoint", beta)]
        assert cardan["order"] == 2
        # one-degree sampling misses the exact extremes by < 1e-4 relative
        assert cardan["fluctuation"] == pytest.approx(float(speed_fluctuation(math.radians(beta))), rel=1e-4)
        assert rows[("TripodCoupling", beta)]["order"] == 3
        assert rows[("TripodCoupling", beta)]["fluctuation"] < 0.02 * cardan["fluctuation"]
        assert rows[("UniversalReducer", beta)]["order"] is None
        # the roller tripods turn on the plain tripod's closure: its output speed, bit for bit
        for roller in ("TripodCoupling single roller", "TripodCoupling double roller"):
            assert rows[(roller, beta)] | {"coupling": "TripodCoupling"} == rows[("TripodCoupling", beta)]


def fluctuation(speed: np.ndarray) -> float:
    settled = speed[len(speed) // 4:]
    return float(np.ptp(settled) / np.mean(settled))


def test_two_cardan_joints_cancel_when_phased_and_double_when_not(fmi2_dir):
    beta = math.radians(20.0)
    single = float(speed_fluctuation(beta))
    steps = (1e-4, 1e-5)
    phased = [fluctuation(comparison.cardan_shaft(fmi2_dir, beta, math.pi / 2, h)["omega_out"]) for h in steps]
    wrong = fluctuation(comparison.cardan_shaft(fmi2_dir, beta, 0.0, 1e-5)["omega_out"])
    # The second joint integrates the first one's speed held over each communication step, so the
    # cancellation leaves a residue of first order in the step: measured 4.0e-3 and 4.0e-4.
    assert phased[0] < 0.05 * single and phased[1] < 0.005 * single
    assert phased[0] / phased[1] == pytest.approx(10.0, rel=0.1)
    assert wrong == pytest.approx(2 * single, rel=0.01)
