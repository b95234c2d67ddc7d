"""What the ``CriticalSpeeds`` FMU reports about unbalance: response, bearing force, damping.

Built once per analysis from the damped finite-element model (:class:`DampedRotor`, up to
FE_ELEMENTS beam elements per segment): a step solves the synchronous response at the current speed (one
banded solve) and interpolates a table of the damped modes over ``[0, omega_max]`` (from a
coarser model, TABLE_ELEMENTS per segment).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import CubicSpline

from .damped import DampedRotor
from .driveline import EXCITED_SHARE, SEARCH_LIMIT, Driveline
from .elements import Unbalance
from .fem import elements_by_length

#: Beam elements on a segment of half the driveline's length or longer, proportionally fewer on a
#: shorter one (:func:`.fem.elements_by_length`). Timoshenko elements converge as h**2: at 16 the first
#: three whirl frequencies of the default tube and of the two-piece examples lie within 6.5e-5 of the
#: exact transfer-matrix roots (2.8e-5 at 24, for 2.4 times the cost of the mode table).
FE_ELEMENTS = 16
#: Beam elements per segment of the model whose damped modes are tabulated: the first four
#: excited modes' damping ratios lie within 0.4 % (frequencies 0.15 %) of a 48-element model's for
#: the tube and the hinged two-piece example at 800 rad/s; the eigenproblems stay small.
TABLE_ELEMENTS = 8
#: Speeds at which the damped modes are tabulated over [0, omega_max] (cubic splines between them).
DAMPING_POINTS = 11
#: Modes tabulated per speed: the lowest that unbalance excites (forward share >= EXCITED_SHARE).
DAMPED_MODES = 4


@dataclass(frozen=True)
class UnbalanceOutputs:
    """The damped model, its unbalance load, the response row at the chosen position and the mode table
    (``modes(speed)`` = damped frequencies of DAMPED_MODES modes, then their damping ratios)."""

    rotor: DampedRotor
    load: NDArray[np.complex128]
    row: NDArray[np.complex128]
    modes: CubicSpline

    @classmethod
    def build(cls, driveline: Driveline, unbalances: Sequence[Unbalance], response_fraction: float,
              omega_max: float) -> UnbalanceOutputs:
        """Outputs for ``unbalances`` on ``driveline``, the response taken at ``response_fraction`` of its length."""
        rotor, coarse = (DampedRotor(driveline, elements_by_length(driveline, most))
                         for most in (FE_ELEMENTS, TABLE_ELEMENTS))
        spins = np.linspace(0.0, omega_max, DAMPING_POINTS)
        table = np.empty((spins.size, 2 * DAMPED_MODES))
        for i, spin in enumerate(spins):
            excited = [m for m in coarse.modes(spin, 4 * DAMPED_MODES) if m.forward_share >= EXCITED_SHARE]
            excited = excited[:DAMPED_MODES]
            missing = DAMPED_MODES - len(excited)  # a short model: beyond the search limit, undamped
            table[i, :DAMPED_MODES] = [m.frequency for m in excited] + [SEARCH_LIMIT] * missing
            table[i, DAMPED_MODES:] = [m.damping_ratio for m in excited] + [0.0] * missing
        row = rotor.shape_rows([response_fraction * driveline.length])
        return cls(rotor, rotor.load(unbalances), row, CubicSpline(spins, table))

    def evaluate(self, speed: float) -> tuple[float, float, float]:
        """Major semi-axis of the orbit at the chosen position [m], the largest bearing force [N]
        and the damping ratio of the tabulated mode nearest ``speed`` [rad/s] (an undamped
        resonance hit exactly gives an infinite response, which the model refuses)."""
        table = self.modes(speed)
        zeta = float(table[DAMPED_MODES + int(np.argmin(np.abs(table[:DAMPED_MODES] - speed)))])
        if speed == 0.0:
            return 0.0, 0.0, zeta
        try:
            solution = self.rotor.solve(speed, self.load)[None, :]
        except ArithmeticError:
            return np.inf, np.inf, zeta
        forward, backward = self.rotor.components(solution, self.row)
        forces = self.rotor.bearing_forces([speed], solution)
        return float(abs(forward[0, 0]) + abs(backward[0, 0])), float(np.max(forces, initial=0.0)), zeta
