"""The one error type every user-facing check raises.

An InputError carries a one-line message that names the offending field and the problem, e.g.
``joints[2].axis: zero vector``.  The CLI prints it as ``tservo: error: <message>`` and exits
with status 2, without a traceback and without writing any output file.
"""


class InputError(ValueError):
    """Bad user input (file, field, array); ``str(e)`` is the one-line message."""

    def __init__(self, field: str, problem: str):
        self.field = field
        self.problem = problem
        super().__init__(f"{field}: {problem}" if field else problem)
