"""Driveline mechanics from the seed papers, free of any FMI dependency.

Each mechanism has a physics core (plain numpy/scipy functions), a declarative
variable table (:class:`driveline.variables.ModelSpec`) and a time-stepping model
(:class:`driveline.model.SteppedModel`) that the FMU adapters in ``fmu_src`` wrap.
"""

__version__ = "0.1.0"
