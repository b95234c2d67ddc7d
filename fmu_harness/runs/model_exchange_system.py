"""A system of FMUs run as one ODE through their Model Exchange interfaces, the way an equation-based
host runs them (``driveline-fmus system --engine model-exchange``).

Every component's continuous states join one state vector, integrated by scipy's DOP853 step by step
(each instance told ``completedIntegratorStep``). At each evaluation the connections are computed in the order their outputs' declared direct
dependencies give (``<ModelStructure>``: an output's ``dependencies`` among the inputs): a connection
whose output depends on another's input comes after it. Connections that depend on each other in a
cycle (strongly connected, found by Tarjan's algorithm) form an algebraic loop, solved by Newton's
method with the Jacobian from the components' directional derivatives (in the vehicle launch: each
joint's ``T_in`` depends on its ``alpha_in``, the drive's ``alpha_in_*`` on both ``T_in``). Nothing is
one step late, so the run converges to the monolithic ODE as the tolerance tightens; a co-simulation
master converges only as its step shrinks.

Initialisation is the co-simulation master's (:func:`.system.run_jacobi`): all instances enter
initialisation with their start values, each connection carries its output's value there, then all
exit. A refused call raises :class:`StepRefused` naming the component.
"""

from __future__ import annotations

import zipfile
from collections.abc import Callable, Collection, Mapping, Sequence
from ctypes import POINTER, Array, c_double, c_uint32
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from scipy.integrate import BDF, DOP853, Radau

from .runner import LoggedInstance, StepRefused, status_name

Port = tuple[str, str]  # (instance, variable)


class NotRunnable(ValueError):
    """What keeps a system from this engine (an FMU without Model Exchange, a loop through an FMU
    without directional derivatives, a time event), in one line."""
#: A loop is solved when Newton's last update moved no value by more than this share of its magnitude
#: (at least 1). The launch's loop is nearly linear (the second update is 1e-12 of the first) but
#: amplifies its outputs' rounding: the joints' friction balance settles T_in to 1e-16 of itself, and
#: d alpha_in / d T_in = 34 /(kg m2) turns that into 2e-13 of alpha_in, where Newton's updates stop
#: falling (measured: a 2-cycle of +-8.9e-13 on alpha_in = 5 rad/s2). That floor is set by the values
#: feeding a value, not by its own size: with the housings' motion the drive's alpha_in also takes
#: T_reaction (1,115 N.m) and the 2-cycle reaches +-1.07e-11 on alpha_in_left = 0.79 rad/s2 (t = 0.4345 s
#: of the launch), so Newton's updates that stop falling are also accepted within this share of what
#: feeds each value through the loop (:meth:`ModelExchangeSystem._solve_loop`).
LOOP_TOLERANCE = 1e-11
#: Newton's updates have stopped falling (reached the loop's rounding floor) when one is more than this
#: share of the one before; while converging each is 1e-12 of the one before.
STALLED = 0.5
MAX_LOOP_ITERATIONS = 20
#: Event iterations at initialisation before the FMU is refused (the project's FMUs need none).
MAX_EVENT_ITERATIONS = 100
#: The integrators' absolute tolerance, on states of order 1 (angles, speeds) down to 1e-3 m.
ATOL = 1e-12
#: scipy's integrators by name: DOP853 (explicit, the default), Radau and BDF (implicit, given the
#: system's exact Jacobian from the FMUs' directional derivatives).
METHODS = {"DOP853": DOP853, "Radau": Radau, "BDF": BDF}
WARNING = 1  # FMI's status Warning: the call done


