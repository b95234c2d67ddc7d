"""Energy balance of the closed launch loop in the monolithic reference (fmu_harness.runs.launch_energy)."""

from __future__ import annotations

from fmu_harness.runs import launch_energy


def test_the_motor_work_is_stored_or_dissipated():
    """The first 50 ms of the launch: the motor's 2.5 J go into the drive's, halfshafts', tyres' and
    plungers' energies and the damping, friction, slip and road losses to 1e-6 of it (measured 4e-8, the
    integration's rtol 1e-10 over a loop amplifying it); the powertrain's mounting balances the housing
    loads' work to 1e-9 (measured 3e-14). Each loss and store is above 1e-6 of the work, so leaving any
    out breaks the balance."""
    found = launch_energy.balance(0.05)
    assert abs(found["loop residual"]) <= 1e-6
    assert abs(found["mounting residual"]) <= 1e-9
    for name in ("halfshaft damping", "joint friction", "tyre slip", "road load", "change of drive",
                 "change of halfshafts", "change of tyres", "change of plungers"):
        assert found[name] > 1e-6 * found["motor work"], name
