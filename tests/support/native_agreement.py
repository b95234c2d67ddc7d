"""What the native FMUs promise against the Python core and FMUs: each output within its tolerance
of its largest magnitude over a run, and the refusals' words up to what a second implementation
words its own way."""

from __future__ import annotations

import re

from pathlib import Path

import numpy as np

from driveline.mounts.halfshafts import GEOMETRY
from driveline.mounts.layout import MAX_MOUNTS
from driveline.mounts.rigid_body import COORDINATES
from driveline.mounts.spec import BRANCH_FORCES, BRANCH_RATES
from fmu_harness.runs.runner import FmuInstance, StepRefused

# Both sides evaluate the same formulas in float64, but numpy's and libm's sin, cos, atan2 may
# differ in the last bit: outputs must agree within this fraction of each signal's largest magnitude.
TOLERANCE = 1e-12
# The critical speeds come from root searches that stop within a tolerance of their own. The damping
# ratio is the small real part of an eigenvalue, which a backward-stable eigensolver fixes to about
# eps max|lambda| only, where max|lambda| is the finite-element model's highest mode, 100 to 1000
# times the first: 1e-10 to 1e-9 of zeta's own size (measured between the two implementations: 6.8e-11
# in the standard scenario, 1.5e-9 in the property test; numpy's own error against a 40-digit
# reference is of the same order). The unbalance response and the bearing force carry the banded
# solve's rounding amplified by the resonance, up to 1 / (2 zeta) = 330 (measured up to 2.6e-12 here,
# 1.1e-10 at 0.07 % from the resonance in the rotor library's own test).
SIGNAL_TOLERANCE = {"omega_crit_1": 1e-10, "omega_crit_2": 1e-10, "omega_crit_3": 1e-10, "damping_ratio": 1e-8,
                    "unbalance_response": 1e-9, "bearing_force_max": 1e-9}
# PowertrainMounts' motion and mount forces: scipy's expm takes the lowest Pade degree (3 to 13) that
# suffices for the step's norm, the C port always 13, so the propagators differ in the last bits and the
# state carries that over every step of a lightly damped motion (measured 1.1e-11 of the largest
# displacement after 3000 steps of 1e-4 s on a random four-mount layout, 8.5e-13 after 300 of 1e-3 s);
# the modal table comes from two eigensolvers (LAPACK, Jacobi): its shares within 1.2e-13.
SIGNAL_TOLERANCE |= {f"{name}{suffix}": 1e-10 for name in COORDINATES for suffix in ("", "_dot", "_ddot")}
SIGNAL_TOLERANCE |= {f"F_{axis}_mount{i}": 1e-10 for i in range(1, MAX_MOUNTS + 1) for axis in "xyz"}
# The modes' kinetic-energy shares are fractions of 1 (each mode's sum to one), their scale. About a progressive
# operating point they take the tangent rates at the two cores' equilibria, equal to Newton's last step (1e-14 of
# the displacement); an eigenvector moves by that change over the relative gap to the next mode (modes 3 and 4 of
# the rubber default at idle lie 7 % apart), so shares agree within 1e-11 (measured up to 7.0e-12; 1.2e-13 on
# linear mounts).
SHARES = tuple(f"share_{j}_{name}" for j in range(1, 7) for name in COORDINATES) + tuple(
    f"mode_{j}_share" for j in range(1, 7))
SIGNAL_TOLERANCE |= dict.fromkeys(SHARES, 1e-11)
# The Maxwell branches' forces are that state too, their rates computed from it (measured up to 4.4e-11 of the
# largest branch force over 100 steps of 1 ms on linear rubber mounts, 2026-12-07).
SIGNAL_TOLERANCE |= {name: 1e-10 for name in (*BRANCH_FORCES, *BRANCH_RATES)}
# The halfshafts' geometry is computed from that motion and carries its differences (measured 1.2e-12 of the
# largest bend-plane rate after 40 steps of 1 ms).
SIGNAL_TOLERANCE |= {f"{name}_{side}": 1e-10 for name in GEOMETRY for side in ("left", "right")}
# The resonance margin is omega / omega_res - 1, a quotient near 1 less 1: its rounding is the
# quotient's, so it is measured against a scale of at least 1 (a drawn margin of 4.5e-4 differed by
# 1.1e-15 between the cores: 2.5e-12 of its own size, 1.1e-15 of the quotient's).
SCALE_FLOOR = {"resonance_margin": 1.0} | dict.fromkeys(SHARES, 1.0)
# On progressive mounts (the rubber default) the motion is measured from the weight's equilibrium, a Newton root:
# at rest the accelerations are the rounding of elastic forces of the weight's size, eps m g over the mounts' lever
# arms and the inertia (about 2e-14 rad/s2), the halfshafts' second rates that over the shaft and sin(beta), some
# ten times more; a motion under loads near zero carries that rounding through the implicit steps. Measured between
# the cores in the standard scenario (rest, 2026-12-07): up to 9e-18 m or rad, 6.3e-16 per s, 5.0e-14 per s2 (the
# left bend plane's); a drawn run whose motion stayed below 1e-21 m differed by 9e-24 m. So the motion is measured
# against a scale of at least these floors, where the tolerance 1e-10 is 1e-15 m or rad, 1e-14 per s, 1e-12 per
# s2: 16 to 100 times that rounding, and far below any motion a load gives (a newton moves the powertrain by
# micrometres and accelerates it by some 5e-3 m/s2).
SCALE_FLOOR |= {f"{name}{suffix}": floor for name in COORDINATES for suffix, floor in (("", 1e-5), ("_dot", 1e-4),
                                                                                      ("_ddot", 1e-2))}
