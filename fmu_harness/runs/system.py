"""The driveline system: an SSP 1.0 package of the project's FMUs and a small fmpy master for it.

Usage: ``python -m fmu_harness.runs.system [--models models] [--native]`` after ``python build_fmu.py``
(which also writes both packages): writes ``models/Driveline.ssp`` and prints the last values of
the system's outputs from the fmpy master. With ``--native`` the same for the native variant,
``models/native/Driveline.ssp``: each component's native (C) FMU where its model has one
(:func:`fmu_harness.packaging.native.native_models`), its Python FMU otherwise; each component's
``description`` in the package says which.

The system: ``SpeedSource`` (a speed ramp with a superposed sine) drives ``TripodCoupling``'s
input shaft; ``CriticalSpeeds``, when the catalog has it, watches the coupling's output shaft
speed through each of its rad/s inputs. Parameter bindings set the ramp, the bend angle, the
load torque and exact kinematics; every component's bindings form one parameter set named
after the system (Ecos applies a parameter set by name at initialisation, libcosim applies
all bindings). The package holds the FMI 2.0 FMUs (libcosim reads no FMI 3.0).

:func:`simulate` is a fixed-step Jacobi master like the importers': connected inputs start
from the start values of their outputs, then all components step from t_k together, their
inputs set from the connected outputs at t_k.
"""

from __future__ import annotations

import argparse
import math
import zipfile
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
from fmpy.model_description import ModelDescription

from driveline.catalog import MODELS
from driveline.mounts.halfshafts import GEOMETRY
from driveline.mounts.spec import DESIGN as MOUNTS_DESIGN
from driveline.vehicle import dynamics
from driveline.vehicle.dynamics import Drive
from driveline.variables import UNITS, ModelSpec, Variable

from ..packaging import native
from . import container, ssp_package
from .runner import FmuInstance, StepRefused
from .ssp import SSC, SSD, SSV
from .ssp_package import SspSystem
from .start_values import Instance, StartValuesRefused, check_start_values
from ..console import summary

for prefix, uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV)):
    ET.register_namespace(prefix, uri)

RPM = math.pi / 30.0
WATCHER = "CriticalSpeeds"


@dataclass(frozen=True)
class Component:
    """One FMU instance of the system and its parameter bindings."""

    name: str
    model: str
    parameters: Mapping[str, float | int]

    @property
    def spec(self) -> ModelSpec:
        return MODELS[self.model].spec


@dataclass(frozen=True)
class Connection:
    start: tuple[str, str]
    end: tuple[str, str]


@dataclass(frozen=True)
class System:
    name: str
    components: tuple[Component, ...]
    connections: tuple[Connection, ...]
    stop_time: float
    step_size: float
    shown: tuple[str, ...] = ()
    """The outputs its one-FMU build (:func:`write_container`) shows as outputs, ``component.variable``; the
    others stay readable there as local variables. Empty: every output."""

    def component(self, name: str) -> Component:
        return next(c for c in self.components if c.name == name)

    def outputs(self) -> list[str]:
        """Every Real output as ``"component.variable"``."""
        return [f"{c.name}.{v.name}" for c in self.components for v in c.spec.of("output") if v.type == "Real"]


#: The couplings the driveline system takes and their bindings: bent 20 degrees under 150 N.m (the
#: tripod with its exact kinematics).
COUPLINGS = {
    "TripodCoupling": {"kinematics": 1, "beta": math.radians(20.0), "T_load": 150.0},
    "CardanJoint": {"beta": math.radians(20.0), "T_load": 150.0},
}
#: What the source feeds the coupling's input shaft (every coupling of COUPLINGS has both inputs): its
#: output shaft's speed and acceleration.
SOURCE_TO_COUPLING = (("omega_out", "omega_in"), ("alpha_out", "alpha_in"))


