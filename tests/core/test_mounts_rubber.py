"""PowertrainMounts on rubber: progressive characteristics, Maxwell branches, loaded equilibrium and modes.

The references share no code with driveline/mounts/: the characteristic written again from the
documentation's equations (C1), (C2), an equilibrium by scipy's hybrid root finder with a
finite-difference Jacobian, the poles of the linearised state-space (branches included) by a general
eigensolver, a mount's stiffness measured from a time-domain run of its branches (solve_ivp), each mode's
damping from a free decay's logarithmic decrement.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eig, eigh, expm
from scipy.optimize import root

from driveline.mounts import characteristic
from driveline.mounts.forces import BranchMap, elastic_energy
from driveline.mounts.implicit_step import implicit_step
from driveline.mounts.layout import load_layout, loads_layout, shipped_layout
from driveline.mounts.model import PowertrainMountsModel
from driveline.mounts.rigid_body import COORDINATES, RigidBody, point_map
from driveline.mounts.rubber import BAND, RELAXATION_FREQUENCIES, relative_stiffness, relaxation_times
from driveline.mounts.spec import AXES, LOAD_INPUTS, VELOCITIES, derivative_name
from driveline.mounts.system import MountSystem, Placement

#: A layout written for the linear model (linear rates, viscous loss factors) and the one on rubber.
LINEAR_LAYOUT = shipped_layout("transverse_fwd_powertrain")
RUBBER = "transverse_fwd_powertrain_rubber"
FULL_TORQUE = 2200.0  # N.m: the drive reaction at full motor torque (issue 42: 1.1 kN.m at half)


def _placement() -> Placement:
    """The spec's default joint placement, motor axis +y."""
    return Placement.of({"left": np.array([0.0, 0.22, 0.0]), "right": np.array([0.0, -0.28, 0.0])},
                        {"left": np.array([0.0, 1.0, 0.0]), "right": np.array([0.0, -1.0, 0.0])},
                        {"left": np.array([0.0, 0.0, 1.0]), "right": np.array([0.0, 0.0, 1.0])},
                        np.array([0.0, 1.0, 0.0]))


def _model(layout: str, **parameters: float) -> PowertrainMountsModel:
    model = PowertrainMountsModel()
    model.layout = layout
    for name, value in parameters.items():
        setattr(model, name, value)
    assert model.initialize(0.0) == []
    return model


# ---- a layout written for the linear model ------------------------------------------------------


def test_a_linear_layout_gives_the_linear_model_s_results_bit_for_bit():
    """The linear model's formulas written out (K^-1 W, eigh(K, M), the 24 x 24 exponential of Van Loan)
    give the model's outputs to the last bit: static sag, modes, shares, motion and mount forces."""
    model = _model(str(LINEAR_LAYOUT), T_mean=700.0)
    body = RigidBody.of(load_layout(LINEAR_LAYOUT))
    system = model._system
    weight = np.array([0.0, 0.0, -body.layout.mass * 9.81, 0.0, 0.0, 0.0])
    torque = np.array([0.0, 0.0, 0.0, 0.0, -700.0, 0.0])
    assert np.array_equal(np.linalg.solve(body.stiffness, weight + torque),
                          [getattr(model, f"{name}_static") for name in COORDINATES])
    values, shapes = eigh(body.stiffness, body.mass)
    assert np.array_equal(np.sqrt(values) / (2.0 * math.pi), [getattr(model, f"f_mode_{j}") for j in range(1, 7)])
    momenta = body.mass @ shapes
    shares = (shapes * momenta).T / np.sum(shapes * momenta, axis=0)[:, None]
    assert np.array_equal(shares, [[getattr(model, f"share_{j}_{n}") for n in COORDINATES] for j in range(1, 7)])
    inverse = np.linalg.inv(body.mass)
    z = np.zeros((24, 24))
    z[:6, 6:12], z[6:12, :6], z[6:12, 6:12] = np.eye(6), -inverse @ body.stiffness, -inverse @ body.damping
    h = 1e-3
    z[:12] *= h
    z[6:12, 12:18] = inverse * h
    z[12:18, 18:] = np.eye(6) * h
    e = expm(z)
    state = np.zeros(12)
    load, rate = np.array([300.0, -200.0, 500.0, 40.0, -60.0, 20.0]), np.array([1e4, 0.0, -2e4, 0.0, 5e3, 0.0])
    for name, value, slope in zip(LOAD_INPUTS, load, rate):
        setattr(model, name, value)
        setattr(model, derivative_name(name), slope)
    for k in range(20):
        assert model.step(k * h, h) == []
        state = e[:12, :12] @ state + e[:12, 12:18] @ load + e[:12, 18:] @ rate
    assert np.array_equal(state, [getattr(model, name) for name in COORDINATES + VELOCITIES])
    forces = body.mount_forces(np.linalg.solve(body.stiffness, weight) + state[:6], state[6:])
    assert np.array_equal(forces[:, 0], [model.F_x_mount1, model.F_x_mount2, model.F_x_mount3])
    assert system.branches.rows.shape == (0, 6)


