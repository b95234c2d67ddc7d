"""Universal reducer: few-teeth-difference planetary gear driven through an RCRCR
spatial mechanism (seed 004: Gu, Chen 2016).

Modules: :mod:`.mechanics` (ratio, RCRCR slide, strength relations eqs 18-21 and the
third-strength-theory check), :mod:`.spec` and :mod:`.model` (the FMU's interface and
time stepping).
"""
