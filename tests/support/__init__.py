"""What the tests share: reference models and solutions (ROSS, Exudyn, rotor and tripod checks), the
two families of FMUs and what each promises against the core, the C test host and the C rotor
library's Python bindings. Imported as ``support`` (the tests' folder is on the path)."""