# ---- the characteristic (C1), (C2) -----------------------------------------------------------------


def _reference_force(d: float, k: float, g: float, ks: float, w: float) -> float:
    """Equations (C1), (C2) of docs/powertrain_mounts.md, written again."""
    def rho(x: float) -> float:
        if x <= 0.0:
            return 0.0
        return x - w / 2.0 if x >= w else (x / w) ** 3 * w - (x / w) ** 4 * w / 2.0
    return k * d + ks * (rho(d - g) - rho(-d - g))


def test_the_characteristic_its_tangent_energy_and_mean_agree_with_their_definitions():
    """F against the reference; F' and F against central differences of F and V (within 1e-6 of the
    stop rate: the differences' truncation at a step of 1e-7 m), F' continuous across the
    breakpoints, the mean against the energy's difference quotient (1e-9 relative)."""
    k, g, ks, w = 2e5, 0.003, 4e6, 0.002
    law = (np.array([k]), np.array([g]), np.array([ks]), np.array([w]))
    d = np.linspace(-0.01, 0.01, 401)
    for x in d:
        assert characteristic.force(np.array([x]), *law)[0] == pytest.approx(_reference_force(x, k, g, ks, w),
                                                                              rel=1e-12, abs=1e-9)
    step = 1e-7
    f = lambda x: characteristic.force(np.array([x]), *law)[0]  # noqa: E731
    v = lambda x: characteristic.energy(np.array([x]), *law)[0]  # noqa: E731
    for x in d:
        assert characteristic.tangent(np.array([x]), *law)[0] == pytest.approx(
            (f(x + step) - f(x - step)) / (2 * step), abs=1e-6 * ks)
        assert f(x) == pytest.approx((v(x + step) - v(x - step)) / (2 * step), abs=1e-6 * ks * 0.01)
    for corner in (g, g + w, -g, -g - w):
        left, right = (characteristic.tangent(np.array([corner + s]), *law)[0] for s in (-1e-12, 1e-12))
        assert abs(left - right) < 1e-6 * ks
    rng = np.random.default_rng(3)
    for _ in range(200):
        a, b = rng.uniform(-0.01, 0.01, 2)
        mean = characteristic.mean_force(np.array([a]), np.array([b]), *law)[0][0]
        assert mean == pytest.approx((v(b) - v(a)) / (b - a), rel=1e-9, abs=1e-9 * ks * 0.01)


# ---- one mount's dynamic stiffness ----------------------------------------------------------------


