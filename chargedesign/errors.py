"""The project's exceptions: every user-facing failure is one of these, with a one-line message."""


class ChargeDesignError(ValueError):
    """Base class: a one-line, user-facing reason. The CLI prints it without a traceback."""


class InputError(ChargeDesignError):
    """Bad input: names the input and what was received."""


class InfeasibleError(ChargeDesignError):
    """The targets cannot be realised; the message names the condition or parameter."""


class SolverError(ChargeDesignError):
    """A numerical solver failed or returned a result that does not meet its checks."""
