"""FMI 2.0 co-simulation FMU of the tripod sliding universal coupling."""

from driveline.tripod.model import TripodCouplingModel
from fmi2_slave import ModelSlave


class TripodCoupling(ModelSlave):
    model_class = TripodCouplingModel