@pytest.mark.parametrize("frequency", [1.0, 2.0, 5.0, 10.0, 20.0, 35.0, 50.0])
def test_one_mount_s_loss_factor_holds_over_the_band(frequency):
    """The engine mount's vertical axis driven by ``d = a sin(w t)`` in the time domain (its branches
    by solve_ivp, rtol 1e-10), the force's in-phase and quadrature parts over the last two periods:
    the loss factor within 10 % of the declared 0.15 at each frequency of 1-50 Hz (the fit's own miss
    is 3 %), the storage rate the closed form (R1)'s within 1e-6."""
    layout = load_layout(shipped_layout(RUBBER))
    mount = layout.mounts[0]
    k, tau = mount.stiffness[2], relaxation_times()
    gains = mount.branches * k
    w, amplitude = 2.0 * math.pi * frequency, 1e-4
    periods = 12 + int(frequency)  # the 0.02 Hz branch settles into its periodic state long after, but
    # carries 1e-4 of the force at 1 Hz: measured over the last periods it shifts the loss factor below 1e-3

    def rhs(t, z):
        return gains * amplitude * w * math.cos(w * t) - z / tau

    end = periods / frequency
    times = np.linspace(end - 2.0 / frequency, end, 801)
    z = solve_ivp(rhs, (0.0, end), np.zeros(len(tau)), t_eval=times, rtol=1e-10, atol=1e-12 * k * amplitude).y
    force = k * amplitude * np.sin(w * times) + z.sum(axis=0)
    weights = np.full(len(times), 1.0)
    weights[0] = weights[-1] = 0.5
    in_phase = 2.0 * np.sum(weights * force * np.sin(w * times)) / (len(times) - 1)
    quadrature = 2.0 * np.sum(weights * force * np.cos(w * times)) / (len(times) - 1)
    assert quadrature / in_phase == pytest.approx(0.15, rel=0.10)
    closed = relative_stiffness(mount.branches, np.array(frequency)) * k
    assert in_phase / amplitude == pytest.approx(closed.real, rel=2e-3)
    assert quadrature / amplitude == pytest.approx(closed.imag, rel=2e-2)
    assert BAND == (1.0, 50.0)


# ---- equilibrium and modes under load ---------------------------------------------------------------


def _reference_elastic(layout, q: np.ndarray) -> np.ndarray:
    total = np.zeros(6)
    for m in layout.mounts:
        t = m.axes @ point_map(m.position, layout.centre_of_gravity)
        local = [_reference_force(float(d), m.stiffness[i], m.gap[i], m.stop_rate[i], m.stop_blend)
                 for i, d in enumerate(t @ q)]
        total += t.T @ np.array(local)
    return total


@pytest.mark.parametrize("torque", [0.0, 1100.0, FULL_TORQUE])
def test_loaded_equilibrium_and_modes_against_an_independent_solve(torque):
    """The static equilibrium under the weight and the drive reaction against scipy's hybrid root of the
    reference characteristics (1e-9 of the largest displacement: the root finder's xtol 1e-13 and
    cond(K_t) below 1e3); the modes against the poles of the linearised state-space with the branches
    (tangent rates from central differences of the reference, a general eigensolver): frequencies within
    2 %, damping ratios within 3 % (equation (4) is a first-order estimate of a pole, its error of the
    order of zeta times the storage's slope; measured below 0.7 % and 1.0 %)."""
    layout = load_layout(shipped_layout(RUBBER))
    placement = _placement()
    system = MountSystem.build(layout, placement, 9.81, torque)
    load = np.array([0.0, 0.0, -layout.mass * 9.81, 0.0, -torque, 0.0])
    solved = root(lambda q: _reference_elastic(layout, q) - load, np.zeros(6), method="hybr",
                  options={"xtol": 1e-13})
    sag = system.static_sag(9.81, torque)
    assert np.max(np.abs(sag - solved.x)) < 1e-9 * np.max(np.abs(solved.x))
    a = _reference_state_matrix(layout, sag)
    poles = eig(a, right=False)
    poles = poles[poles.imag > 1e-6 * np.abs(poles)]
    poles = poles[np.argsort(np.abs(poles))]
    assert len(poles) == 6
    found = system.operating_modes(sag)
    assert np.allclose(found.frequencies, np.abs(poles) / (2 * math.pi), rtol=0.02)
    assert np.allclose(found.damping_ratios, -poles.real / np.abs(poles), rtol=0.03)