def driveline(coupling: str = "TripodCoupling") -> System:
    """Speed ramp 500 to 3000 rpm in 1 s with a 50 rpm, 5 Hz sine, into ``coupling`` (one of
    :data:`COUPLINGS`) bent 20 degrees under 150 N.m; ``CriticalSpeeds`` on the output shaft when it
    exists. The source's speed and acceleration feed the coupling's ``omega_in`` and ``alpha_in``."""
    components = [
        Component("source", "SpeedSource", {"omega_out_start": 500.0 * RPM, "ramp_rate": 2500.0 * RPM,
                                            "sine_amplitude": 50.0 * RPM, "sine_frequency": 5.0}),
        Component("coupling", coupling, COUPLINGS[coupling]),
    ]
    connections = [Connection(("source", output), ("coupling", name)) for output, name in SOURCE_TO_COUPLING]
    if WATCHER in MODELS:
        components.append(Component("critical", WATCHER, {}))
        connections += [
            Connection(("coupling", "omega_out"), ("critical", v.name))
            for v in MODELS[WATCHER].spec.of("input") if v.unit == "rad/s"
        ]
    return System("Driveline", tuple(components), tuple(connections), 1.0, 1e-3)


MOUNTS = "PowertrainMounts"
SIDES = ("left", "right")
#: What each joint feeds the drive back (its output of the same name, per side).
JOINT_FEEDBACK = ("T_in", "phi_out", "omega_out")
#: What the drive feeds each joint.
JOINT_DRIVE = ("omega_in", "alpha_in", "T_load")
#: The joints' housing loads PowertrainMounts takes per side, under the joint's own names: the forces and the
#: bending moments; the moment about the housing's axis reaches the powertrain through the gears, with the
#: rotating parts' inertia, as the drive's ``T_reaction`` (about y, into the mounts' ``M_y``).
HOUSING_LOADS = ("Rx_in", "Ry_in", "Rz_in", "Mx_in", "My_in")
#: What PowertrainMounts feeds each joint: its halfshaft's geometry on the moving powertrain (the output
#: ``<name>_<side>`` into the joint's input ``<name>``), each that the joint takes as an input.
HALFSHAFT_GEOMETRY = GEOMETRY
#: The package's halfshafts (PowertrainMounts' defaults, the joints' l and beta_max the same): the left
#: joint bent 8 deg on the 0.45 m shaft, the right one 6 deg on the 0.70 m one, in the vertical plane.
HALFSHAFTS = MOUNTS_DESIGN


#: The joints' connected inputs at the launch's consistent start (the drive at rest, the halfshafts untwisted):
#: their start values in the package, so that a master that iterates the initialisation exchange from the
#: start values (libcosim, Ecos: a few Jacobi sweeps of the loop) starts at its fixed point, not at the
#: joint's own defaults (2000 rpm, 100 N.m), from which a few sweeps leave about 1 N.m in the loop.
JOINT_AT_REST = {"omega_in": 0.0, "alpha_in": 0.0, "T_load": 0.0}


#: The launch's outputs its one FMU shows as outputs (what fmpy records by default, a host offers as ports):
#: the motor's torque, the vehicle speed, the motor's speed, the halfshaft torques at the drive and at each
#: joint, each joint's input angle (the order tracking's shaft) and axial housing force, the powertrain's six
#: accelerations (the shudder study's pitch, lateral and yaw among them). Every other output stays readable
#: by name as a local variable: recording all 200 at every 0.1 ms step cost fmpy ten times the launch itself.
LAUNCH_SHOWN = (
    "motor.T_motor", "drive.v_x", "drive.omega_motor", "drive.T_load_left", "drive.T_load_right",
    *(f"joint_{side}.{name}" for side in SIDES for name in ("T_in", "phi_in", "Rz_in")),
    *(f"mounts.{axis}_ddot" for axis in ("x", "y", "z", "roll", "pitch", "yaw")),
)


