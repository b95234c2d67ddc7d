"""fmpy-based harness: run the project's FMUs, write results and figures."""