def _reference_state_matrix(layout, sag: np.ndarray) -> np.ndarray:
    """The linearised state matrix about ``sag`` with the branches, from the reference characteristic
    (its tangent rates by central differences of 1e-8 m), assembled mount by mount."""
    step = 1e-8
    tangent = np.column_stack([(_reference_elastic(layout, sag + step * e) - _reference_elastic(layout, sag - step * e))
                               / (2 * step) for e in np.eye(6)])
    rows, gains, times = [], [], []
    for m in layout.mounts:
        t = m.axes @ point_map(m.position, layout.centre_of_gravity)
        for i, d in enumerate(t @ sag):
            law = (m.stiffness[i], m.gap[i], m.stop_rate[i], m.stop_blend)
            rate = (_reference_force(float(d + step), *law) - _reference_force(float(d - step), *law)) / (2 * step)
            for weight, frequency in zip(m.branches, RELAXATION_FREQUENCIES):
                rows.append(t[i])
                gains.append(weight * rate)
                times.append(1.0 / (2.0 * math.pi * frequency))
    rows, gains, times = np.array(rows), np.array(gains), np.array(times)
    n = 12 + len(gains)
    a = np.zeros((n, n))
    inverse = np.linalg.inv(RigidBody.of(layout).mass)
    a[:6, 6:12] = np.eye(6)
    a[6:12, :6] = -inverse @ tangent
    a[6:12, 12:] = -inverse @ rows.T
    a[12:, 6:12] = gains[:, None] * rows
    a[12:, 12:] = -np.diag(1.0 / times)
    return a


def test_rubber_without_stops_steps_exactly(tmp_path):
    """The rubber layout without its snubbers (linear, stepped by the exponential with the 36 branch
    forces in the state) under random piecewise-linear loads, against solve_ivp (DOP853, rtol 1e-11) of
    the reference state matrix: within 1e-8 of the largest displacement (the reference's tangent rates by
    central differences of 1e-8 m round to some eps |F| / 1e-8 m, 1e-10 of the rates; measured 1.5e-10)."""
    text = shipped_layout(RUBBER).read_text()
    text = "\n".join(line for line in text.splitlines() if not line.startswith(("gap", "stop_rate")))
    path = tmp_path / "rubber_linear.toml"
    path.write_text(text)
    model = _model(str(path))
    layout = load_layout(path)
    a = _reference_state_matrix(layout, model._system.weight_sag)
    inverse = np.linalg.inv(RigidBody.of(layout).mass)
    rng = np.random.default_rng(5)
    h, steps = 1e-3, 100
    knots = rng.uniform(-1.0, 1.0, (steps + 1, 6)) * np.array([2e3, 2e3, 2e3, 3e2, 3e2, 3e2])
    state = np.zeros(len(a))
    found, expected = [], []
    for k in range(steps):
        rate = (knots[k + 1] - knots[k]) / h
        for name, value, slope in zip(LOAD_INPUTS, knots[k], rate):
            setattr(model, name, float(value))
            setattr(model, derivative_name(name), float(slope))
        assert model.step(k * h, h) == []

        def rhs(t, s, f0=knots[k], f1=rate):
            out = a @ s
            out[6:12] += inverse @ (f0 + f1 * t)
            return out

        state = solve_ivp(rhs, (0.0, h), state, method="DOP853", rtol=1e-11, atol=1e-16).y[:, -1]
        found.append([getattr(model, name) for name in COORDINATES])
        expected.append(state[:6])
    found, expected = np.array(found), np.array(expected)
    assert np.max(np.abs(found - expected) / np.max(np.abs(expected), axis=0)) < 1e-8


# ---- free decay --------------------------------------------------------------------------------------


def _decrement(signal: np.ndarray) -> float:
    """The mean logarithmic decrement of the peaks of |signal| (parabolic interpolation), as a damping ratio."""
    peaks = []
    for i in range(1, len(signal) - 1):
        if signal[i] > signal[i - 1] and signal[i] >= signal[i + 1] and signal[i] > 0:
            a, b, c = signal[i - 1], signal[i], signal[i + 1]
            peaks.append(b - 0.125 * (a - c) ** 2 / (a - 2 * b + c))
    delta = math.log(peaks[0] / peaks[-1]) / (len(peaks) - 1)
    return delta / math.sqrt(4.0 * math.pi ** 2 + delta ** 2)


