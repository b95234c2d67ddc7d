"""Judging built FMUs: :mod:`.crosscheck` their FMI Cross-Check references, :mod:`.interop` and
:mod:`.importers` the importer matrix, :mod:`.robustness` with :mod:`.robustness_probe` and
:mod:`.failing_model` the hostile-input tables, :mod:`.analysis_work` the analysis work bound,
:mod:`.python_fmu_check` the Python FMUs against the native ones."""
