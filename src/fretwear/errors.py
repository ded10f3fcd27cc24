"""Exceptions that carry a message meant for the user (printed without a traceback)."""


class FretwearError(Exception):
    """Base class: the message says what is wrong and what is expected."""


class InputError(FretwearError, ValueError):
    """Bad input: a case file, a model definition or an argument."""


class ConvergenceError(FretwearError, RuntimeError):
    """A solve that did not converge (never returned or saved as a result)."""
