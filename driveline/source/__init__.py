"""Shaft speed source for system simulations: a ramp with a superposed sine.

Modules: :mod:`.spec` and :mod:`.model` (the ``SpeedSource`` FMU's interface and time stepping).
"""
