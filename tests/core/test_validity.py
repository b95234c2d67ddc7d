"""Validity declared in the spec: exclusive bounds and relations, enforced and worded by the base model."""

from __future__ import annotations

import dataclasses
import math

import pytest

from driveline.catalog import MODELS
from driveline.model import SteppedModel
from driveline.rotor.model import CriticalSpeedsModel
from driveline.tripod.model import TripodCouplingModel
from driveline.variables import DefaultExperiment, ModelSpec, Relation, State, Variable
from fmu_harness.doc_pages.variable_table import markdown


def spec_with(*relations: Relation) -> ModelSpec:
    return ModelSpec(
        "Probe", "a model with bounds and relations only",
        (
            Variable("gap", "parameter", 0.01, "exclusive minimum", "m", "mm", min=0.0, min_exclusive=True),
            Variable("ceiling", "parameter", 0.5, "exclusive maximum", "rad", "deg", max=1.0, max_exclusive=True),
            Variable("limit", "parameter", 2.0, "an inclusive bound", "m", min=0.0),
            Variable("count", "parameter", 3, "an integer", type="Integer"),
            Variable("x", "input", 1.0, "an input", "m"),
            Variable("y", "output", 0.0, "an output", "m", depends_on=("x",)),
        ),
        DefaultExperiment(0.0, 1.0, 0.1),
        relations,
    )


class Probe(SteppedModel):
    spec = spec_with(
        Relation("gap", "<", "limit"),
        Relation("count", ">=", 2.0),
        Relation("x", "<=", "limit", scale=2.0, offset=0.5, reason="twice the limit and a margin"),
    )

    def start(self, start_time: float) -> None:
        self.y = self.x

    def advance(self, current_time: float, step_size: float) -> None:
        self.y = self.x


@pytest.mark.parametrize(
    ("values", "message"),
    [
        (dict(gap=0.0), "parameter gap = 0 mm must be positive"),
        (dict(gap=-1e-3), "parameter gap = -1 mm must be positive"),
        (dict(ceiling=1.0), "parameter ceiling = 57.2958 deg must be below 57.2958 deg"),
        (dict(limit=-1.0, x=-3.0), "parameter limit = -1.0 m is below its minimum 0.0 m"),
        (dict(gap=2.0), "parameter gap = 2000 mm must be below limit = 2000 mm"),
        (dict(count=1), "parameter count = 1 must not be below 2.0"),
        (dict(x=4.6), "input x = 4.6 m must not exceed 2 limit + 0.5 = 4.5 m (twice the limit and a margin)"),
    ],
)
def test_a_declared_rule_refuses_with_its_message(values, message):
    model = Probe()
    for name, value in values.items():
        setattr(model, name, value)
    assert model.initialize(0.0) == [message]


@pytest.mark.parametrize(
    "values",
    [dict(gap=1e-300), dict(ceiling=math.nextafter(1.0, 0.0)), dict(gap=math.nextafter(2.0, 0.0)), dict(count=2),
     dict(x=4.5)],
)
def test_just_inside_every_rule_is_accepted(values):
    model = Probe()
    for name, value in values.items():
        setattr(model, name, value)
    assert model.initialize(0.0) == []


def test_an_input_relation_refuses_the_step_and_the_corrected_input_steps_on():
    model = Probe()
    assert model.step(0.0, 0.1) == []
    before = model.get_state()
    model.x = 5.0
    assert model.step(0.1, 0.1) == ["input x = 5.0 m must not exceed 2 limit + 0.5 = 4.5 m (twice the limit and a margin)"]
    model.x = before["x"]
    assert model.get_state() == before and model.step(0.1, 0.1) == []


def test_relations_wait_for_the_bounds():
    """A value out of its own range is reported alone, not again through a relation."""
    model = Probe()
    model.gap = math.nan
    assert model.initialize(0.0) == ["parameter gap = nan is not finite"]


