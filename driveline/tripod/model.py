"""Time stepping of the tripod coupling: integrates phi_in, evaluates kinematics and forces."""

from __future__ import annotations

from ..model import DrivenShaftModel
from .outputs import coupling_outputs
from .plane_solver import Solution
from .rollers import NOT_CONVERGED
from .spec import (CLOSED_FORM, DOUBLE_ROLLER, EXACT, PLAIN_TRIPOD, RATES_AUTOMATIC, RATES_FROM_INPUTS,
                   RATES_FROM_SAMPLES, SINGLE_ROLLER, SPEC)

BETA_LEAVES_RANGE = "beta extrapolated to the end of the step, beta + beta_dot h + beta_ddot h^2/2, leaves [0, beta_max]"
RATES_ESTIMATED = ("beta_rate = 2 with beta_dot = beta_ddot = 0 at the start: the bend's rates are estimated from "
                   "the beta samples until the host sets either non-zero (or their input derivatives), so the "
                   "outputs at the start and after the first step have none, the second a constant rate")


def sampled_rates(samples: tuple[tuple[float, float], ...]) -> tuple[float, float]:
    """Rate and acceleration at the newest of up to three ``(time, beta)`` samples (newest first):
    the derivatives of the polynomial through them (Newton's divided differences); one sample
    gives zero rates, two a constant rate. Equal steps h: errors h^2 beta'''/3 and h beta'''."""
    if len(samples) < 2:
        return 0.0, 0.0
    (t0, b0), (t1, b1) = samples[0], samples[1]
    slope = (b0 - b1) / (t0 - t1)
    if len(samples) < 3:
        return slope, 0.0
    t2, b2 = samples[2]
    curvature = (slope - (b1 - b2) / (t1 - t2)) / (t0 - t2)
    return slope + curvature * (t0 - t1), 2.0 * curvature


