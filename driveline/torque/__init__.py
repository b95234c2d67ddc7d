"""Motor torque source for system simulations: a ramp to a level, then held.

Modules: :mod:`.spec` and :mod:`.model` (the ``TorqueSource`` FMU's interface and time stepping).
"""
