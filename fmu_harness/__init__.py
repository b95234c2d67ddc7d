"""Everything around the models that is not physics: build the FMUs, run them, check them, study them.

One layer imports only the layers below it (``tests/project/test_package_layers.py`` holds them to it):

* :mod:`.console`: what the commands show their user: one-line mistakes, progress, missing extras;
* :mod:`.packaging`: the Python and native FMUs made from the catalog (model description, shipped
  files, C build for five platforms, generated C constants);
* :mod:`.doc_pages`: the generated sections of the docs pages (variable tables);
* :mod:`.runs`: running built FMUs through fmpy: an instance, the standard scenarios, the SSP
  system and its master, sweeps on Dask;
* :mod:`.checks`: judging FMUs: cross-check references, the importer matrix, robustness probes,
  the analysis work bound, the Python FMUs against the native ones;
* :mod:`.studies`: the main job's engineering studies, their CSV files and figures;
* the commands on top: :mod:`.build_command` (``python build_fmu.py``), :mod:`.main` (the main job)
  and :mod:`.cli` (``driveline-fmus``).
"""
