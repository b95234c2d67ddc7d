"""Cardan (Hooke) joint (seed 003: note on the Cardan joint equation of motion).

Modules: :mod:`.kinematics` (exact output angle, speed, acceleration and speed
fluctuation), :mod:`.spec` and :mod:`.model` (the FMU's interface and time stepping).
"""
