"""The exceptions of fretwear.errors: where a caller catches them, and how an interruption
that arrives inside compiled code is recognised.

References: the documented contract of each class (InputError is bad input, a ValueError;
ConvergenceError a failed solve, a RuntimeError; both FretwearError, whose message the command
line prints without a traceback) and the shape of the exceptions Python and numba raise on
Ctrl-C, built here by hand.
"""

import pytest

from fretwear.errors import ConvergenceError, FretwearError, InputError, interrupted


def test_each_error_is_caught_where_its_kind_of_python_error_is():
    """A caller that knows nothing of fretwear catches bad input as ValueError and a failed
    solve as RuntimeError (the standard library's meaning of each); the command line catches
    both as FretwearError. Exact: class relations, nothing numerical."""
    with pytest.raises(ValueError, match="mu = -1"):
        raise InputError("mu = -1; expected mu >= 0")
    with pytest.raises(RuntimeError):
        raise ConvergenceError("no balance")
    for cls in (InputError, ConvergenceError):
        with pytest.raises(FretwearError):
            raise cls("x")
    assert not issubclass(InputError, RuntimeError)
    assert not issubclass(ConvergenceError, ValueError)


def test_an_interruption_inside_compiled_code_is_an_interruption():
    """Ctrl-C or SIGTERM that arrives while a numba function runs surfaces as SystemError
    ("returned a result with an exception set") caused, through one or more such
    SystemErrors, by the KeyboardInterrupt (seen on a killed wear run): the run must treat it
    as the interruption (save, exit 130/143), and anything else as an error."""
    from fretwear.errors import interrupted

    def nested(depth):
        exc = KeyboardInterrupt()
        for _ in range(depth):
            outer = SystemError("returned a result with an exception set")
            outer.__cause__ = exc
            exc = outer
        return exc

    assert interrupted(KeyboardInterrupt())
    assert interrupted(nested(1)) and interrupted(nested(2))
    assert not interrupted(SystemError("something else"))
    other = SystemError("x")
    other.__cause__ = ValueError("y")
    assert not interrupted(other)


def test_a_cycle_of_causes_ends_and_is_not_an_interruption():
    """A SystemError that is (through its causes) its own cause must not hang the check; it
    holds no KeyboardInterrupt, so it is an error. A KeyboardInterrupt that is the cause of
    a non-SystemError is not looked for (only numba's SystemError wraps it). Exact answers."""
    a, b = SystemError("a"), SystemError("b")
    a.__cause__, b.__cause__ = b, a
    assert not interrupted(a)
    wrapped = RuntimeError("wrapped")
    wrapped.__cause__ = KeyboardInterrupt()
    assert not interrupted(wrapped)
