"""Every FMU instance in one host process receives its own log messages.

fmpy formats FMI 2.0 messages in a native proxy that forwards them to the Python logger
registered last, so with plain fmpy every message of every FMI 2.0 instance reaches the
instance created last; the harness gives each instance its own callbacks and routes by the
``componentEnvironment`` the FMU passes back (``fmu_harness.runs.runner.Fmi2LogRouter``). FMI 3.0
passes each instance its own callback; both versions and both families are checked.
"""

from __future__ import annotations

import math

import pytest

from fmu_harness.runs.runner import StepRefused
from fmu_harness.studies import coupling_comparison

TOO_BENT = 1.5  # rad: beyond beta_max of CardanJoint (45 deg) and TripodCoupling (at most 60 deg)


@pytest.mark.parametrize("pair", [("CardanJoint", "CardanJoint"), ("CardanJoint", "TripodCoupling")])
def test_each_refusal_is_logged_to_the_instance_that_refused(family, pair, fmi):
    with family.open(pair[0], fmi, "first") as first, family.open(pair[1], fmi, "second") as second:
        first.initialize()
        second.initialize()
        for refusing, other in ((first, second), (second, first)):
            logged_by_other = list(other.log)
            refusing.set({"beta": TOO_BENT})
            with pytest.raises(StepRefused) as refused:
                refusing.step(1e-3)
            assert refused.value.status == "Discard"
            assert any("beta" in message for message in refused.value.messages), refused.value.messages
            assert refusing.log[-1].message == refused.value.messages[-1]
            assert other.log == logged_by_other
        # each logged its refusal alone (besides the information lines of the defaults in use, status OK)
        refusals = [[record for record in fmu.log if record.status not in ("OK", "Warning")] for fmu in (first, second)]
        assert len(refusals[0]) == len(refusals[1]) == len(refused.value.messages)


def test_two_joint_cardan_shaft_reports_the_first_joints_refusal(fmi, fmu_dir):
    """The two-joint shaft creates joint 2 after joint 1; joint 1 refuses the bend angle."""
    models = fmu_dir if fmi == "2" else fmu_dir / "fmi3"
    with pytest.raises(StepRefused) as refused:
        coupling_comparison.cardan_shaft(models, math.radians(50.0), math.pi / 2, 1e-4, turns=0.01)
    assert refused.value.time == 0.0
    assert any("beta" in message and "beta_max" in message for message in refused.value.messages), refused.value.messages