class ModelExchangeInstance:
    """One component: an FMU (FMI 2.0 or 3.0) instantiated for Model Exchange through fmpy."""

    def __init__(self, name: str, path: Path, scratch: Path) -> None:
        self.name = name
        self.description = read_model_description(str(path))
        if self.description.modelExchange is None:
            raise NotRunnable(f"{name}: {path.name} has no Model Exchange interface")
        self.fmi3 = self.description.fmiVersion.startswith("3")
        self.log: list[str] = []
        self._instance = LoggedInstance(extract(str(path), unzipdir=str(scratch / name)), self.description,
                                        "ModelExchange", name, self.log.append)
        self.fmu = self._instance.fmu
        self.references = {v.name: v.valueReference for v in self.description.modelVariables}
        self.size = len(self.description.derivatives)
        self.state_names = [u.variable.derivative.name for u in self.description.derivatives]
        self.derivative_names = [u.variable.name for u in self.description.derivatives]
        self.dependencies = {u.variable.name: {v.name for v in u.dependencies}
                             for u in self.description.outputs}
        self.time = 0.0
        with zipfile.ZipFile(path) as archive:  # fmpy 0.3 reads FMI 2.0's name of the flag only
            interface = ET.fromstring(archive.read("modelDescription.xml")).find("ModelExchange")
        flag = "providesDirectionalDerivatives" if self.fmi3 else "providesDirectionalDerivative"
        self.gives_derivatives = interface is not None and interface.get(flag) in ("true", "1")
        self._get, self._set = ("getFloat64", "setFloat64") if self.fmi3 else ("getReal", "setReal")
        self._rates_function = "getContinuousStateDerivatives" if self.fmi3 else "getDerivatives"
        self._functions: dict[str, Callable] = {}
        self._buffers: dict[tuple[str, ...], tuple[Array, Array]] = {}
        self._states, self._rates = (c_double * self.size)(), (c_double * self.size)()

    def call(self, function: str, *arguments):
        """fmpy's ``function`` of this instance; a non-OK status raises :class:`StepRefused` naming it."""
        first = len(self.log)
        try:
            return getattr(self.fmu, function)(*arguments)
        except FMICallException as error:
            raise StepRefused(f"{self.name}: {function}", status_name(error.status), self.time,
                              self.log[first:]) from None

    def _direct(self, function: str, *arguments) -> None:
        """fmpy's low-level ``function`` (``getReal`` for ``fmi2GetReal``) called on ctypes buffers as fmpy declared
        it, without fmpy's wrapper: the engine makes some 80 such calls per right-hand side, and the wrapper was
        most of their cost. A status above Warning raises :class:`StepRefused` naming it, as :meth:`call` does."""
        declared = self._functions.get(function)
        if declared is None:
            declared = self._functions[function] = getattr(self.fmu.dll, f"fmi{3 if self.fmi3 else 2}"
                                                                          f"{function[0].upper()}{function[1:]}")
        first = len(self.log)
        status = declared(self.fmu.component, *arguments)
        if status > WARNING:
            raise StepRefused(f"{self.name}: {function}", status_name(status), self.time, self.log[first:])

    def _buffer(self, names: Sequence[str]) -> tuple[Array, Array]:
        """The value references of ``names`` and a value array of their length, made once per list of names."""
        key = tuple(names)
        found = self._buffers.get(key)
        if found is None:
            found = self._buffers[key] = ((c_uint32 * len(key))(*(self.references[n] for n in key)),
                                          (c_double * len(key))())
        return found

    def get(self, names: Sequence[str]) -> list[float]:
        references, values = self._buffer(names)
        self._direct(self._get, references, len(references), values, *((len(references),) if self.fmi3 else ()))
        return values[:]

    def set(self, names: Sequence[str], values: Sequence[float]) -> None:
        if names:
            references, buffer = self._buffer(names)
            buffer[:] = [float(v) for v in values]
            self._direct(self._set, references, len(references), buffer, *((len(references),) if self.fmi3 else ()))

    def set_start_values(self, values: Mapping[str, object]) -> None:
        for name, value in values.items():
            kind = {bool: "Boolean", int: "Int32" if self.fmi3 else "Integer", str: "String"}.get(
                type(value), "Float64" if self.fmi3 else "Real")
            self.call(f"set{kind}", [self.references[name]], [value])

    def directional(self, unknowns: Sequence[str], known: str) -> np.ndarray:
        """d unknowns / d known at the instance's present point, exact (the FMU's directional derivative)."""
        return self.partials(unknowns, [known])[:, 0]

    def partials(self, unknowns: Sequence[str], knowns: Sequence[str]) -> np.ndarray:
        """The block d unknowns / d knowns at the instance's present point, a directional derivative per known."""
        (rows, sensitivity), (columns, seed) = self._buffer(unknowns), self._buffer(knowns)
        counts = ((len(columns),), (len(rows),)) if self.fmi3 else ((), ())
        block = np.zeros((len(rows), len(columns)))
        for j in range(len(columns)):
            seed[:] = [1.0 if i == j else 0.0 for i in range(len(columns))]
            self._direct("getDirectionalDerivative", rows, len(rows), columns, len(columns), seed, *counts[0],
                         sensitivity, *counts[1])
            block[:, j] = sensitivity
        return block

    def enter_initialization(self, start_values: Mapping[str, object]) -> None:
        if self.fmi3:
            self.call("enterInitializationMode", None, 0.0)
        else:
            self.call("setupExperiment", None, 0.0)
            self.call("enterInitializationMode")
        self.set_start_values(start_values)

    def exit_initialization(self) -> None:
        """Leave initialisation through event mode into continuous-time mode; a time event is refused."""
        self.call("exitInitializationMode")
        for _ in range(MAX_EVENT_ITERATIONS):
            if self.fmi3:
                needed, _, _, _, time_defined, _ = self.call("updateDiscreteStates")
            else:
                needed, _, _, _, time_defined, _ = self.call("newDiscreteStates")
            if time_defined:
                raise NotRunnable(f"{self.name}: the FMU asks for a time event, which this engine does not handle")
            if not needed:
                break
        else:
            raise NotRunnable(f"{self.name}: the FMU still asks for new discrete states after "
                              f"{MAX_EVENT_ITERATIONS} updates at initialisation")
        self.call("enterContinuousTimeMode")

    def set_point(self, time: float, states: np.ndarray) -> None:
        self.time = time
        self._direct("setTime", time)
        if self.size:
            self._states[:] = states.tolist()
            self._direct("setContinuousStates", self._states, self.size)

    def states(self) -> np.ndarray:
        values = np.zeros(self.size)
        if self.size:
            self.call("getContinuousStates", values.ctypes.data_as(POINTER(c_double)), self.size)
        return values

    def derivatives(self) -> np.ndarray:
        if not self.size:
            return np.zeros(0)
        self._direct(self._rates_function, self._rates, self.size)
        return np.frombuffer(self._rates).copy()

    def completed_step(self) -> None:
        """Tell the FMU a step is complete; an event or a termination it asks for is refused."""
        event, terminate = self.call("completedIntegratorStep")
        if event or terminate:
            raise StepRefused(f"{self.name}: completedIntegratorStep", "Discard", self.time,
                              [f"the FMU asks to {'terminate' if terminate else 'enter event mode'}, which this "
                               "engine does not handle"])

    def close(self) -> None:
        try:
            self.fmu.terminate()
        except FMICallException:
            pass
        self.fmu.freeInstance()
        self._instance.release()


