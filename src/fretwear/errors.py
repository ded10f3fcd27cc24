"""Exceptions that carry a message meant for the user (printed without a traceback)."""


class FretwearError(Exception):
    """Base class: the message says what is wrong and what is expected."""


class InputError(FretwearError, ValueError):
    """Bad input: a case file, a model definition or an argument."""


class ConvergenceError(FretwearError, RuntimeError):
    """A solve that did not converge where nothing can go on without it (or where the caller
    asked for an exception, ``raise_on_failure``); results otherwise say so themselves
    (``success`` False, ``message``) and a failed solve is never saved as a result."""
