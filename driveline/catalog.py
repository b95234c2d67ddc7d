"""Every model of the project, by FMU name; the build and the test harness iterate this."""

from __future__ import annotations

from .cardan.model import CardanJointModel
from .model import SteppedModel
from .mounts.model import PowertrainMountsModel
from .reducer.model import UniversalReducerModel
from .rotor.model import CriticalSpeedsModel
from .source.model import SpeedSourceModel
from .torque.model import TorqueSourceModel
from .tripod.model import TripodCouplingModel
from .vehicle.model import VehicleDrivelineModel

MODELS: dict[str, type[SteppedModel]] = {
    model.spec.name: model
    for model in (
        TripodCouplingModel, CardanJointModel, UniversalReducerModel, CriticalSpeedsModel, SpeedSourceModel,
        PowertrainMountsModel, TorqueSourceModel, VehicleDrivelineModel,
    )
}