@pytest.mark.parametrize("torque", [0.0, 1100.0])
def test_free_decay_of_each_mode_matches_its_damping_ratio(torque):
    """The body at rest in its loaded equilibrium struck along mode j's shape (a velocity of
    ``2 pi f_j`` times 50 um at the largest coordinate), stepped by the model (the implicit scheme,
    100 steps a period), its modal coordinate ``phi_j^T M q`` over six periods: the logarithmic
    decrement's damping ratio within 10 % of ``zeta_mode_j``, at idle and under the drive reaction (on the
    stops); measured within 1.3 %: equation (4)'s estimate of the pole (the test above), the other
    modes, barely excited, and the scheme's own error at 100 steps a period."""
    model = _model(RUBBER, T_mean=torque, T_motor=torque)  # loaded by the drive reaction T_mean describes
    system = model._system
    sag = system.static_sag(9.81, torque)
    found = system.operating_modes(sag)
    base = np.concatenate([sag - system.weight_sag, np.zeros(6)])
    for j in range(6):
        shape, frequency = found.shapes[:, j], found.frequencies[j]
        start = base.copy()
        start[6:] += 2.0 * math.pi * frequency * 5e-5 * shape / np.max(np.abs(shape))
        model._branch_forces = tuple(np.zeros(len(system.branches)))
        for name, value in zip(COORDINATES + VELOCITIES, start):
            setattr(model, name, float(value))
        h = 1.0 / (100.0 * frequency)
        modal = []
        for k in range(600):
            assert model.step(k * h, h) == []
            q = np.array([getattr(model, name) for name in COORDINATES]) - base[:6]
            modal.append(shape @ system.body.mass @ q)
        measured = _decrement(np.array(modal))
        assert measured == pytest.approx(getattr(model, f"zeta_mode_{j + 1}"), rel=0.10), j


# ---- energy balance ------------------------------------------------------------------------------------


def test_the_energy_balance_of_a_run_closes_within_rounding():
    """Random loads (piecewise linear, 2 kN and 300 N m, pushing the mounts onto their stops) over 400 steps of
    the implicit scheme: the work of the loads equals the change of kinetic, elastic, gravitational and
    branch energy plus the viscous and branch dissipation within 1e-10 of the work's magnitude (Newton
    stops at 1e-14 of the displacement; measured 1e-13)."""
    layout = load_layout(shipped_layout(RUBBER))
    system = MountSystem.build(layout, _placement(), 9.81, 0.0)
    rng = np.random.default_rng(11)
    h, steps = 1e-3, 400
    knots = rng.uniform(-1.0, 1.0, (steps + 1, 6)) * np.array([2e3, 2e3, 2e3, 3e2, 3e2, 3e2])
    mass, branches = system.body.mass, system.branches

    def energy(state):
        big_q = system.weight_sag + state[:6]
        return (0.5 * state[6:12] @ mass @ state[6:12] + elastic_energy(layout, big_q) - system.weight @ big_q
                + np.sum(state[12:] ** 2 / (2.0 * branches.gains)))

    state = np.zeros(system.size)
    start, work, dissipated, magnitude = energy(state), 0.0, 0.0, 0.0
    for k in range(steps):
        rate = (knots[k + 1] - knots[k]) / h
        state, parts = implicit_step(layout, mass, system.body.damping, branches, system.weight, system.weight_sag,
                                     state, knots[k], rate, h)
        work += parts.mean_load @ parts.dq
        magnitude += np.abs(parts.mean_load) @ np.abs(parts.dq)
        dissipated += h * np.sum(parts.mean_branch ** 2 / (branches.gains * branches.times))
    assert max(abs(d) for d in (to_axes @ (system.weight_sag + state[:6]) for to_axes in layout.maps)
               for d in d) > 0.0
    assert abs(energy(state) - start + dissipated - work) < 1e-10 * magnitude


# ---- the rubber layout -------------------------------------------------------------------------------


def test_the_rubber_layout_holds_the_wind_up_and_damps_its_modes_alike():
    """Under 1.1 kN.m about the drive axis the wind-up is at most 2 degrees (designed: 1.5); the six modes'
    damping ratios lie within a ratio of 1.5 of each other, at idle and at full torque."""
    for torque in (0.0, 1100.0, FULL_TORQUE):
        model = _model(RUBBER, T_mean=torque)
        ratios = [getattr(model, f"zeta_mode_{j}") for j in range(1, 7)]
        assert max(ratios) / min(ratios) <= 1.5
        assert all(0.07 <= r <= 0.09 for r in ratios)  # near eta / (2 - 2 eta / pi) = 0.079
        if torque == 1100.0:
            assert 0.0 < math.degrees(model.wind_up) <= 2.0


