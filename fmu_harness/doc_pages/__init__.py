"""The generated parts of the docs pages: :mod:`.sections` finds and replaces them,
:mod:`.variable_table` writes each model's variable table."""