class TripodCouplingModel(DrivenShaftModel):
    """The ``TripodCoupling`` co-simulation model: inputs set at a communication point, speed and
    bend following their rates over the step, outputs at the step's end."""

    spec = SPEC
    dependency_points = (
        {"kinematics": EXACT, "mu": 0.05, "seed_reactions": 1, "alpha_in": 30.0, "beta_dot": 0.5, "beta_ddot": 3.0,
         "phi_in_start": 0.4},
        {"beta_rate": RATES_FROM_SAMPLES, "beta_dot": 0.5, "phi_in_start": 0.4},
        {"kinematics": EXACT, "mu": 0.05, "alpha_in": 30.0, "beta_dot": 0.5, "beta_ddot": 3.0, "phi_in_start": 0.4},
        # the roller tripods, with every slip at 0.08 m/s (80 v_slip) or more at phi_in_start and at 0.4 rad
        # past it, where the derivatives' tests are: nearer to a slip's regularisation the core's
        # extrapolated differences lose their accuracy (31 v_slip: 1.3e-9)
        {"kinematics": EXACT, "mu": 0.05, "tripod_type": SINGLE_ROLLER, "alpha_in": 30.0, "beta_dot": 0.5,
         "phi_in_start": 0.2},
        {"kinematics": EXACT, "mu": 0.05, "tripod_type": DOUBLE_ROLLER, "T_load": -300.0, "beta_rate": RATES_FROM_INPUTS,
         "beta_ddot": 3.0, "phi_in_start": 0.55},  # its needles' slip: 2.5 v_slip at 0.8 rad, 93 from 0.55
        # the moving housing: the bend plane turned and turning, the spider plunging (groove slips of 20 mm/s
        # and more), with the seed's eqs turned into the housing's frame
        {"kinematics": EXACT, "mu": 0.05, "seed_reactions": 1, "alpha_in": 30.0, "beta_dot": 0.5, "beta_ddot": 3.0,
         "phi_in_start": 0.4, "psi": 0.7, "psi_dot": 4.0, "psi_ddot": 25.0, "plunge_dot": 0.02},
    )

    def reset_internal_state(self) -> None:
        self._solution: Solution | None = None  # warm start of the exact solver
        self._beta_samples: tuple[tuple[float, float], ...] = ()  # (time, beta), newest first, at most 2
        self._rates_set = False  # beta_rate = 2: the host has set beta_dot or beta_ddot non-zero

    def internal_from_saved(self, state: dict) -> dict:
        """The warm start (five floats, or none), the bend samples (up to two pairs of floats) and
        whether the host set the rates (a bool)."""
        if not isinstance(state["_rates_set"], bool):
            raise ValueError("the saved choice of the bend's rates is not a bool")
        samples = state["_beta_samples"]
        if not (isinstance(samples, tuple) and len(samples) <= 2
                and all(isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(v, float) for v in pair)
                        for pair in samples)):
            raise ValueError("the saved bend samples are not up to two (time, beta) pairs of floats")
        saved = state["_solution"]
        if saved is None:
            return {}
        if not (isinstance(saved, tuple) and len(saved) == len(Solution._fields)
                and all(isinstance(value, float) for value in saved)):
            raise ValueError(f"the saved warm start of the solver is not {len(Solution._fields)} floats")
        return {"_solution": Solution(*saved)}

    native_constants = {"RATES_FROM_INPUTS": RATES_FROM_INPUTS, "RATES_FROM_SAMPLES": RATES_FROM_SAMPLES,
                        "RATES_AUTOMATIC": RATES_AUTOMATIC, "BETA_LEAVES_RANGE": BETA_LEAVES_RANGE,
                        "RATES_ESTIMATED": RATES_ESTIMATED, "ROLLERS_NOT_CONVERGED": NOT_CONVERGED}

    extra_parameter_probes = {"friction_needs_exact": {"mu": 0.05, "kinematics": CLOSED_FORM},
                              "rollers_need_exact": {"tripod_type": SINGLE_ROLLER, "kinematics": CLOSED_FORM}}

    def extra_parameter_errors(self) -> list[str]:
        if self.mu > 0.0 and self.kinematics != EXACT:
            return [f"friction mu = {self.mu!r} needs the exact kinematics (kinematics = {EXACT})"]
        if self.tripod_type != PLAIN_TRIPOD and self.mu_roll > 0.0 and self.kinematics != EXACT:
            return [f"the roller tripod's rolling resistance mu_roll = {self.mu_roll!r} needs the exact kinematics "
                    f"(kinematics = {EXACT})"]
        return []

    def start_notice(self) -> str | None:
        """The automatic rates with none set: the host learns that they are estimated, and how to give them."""
        return RATES_ESTIMATED if self.beta_rate == RATES_AUTOMATIC and not self._rates_set else None

    def start(self, start_time: float) -> None:
        self._solution = None
        self._beta_samples = ()
        self._rates_set = False
        super().start(start_time)

    def advance(self, current_time: float, step_size: float) -> None:
        """phi_in advances by ``omega_in h + alpha_in h^2 / 2`` (exact on a linear speed ramp)."""
        self.phi_in = self.phi_in + (self.omega_in + 0.5 * self.alpha_in * step_size) * step_size
        self._evaluate(current_time, step_size)

    def evaluate(self, input_time: float) -> None:
        """Outputs at the current phi_in and inputs."""
        self._evaluate(input_time, 0.0)

    def _evaluate(self, input_time: float, elapsed: float) -> None:
        """Outputs ``elapsed`` after ``input_time``, with speed and bend moved on by their rates."""
        beta_dot, beta_ddot = self.beta_dot, self.beta_ddot
        if self.beta_rate != RATES_FROM_INPUTS:  # the samples are kept for the automatic choice too
            samples = ((input_time, self.beta),) + tuple(s for s in self._beta_samples if s[0] < input_time)
            self._beta_samples = samples[:2]
            self._rates_set = self._rates_set or beta_dot != 0.0 or beta_ddot != 0.0
            if self.beta_rate == RATES_FROM_SAMPLES or not self._rates_set:
                beta_dot, beta_ddot = sampled_rates(samples[:3])
        beta = self.beta + (beta_dot + 0.5 * beta_ddot * elapsed) * elapsed
        if not 0.0 <= beta <= self.beta_max:
            raise ValueError(BETA_LEAVES_RANGE)
        psi = self.psi + (self.psi_dot + 0.5 * self.psi_ddot * elapsed) * elapsed
        values, self._solution = coupling_outputs(
            self.phi_in, beta, self.omega_in + self.alpha_in * elapsed, self.T_load,
            self.r, self.l, self.m_plunger, self.kinematics, self._solution, self.alpha_in, self.seed_reactions,
            self.mu, self.v_slip, beta_dot + beta_ddot * elapsed, beta_ddot, self.tripod_type, self.mu_roll,
            self.roller_radius, psi, self.psi_dot + self.psi_ddot * elapsed, self.psi_ddot, self.plunge_dot,
            self.roller_bore_radius,
        )
        self.__dict__.update(values)