def vehicle_launch(housing_motion: bool = True) -> System:
    """A launch of a front-wheel-drive car from standstill: ``TorqueSource`` ramps the motor to 140 N.m
    (half its peak) in 0.3 s into ``VehicleDriveline``, whose side gears drive two ``TripodCoupling`` s
    (exact kinematics, friction 0.05; left 8 deg on the 0.45 m shaft, right 6 deg on the 0.70 m one)
    that twist the halfshafts; ``PowertrainMounts``, when the catalog has it, takes both joints' housing
    loads and the drive's ``T_reaction`` (its ``g`` the drive's standard gravity: one value across the models)
    and gives each joint its halfshaft's geometry on the moving powertrain (:data:`HALFSHAFT_GEOMETRY`; its
    ``housing_motion`` 0 holds the design geometry, the housings as if fixed). Without ``housing_motion``
    the package of before: the joints' bends bound, PowertrainMounts feeding them nothing. Communication step
    0.1 ms (the differential's internal mode, 670 rad/s, needs it)."""
    moving = housing_motion and MOUNTS in MODELS
    joints = {side: {**JOINT_AT_REST, "kinematics": 1, "mu": 0.05, "l": HALFSHAFTS[side][0],
                     **({"beta_rate": 0} if moving else {"beta": HALFSHAFTS[side][1]}), "phi_in_start": 0.0}
              for side in SIDES}
    components = [
        Component("motor", "TorqueSource", {"T_level": 140.0, "ramp_time": 0.3}),
        Component("drive", "VehicleDriveline", {}),
        *(Component(f"joint_{side}", "TripodCoupling", joints[side]) for side in SIDES),
    ]
    connections = [Connection(("motor", "T_motor"), ("drive", "T_motor"))]
    if moving:  # first: the initialisation exchange hands the joints their bend before they report phi_out
        joint_inputs = {v.name for v in MODELS["TripodCoupling"].spec.of("input")}
        connections += [Connection(("mounts", f"{name}_{side}"), (f"joint_{side}", name))
                        for side in SIDES for name in HALFSHAFT_GEOMETRY if name in joint_inputs]
    for side in SIDES:
        joint = f"joint_{side}"
        connections += [Connection(("drive", f"{name}_{side}"), (joint, name)) for name in JOINT_DRIVE]
        connections += [Connection((joint, name), ("drive", f"{name}_{side}")) for name in JOINT_FEEDBACK]
    if MOUNTS in MODELS:
        components.append(Component("mounts", MOUNTS, {"g": dynamics.GRAVITY, "housing_motion": int(moving)}))
        connections += [Connection((f"joint_{side}", name), ("mounts", f"{name}_{side}"))
                        for side in SIDES for name in HOUSING_LOADS]
        connections.append(Connection(("drive", "T_reaction"), ("mounts", "M_y")))
    shown = tuple(name for name in LAUNCH_SHOWN if MOUNTS in MODELS or not name.startswith("mounts."))
    return System("VehicleLaunch", tuple(components), tuple(connections), 4.0, 1e-4, shown)


#: The launch's Gauss-Seidel order: the drive first, whose outputs the joints pass on within the step
#: (their T_in depends directly on T_load and alpha_in), then the joints, then the mounts they load.
LAUNCH_ORDER = ("motor", "drive", "joint_left", "joint_right", "mounts")


def systems() -> tuple[System, ...]:
    """Every system the build packages."""
    return driveline(), vehicle_launch()


# -- SSP ------------------------------------------------------------------------------------
def _type_element(variable: Variable) -> ET.Element:
    return ET.Element(f"{{{SSC}}}{variable.type}", {"unit": variable.unit} if variable.unit and variable.type == "Real" else {})


def _component(component: Component, connected: set[str], parameter_set: str, family: str) -> ET.Element:
    element = ET.Element(f"{{{SSD}}}Component", name=component.name, description=f"{family} FMU of {component.model}",
                         type="application/x-fmu-sharedlibrary", source=f"resources/{component.model}.fmu")
    connectors = ET.SubElement(element, f"{{{SSD}}}Connectors")
    for variable in component.spec.variables:
        if variable.causality in ("input", "output") and f"{component.name}.{variable.name}" in connected:
            connector = ET.SubElement(connectors, f"{{{SSD}}}Connector", name=variable.name, kind=variable.causality)
            connector.append(_type_element(variable))
    if component.parameters:
        values = ET.SubElement(ET.SubElement(ET.SubElement(element, f"{{{SSD}}}ParameterBindings"),
                                             f"{{{SSD}}}ParameterBinding"), f"{{{SSD}}}ParameterValues")
        parameters = ET.SubElement(ET.SubElement(values, f"{{{SSV}}}ParameterSet", version="1.0", name=parameter_set),
                                   f"{{{SSV}}}Parameters")
        for name, value in component.parameters.items():
            variable = component.spec[name]
            parameter = ET.SubElement(parameters, f"{{{SSV}}}Parameter", name=name)
            attributes = {"value": repr(float(value)) if variable.type == "Real" else str(value)}
            if variable.unit and variable.type == "Real":
                attributes["unit"] = variable.unit
            ET.SubElement(parameter, f"{{{SSV}}}{variable.type}", attributes)
    return element


