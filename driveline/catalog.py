"""Every model of the project, by FMU name; the build and the test harness iterate this.

Each model's module is imported when the model is first asked for (``MODELS[name]``, or iterating the
values), so a host that checks or runs one model imports that model's core alone, not every core with
its scipy modules (``driveline-fmus system`` on a package of two models starts without the rotor's).
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, Mapping

from .model import SteppedModel

#: Each model's class, by FMU name, as ``module:class``, in the catalog's order.
CLASSES = {
    "TripodCoupling": "driveline.tripod.model:TripodCouplingModel",
    "CardanJoint": "driveline.cardan.model:CardanJointModel",
    "UniversalReducer": "driveline.reducer.model:UniversalReducerModel",
    "CriticalSpeeds": "driveline.rotor.model:CriticalSpeedsModel",
    "SpeedSource": "driveline.source.model:SpeedSourceModel",
    "PowertrainMounts": "driveline.mounts.model:PowertrainMountsModel",
    "TorqueSource": "driveline.torque.model:TorqueSourceModel",
    "VehicleDriveline": "driveline.vehicle.model:VehicleDrivelineModel",
}


class Catalog(Mapping[str, type[SteppedModel]]):
    """The models by FMU name, each class imported on first use and checked to carry that name."""

    def __init__(self, classes: Mapping[str, str]):
        self._classes = dict(classes)
        self._loaded: dict[str, type[SteppedModel]] = {}

    def __getitem__(self, name: str) -> type[SteppedModel]:
        if name not in self._loaded:
            module, _, attribute = self._classes[name].partition(":")
            model = getattr(importlib.import_module(module), attribute)
            if model.spec.name != name:
                raise ValueError(f"the catalog's {name} is {model.__qualname__}, whose spec names {model.spec.name}")
            self._loaded[name] = model
        return self._loaded[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._classes)

    def __len__(self) -> int:
        return len(self._classes)


MODELS: Mapping[str, type[SteppedModel]] = Catalog(CLASSES)