@pytest.mark.parametrize(
    ("relation", "fragment"),
    [
        (Relation("gap", "<", "nowhere"), "names no variable"),
        (Relation("gap", "=", "limit"), "no operator"),
        (Relation("y", "<", "limit"), "numeric parameters or inputs"),
        (Relation("gap", "<", "ceiling"), "different units"),
    ],
)
def test_a_spec_refuses_relations_it_cannot_enforce(relation, fragment):
    with pytest.raises(ValueError, match=fragment):
        spec_with(relation)


@pytest.mark.parametrize(
    ("output", "states", "fragment"),
    [
        (Variable("y", "output", 0.0, "undeclared"), (), r"output y declares no dependencies: give its Variable "
                                                        r"depends_on=\(...\).*docs/development.md, Add a model"),
        (Variable("y", "output", 0.0, "declared", depends_on=("nowhere",)), (), "no input, parameter or state"),
        (Variable("y", "output", 0.0, "a state"), (State("y", ("y",), "x", 1.0),),
         "initial values must name parameters or inputs"),
        (Variable("y", "output", 0.0, "at start", depends_on=(), initial_depends_on=("y",)), (), "no input"),
    ],
)
def test_a_spec_refuses_outputs_without_a_correct_dependency_declaration(output, states, fragment):
    variables = (Variable("x", "input", 1.0, "an input"), Variable("p", "parameter", 1.0, "a parameter"), output)
    with pytest.raises(ValueError, match=fragment):
        ModelSpec("Probe", "an output and what it depends on", variables, DefaultExperiment(0.0, 1.0, 0.1),
                  states=states)


def test_a_local_is_computed_as_an_output_is_and_relates_to_nothing():
    """A local (an internal state) may be a state and a state's derivative, declares its dependencies as an
    output does, is checked after a step with the outputs, and no relation names it."""
    variables = (Variable("x", "input", 1.0, "an input"), Variable("s", "local", 0.0, "an internal state"),
                 Variable("s_dot", "local", 0.0, "its rate", depends_on=("s", "x")))
    spec = ModelSpec("Probe", "an internal state", variables, DefaultExperiment(0.0, 1.0, 0.1),
                     states=(State("s", (), "s_dot", 1.0),))
    assert spec.of("local") == variables[1:] and not spec.of("output")
    assert spec.derivative_dependencies(spec.states[0]) == ("x", "s")
    assert [v.article for v in variables] == ["an input", "a local", "a local"]
    with pytest.raises(ValueError, match="local s_dot declares no dependencies"):
        ModelSpec("Probe", "undeclared", (*variables[:2], Variable("s_dot", "local", 0.0, "its rate")),
                  DefaultExperiment(0.0, 1.0, 0.1), states=(State("s", (), "s_dot", 1.0),))
    with pytest.raises(ValueError, match="numeric parameters or inputs"):
        ModelSpec("Probe", "a relation on a local", variables, DefaultExperiment(0.0, 1.0, 0.1),
                  (Relation("x", "<", "s"),), states=(State("s", (), "s_dot", 1.0),))


def test_a_step_refuses_a_local_that_is_not_finite_as_an_output():
    class Internal(SteppedModel):
        spec = ModelSpec("Internal", "an internal value", (
            Variable("x", "input", 1.0, "an input"),
            Variable("y", "output", 0.0, "an output", depends_on=("x",)),
            Variable("z", "local", 0.0, "an internal value", depends_on=("x",))), DefaultExperiment(0.0, 1.0, 0.1))

        def _evaluate(self) -> None:
            self.y, self.z = self.x, 1.0 / self.x if self.x else math.nan

        def start(self, start_time: float) -> None:
            self._evaluate()

        def advance(self, current_time: float, step_size: float) -> None:
            self._evaluate()

    model = Internal()
    assert model.initialize(0.0) == []
    model.x = 0.0
    assert model.step(0.0, 0.1) == ["local z is not finite (nan); the step was not taken"]