def system_structure(system: System, natives: Collection[str] = ()) -> bytes:
    """The SSP 1.0 ``SystemStructure.ssd`` of ``system``, the components of the models in
    ``natives`` described as native FMUs, the others as Python FMUs."""
    root = ET.Element(f"{{{SSD}}}SystemStructureDescription", version="1.0", name=system.name)
    element = ET.SubElement(root, f"{{{SSD}}}System", name=system.name)
    connected = {f"{c}.{v}" for connection in system.connections for c, v in (connection.start, connection.end)}
    ET.SubElement(element, f"{{{SSD}}}Elements").extend(
        _component(c, connected, system.name, "native" if c.model in natives else "Python") for c in system.components
    )
    connections = ET.SubElement(element, f"{{{SSD}}}Connections")
    for connection in system.connections:
        ET.SubElement(connections, f"{{{SSD}}}Connection", startElement=connection.start[0],
                      startConnector=connection.start[1], endElement=connection.end[0], endConnector=connection.end[1])
    used = {v.unit for c in system.components for v in c.spec.variables if v.unit}
    units = ET.SubElement(root, f"{{{SSD}}}Units")
    for unit in (UNITS[name] for name in UNITS if name in used):
        ET.SubElement(ET.SubElement(units, f"{{{SSC}}}Unit", name=unit.name), f"{{{SSC}}}BaseUnit",
                      {k: str(v) for k, v in unit.exponents.items()})
    ET.SubElement(root, f"{{{SSD}}}DefaultExperiment", startTime="0.0", stopTime=repr(system.stop_time))
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def native_components(system: System, natives: Path | None) -> list[str]:
    """The models of ``system`` that run as native FMUs: those with a C port, given ``natives``."""
    models = {c.model for c in system.components}
    return [] if natives is None else [model for model in native.native_models() if model in models]


def component_fmus(system: System, models: Path, natives: Path | None = None) -> dict[str, Path]:
    """``{model: FMI 2.0 FMU}`` for the models of ``system``: the native FMUs below ``natives``
    (``native/``) of :func:`native_components`, the Python FMUs in ``models`` of the others."""
    from ..packaging import fmu_path  # the Python FMUs' builder, not needed to run a package

    fmus = {c.model: fmu_path(models, c.model) for c in system.components}
    if natives is not None:
        fmus |= {model: native.fmu_path(natives, model) for model in native_components(system, natives)}
    return fmus


def ssp_path(system: System, models: Path, natives: Path | None = None) -> Path:
    """Where :func:`write_ssp` puts the package: ``models/<system>.ssp``, the native variant
    ``natives/native/<system>.ssp``."""
    return models / f"{system.name}.ssp" if natives is None else native.fmu_path(natives, system.name).with_suffix(".ssp")


def write_ssp(system: System, models: Path, natives: Path | None = None) -> Path:
    """The SSP package of ``system`` at :func:`ssp_path` with the FMUs of :func:`component_fmus`."""
    fmus = component_fmus(system, models, natives)
    path = ssp_path(system, models, natives)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("SystemStructure.ssd", system_structure(system, native_components(system, natives)))
        for model in sorted(fmus):
            archive.write(fmus[model], f"resources/{model}.fmu")
    return path


def container_path(system: System, models: Path, fmi: str = "2") -> Path:
    """Where :func:`write_container` puts the system as one FMU: ``models/native/<system>.fmu``, FMI 3.0 in
    ``models/native/fmi3/``."""
    return native.fmu_path(models, system.name, fmi)