# The wind-up is the rotation about the drive axis between two equilibria, each a Newton root settled to 1e-14 of
# the displacement (some 5e-17 rad on the default's sag of a few milliradians): under a mean torque near zero
# (a drawn -0.0019 N.m winds up some 2e-8 rad) the two cores' wind-ups differ by that rounding (measured 1.4e-11 of
# such a wind-up: 2.8e-19 rad, 2026-12-07). Its floor of 1e-3 rad makes the tolerance 1e-15 rad, ten times the two
# roots' bound and far below any wind-up a drive torque gives (1.5 deg, 0.025 rad, at 1.1 kN.m).
SCALE_FLOOR |= {"wind_up": 1e-3}
# The branches' forces follow that motion through their rates (1e4 to 1e5 N/m): their floors are the motion's
# times 1e5 N/m, 1 N and 10 N/s.
SCALE_FLOOR |= dict.fromkeys(BRANCH_FORCES, 1.0) | dict.fromkeys(BRANCH_RATES, 10.0)
SCALE_FLOOR |= {f"{name}_{side}": {"": 1e-5, "dot": 1e-4, "ddot": 1e-2}[name.split("_", 1)[1] if "_" in name else ""]
                for name in GEOMETRY for side in ("left", "right")}


#: Where the agreement rule ends: a quantity of up to this magnitude can be multiplied by another
#: (a mount force by its deflection, a step matrix's norm by a state) and stay finite; beyond about
#: sqrt(max float) = 1.3e154 equally valid orders of evaluation overflow in one core and not the other,
#: and the two cores' last digits stop meaning anything (a drawn PowertrainMounts run with an accepted
#: input of 1e300 N grew states of 1e290-1e294 that differed beyond the tolerance). A run is compared
#: up to its first row with an output beyond this; past it both cores must still refuse the same steps.
AGREEMENT_MAGNITUDE = 1e150


def within_the_agreement_range(core_rows: list[list[float]]) -> int:
    """How many leading rows hold only outputs of at most :data:`AGREEMENT_MAGNITUDE` (NaN, a
    refused output's value, does not end the range)."""
    for count, row in enumerate(core_rows):
        if np.any(np.abs(np.asarray(row, dtype=float)) > AGREEMENT_MAGNITUDE):
            return count
    return len(core_rows)


def scale(name: str, values: np.ndarray) -> float:
    """An output's largest magnitude, the scale its tolerance is relative to (at least its
    :data:`SCALE_FLOOR`; 1 for an output that stays zero)."""
    return max(float(np.abs(values).max()), SCALE_FLOOR.get(name, 0.0)) or 1.0


def deviations(reference: np.ndarray, other: np.ndarray) -> dict[str, float]:
    """Largest difference of each output, relative to that output's largest magnitude."""
    return {n: float(np.abs(reference[n] - other[n]).max() / scale(n, reference[n])) for n in reference.dtype.names}


def deviation(reference: np.ndarray, other: np.ndarray) -> float:
    """Largest difference of any output, relative to that output's largest magnitude."""
    return max(deviations(reference, other).values())


def beyond_tolerance(reference: np.ndarray, other: np.ndarray) -> dict[str, float]:
    """The outputs that differ by more than their tolerance (:data:`SIGNAL_TOLERANCE`, else TOLERANCE)."""
    return {n: d for n, d in deviations(reference, other).items() if not d <= SIGNAL_TOLERANCE.get(n, TOLERANCE)}


#: Where tomllib's and the C reader's words for a malformed TOML text begin.
MALFORMED = "malformed TOML: "


def up_to_the_toml_reason(message: str) -> str:
    """A message up to the reason of a malformed TOML text, which tomllib words in its own way, and
    without the nearest finite-element frequency of a failed plausibility check: that check fails
    where the eigenproblem is beyond double precision, and its lowest eigenvalues are round-off; nor
    the frequency of the free mode of PowertrainMounts' unrestrained layouts (the round-off of a zero
    eigenvalue)."""
    message = re.sub(r"\(nearest \S+ rad/s\)", "(nearest ... rad/s)", message)
    message = re.sub(r"unrestrained \(mode 1, mostly (\w+), at \S+ Hz", r"unrestrained (mode 1, mostly \1, at ... Hz",
                     message)
    return message[:message.index(MALFORMED) + len(MALFORMED)] if MALFORMED in message else message


def rows_beyond_tolerance(outputs: list[str], reference_rows: list[list[float]], rows: list[list[float]]) -> np.ndarray:
    """Rows of outputs (one row per step) against reference rows: each difference relative to its
    output's largest magnitude over the run, zeroed where it is within that output's tolerance."""
    reference, values = np.array(reference_rows, dtype=float), np.array(rows, dtype=float)
    scales = np.array([scale(n, reference[:, i]) for i, n in enumerate(outputs)])
    tolerances = np.array([SIGNAL_TOLERANCE.get(n, TOLERANCE) for n in outputs])
    relative = (values - reference) / scales
    return np.where(np.abs(values - reference) <= tolerances * scales, 0.0, relative)


def refusals(path: Path, parameters: dict) -> list[str]:
    """The reasons ``parameters`` are refused for at initialisation: the native FMU's Error, the
    Python FMU's messages (logged after the call's name, the wrappers returning OK)."""
    with FmuInstance(path) as fmu:
        first = len(fmu.log)
        try:
            fmu.initialize(parameters)
        except StepRefused as refused:
            return refused.messages
        return [message.removeprefix("exitInitializationMode: ") for message in fmu.messages_since(first)]
