"""The one exception type of the analysis tools.

InputError means "the user's input cannot give an answer": a malformed or too short
log, a missing column, a sweep that does not bracket the resonance, a fit with too few
points. The command-line scripts print its message on one line and exit non-zero;
anything else escaping a tool is a bug and keeps its traceback.
"""


class InputError(ValueError):
    """Bad or insufficient input data; the message says what and where."""
