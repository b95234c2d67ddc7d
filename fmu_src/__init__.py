"""What goes into an FMU besides the model's own modules: the FMI 2.0 and 3.0 adapters over one
model adapter, and :mod:`.loading`, which every generated FMU script calls for its slave base."""

# Imported with the package, so that a host holding this package from another FMU's folder also
# holds the module an FMU script imports first (the package's search path may be gone by then).
from . import loading  # noqa: F401