# ---- refusals --------------------------------------------------------------------------------------------

HEADER = "mass = 200.0\ncentre_of_gravity = [0.0, 0.0, 0.3]\ninertia = [11.0, 8.0, 10.0, 0.3, 1.0, 0.4]\n"
MOUNT = "[[mounts]]\nposition = [0.2, 0.3, 0.5]\nstiffness = [1e5, 1e5, 2e5]\n"


@pytest.mark.parametrize("extra, message", [
    ("gap = [0.003, 0.003, 0.003]\nstop_rate = [1e6, -2e5, 0.0]\n",
     "mounts[0].stop_rate[1] -200000.0 makes the characteristic not monotonic"),
    ("gap = [0.003, -0.001, 0.003]\nstop_rate = [1e6, 1e6, 1e6]\n", "mounts[0].gap[1] must be >= 0, got -0.001"),
    ("gap = [0.003, 0.003, 0.003]\n", "mounts[0].gap needs the key 'stop_rate'"),
    ("loss_factor = 1.2\ndynamic_ratio = 2.0\n", "mounts[0].loss_factor must lie in (0, 1) for rubber damping"),
    ("loss_factor = 0.0\ndynamic_ratio = 2.0\n", "mounts[0].loss_factor must lie in (0, 1) for rubber damping"),
    ("dynamic_ratio = 2.0\n", "mounts[0].dynamic_ratio needs the key 'loss_factor'"),
    ("loss_factor = 0.15\ndynamic_ratio = 0.9\n", "mounts[0].dynamic_ratio must be >= 1"),
    ("loss_factor = 0.2\ndynamic_ratio = 1.2\n", "mounts[0].dynamic_ratio 1.2 cannot go with loss_factor 0.2"),
    ("stop_blend = 0.0\n", "mounts[0].stop_blend must be > 0"),
])
def test_a_bad_characteristic_is_refused_in_one_line_naming_the_mount_and_key(extra, message):
    with pytest.raises(ValueError) as caught:
        loads_layout(HEADER + MOUNT + extra, "layout.toml")
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_the_model_refuses_a_bad_characteristic_at_initialisation(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text(HEADER + MOUNT * 3 + "gap = [0.003, -0.001, 0.003]\nstop_rate = [1e6, 1e6, 1e6]\n")
    model = PowertrainMountsModel()
    model.layout = str(path)
    errors = model.initialize(0.0)
    assert len(errors) == 1 and "mounts[2].gap[1] must be >= 0" in errors[0] and errors[0].startswith("powertrain: ")


def test_the_branch_map_follows_the_layout():
    """Three rubber mounts, three axes, four branches each: 36 branch forces; their rates at idle the
    linear rates times the weights (no stop touched under the weight alone)."""
    layout = load_layout(shipped_layout(RUBBER))
    system = MountSystem.build(layout, _placement(), 9.81, 0.0)
    branches = BranchMap(layout, system.weight_sag)
    assert len(branches) == 36 and system.size == 48
    assert np.allclose(branches.gains[:4], layout.mounts[0].branches * layout.mounts[0].stiffness[0], rtol=1e-15)
    assert AXES == ("x", "y", "z")


def test_loads_beyond_the_range_of_numbers_are_refused_not_garbage():
    """A load near 1e300 on the stops: the step refused with the reason, the state kept; a mean torque
    of 1e300: the parameters refused at initialisation (Newton finds no equilibrium)."""
    model = _model(RUBBER)
    before = [getattr(model, name) for name in COORDINATES]
    model.F_x = 1e300
    errors = model.step(0.0, 1e-3)
    assert len(errors) == 1 and "beyond the range of numbers" in errors[0]
    assert [getattr(model, name) for name in COORDINATES] == before
    model = PowertrainMountsModel()
    model.layout, model.T_mean = RUBBER, 1e300
    assert model.initialize(0.0) == ["powertrain: no static equilibrium found in 60 Newton steps"]