def strongly_connected(nodes: int, after: Mapping[int, Collection[int]]) -> list[list[int]]:
    """Tarjan's strongly connected components of the graph whose edges ``k -> after[k]`` say that k
    must be computed before each of ``after[k]``; in that order (each component before those that
    need it), each component's nodes in ascending order."""
    index: dict[int, int] = {}
    lowest: dict[int, int] = {}
    stack: list[int] = []
    on_stack: set[int] = set()
    found: list[list[int]] = []

    def visit(node: int) -> None:  # recursion depth: the number of connections in one chain
        index[node] = lowest[node] = len(index)
        stack.append(node)
        on_stack.add(node)
        for following in after.get(node, ()):
            if following not in index:
                visit(following)
                lowest[node] = min(lowest[node], lowest[following])
            elif following in on_stack:
                lowest[node] = min(lowest[node], index[following])
        if lowest[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                on_stack.discard(member)
                component.append(member)
                if member == node:
                    break
            found.append(sorted(component))

    for node in range(nodes):
        if node not in index:
            visit(node)
    return found[::-1]


class ModelExchangeSystem:
    """Instances ``{name: FMU}`` with their start values and ``connections`` ``((instance, output),
    (instance, input))`` as one ODE: :meth:`rates` of the stacked states; :attr:`blocks`, the
    connections' order (each a list of connection numbers), :attr:`loops` which of them are algebraic loops
    (more than one connection, or one feeding itself)."""

    def __init__(self, fmus: Mapping[str, Path], parameters: Mapping[str, Mapping[str, object]],
                 connections: Sequence[tuple[Port, Port]], scratch: Path) -> None:
        self.instances: dict[str, ModelExchangeInstance] = {}
        try:
            for name, path in fmus.items():
                self.instances[name] = ModelExchangeInstance(name, path, scratch)
            self.connections = list(connections)
            for name, instance in self.instances.items():
                instance.enter_initialization(parameters.get(name, {}))
            for (source, output), (target, input_) in self.connections:
                self.instances[target].set([input_], self.instances[source].get([output]))
            for instance in self.instances.values():
                instance.exit_initialization()
        except BaseException:
            self.close()
            raise
        after = self._order()
        self.blocks = strongly_connected(len(self.connections), after)
        self.loops = [len(block) > 1 or block[0] in after[block[0]] for block in self.blocks]
        for block in (b for b, loop in zip(self.blocks, self.loops) if loop):
            for (_, _), (target, _) in (self.connections[k] for k in block):
                if not self.instances[target].gives_derivatives:
                    self.close()
                    raise NotRunnable(f"{target}: the algebraic loop of {self.loop_name(block)} goes through it, and "
                                      "it gives no directional derivatives to solve it with")
        self.stages = self._stages(after)
        carried = self.blocks + [stage for stage in self.stages if stage is not None]
        self._loop_columns = {id(block): self._columns(block) for block, loop in zip(self.blocks, self.loops) if loop}
        self._reads = {id(block): self._grouped(block, 0) for block in carried}
        self._writes = {id(block): self._grouped(block, 1) for block in carried}
        sizes = [instance.size for instance in self.instances.values()]
        self.evaluations = 0  # of :meth:`rates`, the integrator's right-hand sides
        self.slices = dict(zip(self.instances, (slice(a, b) for a, b in zip(np.cumsum([0, *sizes]), np.cumsum(sizes)))))

    def _order(self) -> dict[int, list[int]]:
        """k -> the connections whose output depends directly on connection k's input."""
        after: dict[int, list[int]] = {}
        for k, (_, (target, input_)) in enumerate(self.connections):
            after[k] = [j for j, ((source, output), _) in enumerate(self.connections)
                        if source == target and input_ in self.instances[source].dependencies.get(output, set())]
        return after

    def _stages(self, after: Mapping[int, Collection[int]]) -> list[list[int] | None]:
        """The blocks that are no loop, in order, joined while none needs another's input: each such stage is
        carried with one get per source instance and one set per target, the same values as block by block;
        each loop is a stage of its own, ``None`` in its place (:meth:`settle` solves it)."""
        stages: list[list[int] | None] = []
        for block, loop in zip(self.blocks, self.loops):
            if loop:
                stages.append(None)
            elif stages and stages[-1] is not None and not any(j in block for k in stages[-1] for j in after[k]):
                stages[-1] = stages[-1] + block
            else:
                stages.append(list(block))
        return stages

    def _columns(self, block: list[int]) -> list[tuple[ModelExchangeInstance, list[str], list[int], str]]:
        """Per connection of the loop ``block``: the instance it feeds, that instance's outputs in the loop, their
        rows in the block, and the input it feeds."""
        found = []
        for k in block:
            _, (target, input_) = self.connections[k]
            rows = [row for row, j in enumerate(block) if self.connections[j][0][0] == target]
            found.append((self.instances[target], [self.connections[block[row]][0][1] for row in rows], rows, input_))
        return found

    def loop_name(self, block: list[int]) -> str:
        return ", ".join(f"{s}.{o}" for (s, o), _ in (self.connections[k] for k in block))

    def start(self) -> np.ndarray:
        """The stacked states the instances hold after initialisation."""
        return np.concatenate([instance.states() for instance in self.instances.values()])

    def _grouped(self, block: list[int], end: int) -> list[tuple[ModelExchangeInstance, list[str], list[int]]]:
        """The block's connections by instance of their source (``end`` 0) or target (1): (instance,
        variables, positions in the block), so that each instance is called once."""
        groups: dict[str, tuple[list[str], list[int]]] = {}
        for position, k in enumerate(block):
            name, variable = self.connections[k][end]
            groups.setdefault(name, ([], []))[0].append(variable)
            groups[name][1].append(position)
        return [(self.instances[name], variables, positions) for name, (variables, positions) in groups.items()]

    def _carry(self, block: list[int], values: Sequence[float]) -> None:
        for instance, inputs, positions in self._writes[id(block)]:
            instance.set(inputs, [values[p] for p in positions])

    def _outputs(self, block: list[int]) -> np.ndarray:
        values = np.zeros(len(block))
        for instance, outputs, positions in self._reads[id(block)]:
            values[positions] = instance.get(outputs)
        return values

    def _loop_jacobian(self, block: list[int]) -> np.ndarray:
        """I - dy/dv of the loop ``block`` at the present point: a directional derivative of the outputs of the
        loop that each input feeds, per input."""
        jacobian = np.eye(len(block))
        for column, (instance, outputs, rows, input_) in enumerate(self._loop_columns[id(block)]):
            jacobian[rows, column] -= instance.directional(outputs, input_)
        return jacobian

    def _solve_loop(self, block: list[int]) -> None:
        """The loop's values v = y(v) by Newton's method, (I - dy/dv) dv = y(v) - v, the Jacobian from the
        directional derivatives of each output with respect to the inputs of the loop it depends on, taken at
        the first iteration and kept (the loop is nearly linear: the second update is 1e-12 of the first, and
        ends it). Solved when the update is within :data:`LOOP_TOLERANCE` of each value, or, once the updates
        stop falling (:data:`STALLED`: the rounding floor), within :data:`LOOP_TOLERANCE` of what feeds each
        value through the loop, |(I - dy/dv)^-1| max(1, |v|): the outputs' rounding carried to it."""
        values = self._outputs(block)
        jacobian, previous = None, np.inf
        for _ in range(MAX_LOOP_ITERATIONS):
            self._carry(block, values)
            residual = self._outputs(block) - values
            if jacobian is None:
                jacobian = self._loop_jacobian(block)
            update = np.linalg.solve(jacobian, residual)
            values = values + update
            size, scale = np.abs(update), np.maximum(1.0, np.abs(values))
            if np.all(size <= LOOP_TOLERANCE * scale) or (
                    size.max() > STALLED * previous
                    and np.all(size <= LOOP_TOLERANCE * (np.abs(np.linalg.inv(jacobian)) @ scale))):
                self._carry(block, values)
                return
            previous = size.max()
        raise StepRefused(f"the algebraic loop of {self.loop_name(block)}", "Discard", next(iter(self.instances.values())).time,
                          [f"Newton's method did not converge in {MAX_LOOP_ITERATIONS} iterations"])

    def settle(self, time: float, states: np.ndarray) -> None:
        """Every instance at ``time`` and its share of ``states``, every connection's input set."""
        for name, instance in self.instances.items():
            instance.set_point(time, states[self.slices[name]])
        loops = iter(block for block, loop in zip(self.blocks, self.loops) if loop)
        for stage in self.stages:
            if stage is None:
                self._solve_loop(next(loops))
            else:
                self._carry(stage, self._outputs(stage))

    def completed_step(self, time: float, states: np.ndarray) -> None:
        """An integrator step ends at ``(time, states)``: every instance there, then told."""
        self.settle(time, states)
        for instance in self.instances.values():
            instance.completed_step()

    def rates(self, time: float, states: np.ndarray) -> np.ndarray:
        self.evaluations += 1
        self.settle(time, states)
        return np.concatenate([instance.derivatives() for instance in self.instances.values()])

    def jacobian(self, time: float, states: np.ndarray) -> np.ndarray:
        """d rates / d states, exact: each instance's partial derivatives of its state derivatives and
        connected outputs (Y) with respect to its states and connected inputs (u), then the connections
        u = Y_x dx + Y_u u eliminated: J = F_x + F_u (I - Y_u)^-1 Y_x."""
        self.settle(time, states)
        count, size = len(self.connections), len(states)
        y_x, y_u = np.zeros((count, size)), np.eye(count)
        f_x, f_u = np.zeros((size, size)), np.zeros((size, count))
        for name, instance in self.instances.items():
            feeds = [k for k, (_, (target, _)) in enumerate(self.connections) if target == name]
            fed = [k for k, ((source, _), _) in enumerate(self.connections) if source == name]
            outputs = [self.connections[k][0][1] for k in fed]
            knowns = instance.state_names + [self.connections[k][1][1] for k in feeds]
            if not knowns or not (fed or instance.size):
                continue
            block = instance.partials(instance.derivative_names + outputs, knowns)
            rows, columns = self.slices[name], instance.size
            f_x[rows, rows], f_u[rows, feeds] = block[:columns, :columns], block[:columns, columns:]
            y_x[fed, rows] = block[columns:, :columns]
            y_u[np.ix_(fed, feeds)] -= block[columns:, columns:]
        return f_x + f_u @ np.linalg.solve(y_u, y_x)

    def outputs(self, time: float, states: np.ndarray, ports: Sequence[Port]) -> list[float]:
        self.settle(time, states)
        by_instance: dict[str, list[int]] = {}
        for position, (name, _) in enumerate(ports):
            by_instance.setdefault(name, []).append(position)
        values = [0.0] * len(ports)
        for name, positions in by_instance.items():
            for position, value in zip(positions, self.instances[name].get([ports[p][1] for p in positions])):
                values[position] = value
        return values

    def close(self) -> None:
        for instance in self.instances.values():
            instance.close()


def run_model_exchange(fmus: Mapping[str, Path], parameters: Mapping[str, Mapping[str, object]],
                       connections: Sequence[tuple[Port, Port]], stop_time: float, interval: float,
                       outputs: list[str], scratch: Path, rtol: float = 1e-8,
                       on_step: Callable[[int, int], None] | None = None, method: str = "DOP853",
                       initial: bool = False, counts: dict[str, int] | None = None) -> np.ndarray:
    """Rows of t_k = k ``interval`` (k = 1 ... N, from k = 0 with ``initial``) and ``outputs`` (``"instance.variable"``) of the system
    integrated by ``method`` (:data:`METHODS`; the implicit ones with :meth:`ModelExchangeSystem.jacobian`)
    at relative tolerance ``rtol``, step by step (``completedIntegratorStep`` after each), the rows from
    its dense output; ``on_step(k, N)`` after each integrator step with the rows done. ``counts``, when given, gets
    the run's integrator steps, right-hand sides and Jacobians (what its cost is made of)."""
    system = ModelExchangeSystem(fmus, parameters, connections, scratch)
    try:
        count = int(round(stop_time / interval))
        times = (np.arange(count) + 1.0) * interval
        ports = [tuple(name.split(".", 1)) for name in outputs]
        exact = {} if METHODS[method] is DOP853 else {"jac": system.jacobian}
        lacking = [name for name, instance in system.instances.items() if exact and not instance.gives_derivatives]
        if lacking:
            raise NotRunnable(f"{method} needs the system's Jacobian, and {', '.join(lacking)} "
                              f"{'gives' if len(lacking) == 1 else 'give'} no directional derivatives")
        start = system.start()
        solver = METHODS[method](system.rates, 0.0, start, times[-1], rtol=rtol, atol=ATOL, **exact)
        rows: list[list[float]] = []
        first = [[0.0, *system.outputs(0.0, start, ports)]] if initial else []
        steps = 0
        while len(rows) < count:
            message = solver.step()
            steps += 1
            if solver.status == "failed":
                raise StepRefused(method, "Discard", solver.t, [message])
            end, interpolant = solver.t, solver.dense_output()
            due = times[len(rows):][times[len(rows):] <= end]
            rows += [[time, *system.outputs(time, interpolant(time), ports)] for time in due]
            system.completed_step(end, solver.y)
            if on_step is not None:
                on_step(len(rows), count)
        if counts is not None:
            counts.update({"steps": steps, "right-hand sides": system.evaluations, "Jacobians": solver.njev})
        return np.array(first + rows)
    finally:
        system.close()
