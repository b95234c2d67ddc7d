"""A halfshaft between a joint whose housing moves with the powertrain and one fixed at its wheel."""
