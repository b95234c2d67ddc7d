"""The parts of a front-wheel-drive car between the motor and the road other than the joints.

Modules: :mod:`.compact_car` (the default car's data and their sources), :mod:`.dynamics` (the
equations of motion and their integration over a communication step), :mod:`.spec` and
:mod:`.model` (the ``VehicleDriveline`` FMU's interface and time stepping).
"""
