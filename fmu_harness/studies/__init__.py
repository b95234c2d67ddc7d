"""The main job's engineering studies on the native FMUs, each writing CSV files and figures:
:mod:`.tripod_study`, :mod:`.coupling_comparison`, :mod:`.critical_speed_study`, with the CSV
writer :mod:`fmu_harness.runs.result_table` (which the sweeps and the system command share)."""
