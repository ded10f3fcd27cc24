"""Exceptions that carry a message meant for the user (printed without a traceback)."""


class FretwearError(Exception):
    """Base class: the message says what is wrong and what is expected."""


class InputError(FretwearError, ValueError):
    """Bad input: a case file, a model definition or an argument."""


class ConvergenceError(FretwearError, RuntimeError):
    """A solve that did not converge where nothing can go on without it (or where the caller
    asked for an exception, ``raise_on_failure``); results otherwise say so themselves
    (``success`` False, ``message``) and a failed solve is never saved as a result."""


def interrupted(exc: BaseException) -> bool:
    """True for Ctrl-C (or SIGTERM turned into it): a KeyboardInterrupt, or the SystemError a
    compiled function (a numba dispatcher) raises when the interruption arrives while it runs
    ("returned a result with an exception set"), whose cause (possibly through further such
    SystemErrors) is the KeyboardInterrupt."""
    seen = 0
    while isinstance(exc, SystemError) and exc.__cause__ is not None and seen < 16:
        exc, seen = exc.__cause__, seen + 1  # numba nests them: SystemError <- SystemError
    return isinstance(exc, KeyboardInterrupt)