def write_container(system: System, models: Path, fmi: str = "2") -> Path:
    """The native package of ``system`` (:func:`write_ssp` with ``natives``) as one co-simulation FMU
    (:mod:`fmu_harness.runs.container`) at :func:`container_path`: the native FMUs of FMI version ``fmi``
    inside, stepping by Jacobi at the system's step as the project's master does, showing the system's
    :attr:`System.shown` outputs as outputs."""
    package = ssp_package.read(ssp_path(system, models, models))
    fmus = {c.name: native.fmu_path(models, c.model, fmi) for c in system.components}
    return container.build(package, fmus, container_path(system, models, fmi), system.step_size, int(fmi),
                           shown=system.shown)


# -- fmpy master ----------------------------------------------------------------------------
Port = tuple[str, str]


class Reading:
    """A batched read of outputs ``(instance, variable)``: one call per instance, with its value
    references and buffer prepared once (:meth:`FmuInstance.reader`)."""

    def __init__(self, instances: Mapping[str, FmuInstance], ports: Sequence[Port]):
        names: dict[str, list[str]] = {}
        for instance, variable in ports:
            if variable not in names.setdefault(instance, []):
                names[instance].append(variable)
        self.position = {port: i for i, port in enumerate((i, v) for i, found in names.items() for v in found)}
        """Each port's place in the values read."""
        self._reads = [instances[instance].reader(tuple(found)) for instance, found in names.items()]

    def __call__(self) -> list[float]:
        return [value for read in self._reads for value in read()]


class Transfer:
    """Connections ``((instance, output), (instance, input))`` carried in batches: one read of the
    connected outputs per source instance (:class:`Reading`), then one write of the connected inputs
    per destination instance."""

    def __init__(self, instances: Mapping[str, FmuInstance], connections: Collection[tuple[Port, Port]]):
        self._read = Reading(instances, [start for start, _ in connections])
        targets: dict[str, list[tuple[str, int]]] = {}
        for start, (target, name) in connections:
            targets.setdefault(target, []).append((name, self._read.position[start]))
        self._writes = [(instances[target].writer(tuple(name for name, _ in pairs)), [i for _, i in pairs])
                        for target, pairs in targets.items()]

    def __call__(self) -> None:
        """Set every connected input from its output as they are now."""
        values = self._read()
        for write, positions in self._writes:
            write([values[i] for i in positions])


def run_jacobi(fmus: Mapping[str, Path], parameters: Mapping[str, Mapping[str, object]],
               connections: Collection[tuple[Port, Port]], stop_time: float, step_size: float,
               outputs: list[str], on_step: Callable[[int, int], None] | None = None,
               order: Sequence[str] | None = None,
               unpacked: Mapping[str, tuple[str, ModelDescription]] | None = None, initial: bool = False) -> np.ndarray:
    """The fixed-step Jacobi master: instances ``{name: FMU}`` with their start values, connections
    ``((instance, output), (instance, input))``; rows of t_k and ``outputs`` (``"instance.variable"``)
    for t_1 ... t_N, from t_0 = 0 (the outputs after initialisation) with ``initial``. ``on_step(k, N)`` is called after each step. A refused step or initialisation
    raises :class:`StepRefused` with the instance's name before its reasons. With ``order`` (every instance's
    name) it is a Gauss-Seidel master instead: the instances step one after the other in that order,
    each with its inputs set just before from the outputs as they are then (those of the instances
    already stepped at t_k+1). ``unpacked``: ``{name: (extracted folder, model description)}`` of
    FMUs already extracted and parsed (kept after the run).

    Values travel in batches (:class:`Transfer`, :class:`Reading`): per step one read per instance feeding others, one
    write per instance fed, one doStep per instance and one read per instance of ``outputs``."""
    unpacked = unpacked or {}
    instances = {name: FmuInstance(path, name, *unpacked.get(name, (None, None))) for name, path in fmus.items()}
    try:
        # Like the importers: all instances enter initialisation, each connection carries the
        # start value of its output (outputs are computed on exit), then all exit.
        for name, instance in instances.items():
            instance.enter_initialization(parameters.get(name, {}))
        for start, end in connections:
            instances[end[0]].set({end[1]: instances[start[0]].get([start[1]])[0]})
        for name, instance in instances.items():
            _named(name, instance.exit_initialization)

        ports = [tuple(name.split(".", 1)) for name in outputs]
        record = Reading(instances, ports)
        columns = [record.position[port] for port in ports]
        steps = int(round(stop_time / step_size))
        groups = [list(instances)] if order is None else [[name] for name in order]
        sweeps = [(group, Transfer(instances, [c for c in connections if c[1][0] in group])) for group in groups]
        rows = [record()] if initial else []
        for k in range(steps):
            for group, transfer in sweeps:
                transfer()
                _step(instances, group, k, step_size)
            rows.append(record())
            if on_step is not None:
                on_step(k + 1, steps)
        times = (np.arange(len(rows)) + (0.0 if initial else 1.0)) * step_size
        return np.column_stack([times, np.array(rows, dtype=float).reshape(len(rows), len(outputs))[:, columns]])
    finally:
        for instance in instances.values():
            instance.close()


