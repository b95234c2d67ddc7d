"""A rigid powertrain on linear rubber mounts, small motion about its static equilibrium.

:mod:`.layout` reads the layout files, :mod:`.rigid_body` builds the mass, stiffness and
damping matrices and the modes with their kinetic-energy decoupling table, :mod:`.joints`
turns TripodCoupling's housing reactions into loads on the powertrain, and :mod:`.exact_step`
moves the state over a step by the matrix exponential.
"""
