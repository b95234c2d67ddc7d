"""The measured CPU time of one work-budget unit (:mod:`.budget`), in each core: written by
``python -m benchmarks.unit_rates --update-docs`` (the analysis of ``BUDGET_LAYOUT``, which spends the
whole budget, divided by its units), not by hand. The refusal's "about N s" and the docs follow from it.
"""

#: When, where and under what load the rates below were measured.
MEASURED = ('2026-12-07 07:23 UTC on AMD EPYC (x86_64), 2 cores, Python 3.11.7; '
            'load average (1 min) 11.34 at start, 10.50 at end; '
            "CPU time of the budget layout's analysis over 33333333 units, best of 3 rounds")
#: Native CPU seconds of one unit.
NATIVE_SECONDS_PER_UNIT = 4.5e-08
#: Python core CPU seconds of one unit.
PYTHON_SECONDS_PER_UNIT = 2.6e-07
