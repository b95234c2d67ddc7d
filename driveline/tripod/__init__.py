"""Tripod sliding universal coupling (seed 000: Xiu, Chang, Ju, Zheng 2024).

Modules: :mod:`.geometry` (orbit radius, arm lengths), :mod:`.closed_form` (eq 18
and its consistent derivative), :mod:`.exact` (numerical closed-loop kinematics),
:mod:`.dynamics` (the seed's eqs 20-34 as printed), :mod:`.reactions` (exact bearing
reactions from the force balance), :mod:`.reactions_closed_form` (their leading order in
r/l), :mod:`.spec` and :mod:`.model` (the FMU's interface and time stepping).
"""
