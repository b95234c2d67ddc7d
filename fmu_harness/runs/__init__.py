"""Running built FMUs through fmpy: :mod:`.runner` one instance, :mod:`.scenario` the standard
input signals, :mod:`.system` the driveline as an SSP system and its master, :mod:`.sweep` parameter
sweeps on Dask."""