def _step(instances: Mapping[str, FmuInstance], names: list[str], k: int, step_size: float) -> None:
    """Step the instances ``names`` from t_k."""
    for name in names:
        instance = instances[name]
        instance.time = k * step_size
        _named(name, instance.step, step_size)


def _named(name: str, call: Callable[..., None], *arguments: object) -> None:
    """``call(*arguments)`` of the instance ``name``; its :class:`StepRefused` names the instance first."""
    try:
        call(*arguments)
    except StepRefused as refused:
        raise StepRefused(f"{name}: {refused.call}", refused.status, refused.time, refused.messages) from None


def step_limit_error(system: SspSystem, models: Mapping[str, str], step: float) -> str | None:
    """Why ``step`` is too long for a component whose model (``models``: each component's model name)
    states a limit for a Jacobi coupling (the Jacobi master, libcosim, Ecos): a ``VehicleDriveline``'s
    differential mode; None when no limit is passed."""
    for component in system.components:
        if models[component.name] != "VehicleDriveline":
            continue
        values = {v.name: v.start for v in MODELS["VehicleDriveline"].spec.variables} | component.parameters
        drive = Drive(*(float(values[name]) for name in Drive._fields))
        limit = dynamics.jacobi_step_limit(drive)
        if step > limit:
            return (f"{component.name} (VehicleDriveline): --step {step!r} s is above {limit:.3g} s, the longest step "
                    f"at which its differential's internal mode ({dynamics.modes_text(drive)}) stays stable with the "
                    f"joints' torques one step late (omega h <= min({dynamics.JACOBI_OMEGA_STEP}, "
                    f"{dynamics.JACOBI_DAMPING_STEP} zeta)): take a shorter step, or the Gauss-Seidel master")
    return None


def simulate(system: System, models: Path, outputs: list[str] | None = None, natives: Path | None = None,
             order: Sequence[str] | None = None) -> np.ndarray:
    """Run ``system`` with the FMUs of :func:`component_fmus`; rows of t_k and ``outputs``
    (default: all Real outputs) for t_1 ... t_N. Parameters an FMU would refuse raise
    ``StartValuesRefused`` before any FMU is loaded."""
    check_start_values([Instance(c.name, c.model, c.parameters) for c in system.components])
    fmus = component_fmus(system, models, natives)
    return run_jacobi({c.name: fmus[c.model] for c in system.components},
                      {c.name: c.parameters for c in system.components},
                      [(connection.start, connection.end) for connection in system.connections],
                      system.stop_time, system.step_size, outputs or system.outputs(), order=order)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=summary(__doc__))
    parser.add_argument("--models", type=Path, default=Path("models"), help="folder of built FMUs")
    parser.add_argument("--native", action="store_true", help="the native FMUs where a model has one")
    args = parser.parse_args(argv)
    system = driveline()
    natives = args.models if args.native else None
    print(write_ssp(system, args.models, natives))
    try:
        result = simulate(system, args.models, natives=natives)
    except StartValuesRefused as refused:
        parser.exit(1, f"refused: {refused}\n")
    for name, last in zip(system.outputs(), result[-1, 1:]):
        print(f"{name} = {last:.9g}")


if __name__ == "__main__":
    main()