def test_the_dependencies_at_initialisation_follow_a_state_to_its_initial_values():
    variables = (Variable("x", "input", 1.0, "an input"), Variable("p", "parameter", 1.0, "a parameter"),
                 Variable("x0", "parameter", 0.0, "the state's initial value"),
                 Variable("s", "output", 0.0, "a state"),
                 Variable("y", "output", 0.0, "from the state and the input", depends_on=("s", "x")),
                 Variable("z", "output", 0.0, "from p alone, zero at the start", depends_on=("p",),
                          initial_depends_on=()))
    spec = ModelSpec("Probe", "a state and two outputs", variables, DefaultExperiment(0.0, 1.0, 0.1),
                     states=(State("s", ("x0",), "x", 1.0),))
    assert [spec.output_dependencies(name) for name in ("s", "y", "z")] == [(), ("x",), ()]
    assert [spec.initial_dependencies(name) for name in ("s", "y", "z")] == [("x0",), ("x", "x0"), ()]


def test_a_state_starting_in_an_equilibrium_depends_at_initialisation_on_the_inputs():
    variables = (Variable("F", "input", 1.0, "a force"), Variable("k", "parameter", 1.0, "a stiffness"),
                 Variable("q", "output", 0.0, "the displacement, F / k at the start"),
                 Variable("v", "output", 0.0, "the velocity, 0 at the start"),
                 Variable("a", "output", 0.0, "the acceleration, 0 at the start",
                          depends_on=("F", "k", "q"), initial_depends_on=()))
    spec = ModelSpec("Probe", "a spring starting at rest", variables, DefaultExperiment(0.0, 1.0, 0.1),
                     states=(State("q", ("F", "k"), "v", 1.0), State("v", (), "a", 1.0)))
    assert [spec.initial_dependencies(name) for name in ("q", "v", "a")] == [("F", "k"), (), ()]
    assert [spec.output_dependencies(name) for name in ("q", "v", "a")] == [(), (), ("F",)]


def test_an_exclusive_bound_needs_its_value():
    with pytest.raises(ValueError, match="exclusive"):
        Variable("v", "parameter", 1.0, "no minimum", min_exclusive=True)


def test_the_models_declare_their_rules():
    tripod = TripodCouplingModel()
    tripod.l = 0.02
    assert tripod.initialize(0.0) == [
        "parameter l = 20 mm must exceed r = 26 mm (the bearing centre lies beyond the grooves)"]
    rotor = CriticalSpeedsModel()
    rotor.D_inner = 0.08
    assert rotor.initialize(0.0) == ["parameter D_inner = 80 mm must be below D_outer = 76.2 mm"]
    rotor = CriticalSpeedsModel()
    rotor.omega_in = -1600.0
    assert rotor.input_errors() == ["input omega_in = -15278.9 rpm must not be below -omega_in_max = -14323.9 rpm"]


@pytest.mark.parametrize("name", MODELS)
def test_declarations_are_plain_data(name):
    """What a code generator reads: names, operators and numbers only."""
    spec = MODELS[name].spec
    for relation in spec.relations:
        assert all(isinstance(value, (str, float, int)) for value in dataclasses.asdict(relation).values())
    for variable in spec.variables:
        assert isinstance(variable.min_exclusive, bool) and isinstance(variable.max_exclusive, bool)


def test_the_variable_table_shows_the_rules():
    table = markdown(MODELS["UniversalReducer"].spec)
    assert "| `module` | parameter | m (mm) | 0.002 | > 0 |  |" in table
    assert "| `intersection_angle_max` | parameter | rad (deg) | 2.96706 | 0 | < 3.14159 |" in table
    assert "`z1 > z2` (i = z1 / (z1 - z2))" in table and "inclusive min or max" in table


@pytest.mark.parametrize("name", ["TorqueSource", "CardanJoint", "SpeedSource"])
def test_a_step_whose_end_time_is_not_finite_is_refused(name):
    """From t = 1e308 s by 1e308 s the end time overflows: refused, the model left at the time it reached, whose
    check of time going backwards then still holds (it compared against NaN after an infinite time)."""
    model = MODELS[name]()
    assert model.initialize(0.0) == [] and model.step(0.0, 1e-3) == []
    before = model.outputs()
    assert model.step(1e308, 1e308) == [
        "the communication step from t = 1e+308 s by 1e+308 s ends at a time that is not finite"]
    assert model.time == 1e-3 and model.outputs() == before
    assert model.goes_back(0.0)
