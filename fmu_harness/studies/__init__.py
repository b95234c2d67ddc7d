"""The main job's engineering studies on the native FMUs, each writing CSV files and figures:
:mod:`.tripod_study`, :mod:`.coupling_comparison`, :mod:`.critical_speed_study`, with the CSV
writer :mod:`.result_table`."""
