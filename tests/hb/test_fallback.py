"""The time-domain operations the harmonic-balance and wear drivers may fall back on
(fretwear.hb.fallback): a frozen record of two callables whose calls its docstring documents.

References: the calls written in the record's docstring (the contract the drivers code
against) bound, with :func:`inspect.signature`, to the operations fretwear's time-domain
solver provides; and the dataclass rules of a frozen record.
"""

from __future__ import annotations

import dataclasses
import inspect
import re

import pytest

from fretwear.hb.fallback import TimeDomainFallback


def documented_call(name: str) -> tuple[list[str], list[str]]:
    """The positional and keyword-only argument names of ``name(...)`` as the docstring of
    TimeDomainFallback writes it (``solution | None`` is the argument ``solution``)."""
    doc = " ".join(TimeDomainFallback.__doc__.split())
    args = re.search(rf"``{name}\(([^)]*)\)", doc).group(1)
    positional, _, keywords = (part.strip() for part in args.partition("*"))
    names = lambda s: [a.split("|")[0].strip() for a in s.split(",") if a.strip()]  # noqa: E731
    return names(positional), names(keywords)


def test_the_record_holds_two_operations_and_cannot_change():
    """A driver reads exactly ``start`` and ``averaged_rate``; a record passed to a sweep or a
    wear run cannot be changed under it (frozen), and two records of the same operations are
    equal."""
    assert [f.name for f in dataclasses.fields(TimeDomainFallback)] == ["start", "averaged_rate"]
    rec = TimeDomainFallback(start=print, averaged_rate=len)
    with pytest.raises(dataclasses.FrozenInstanceError):
        rec.start = len
    assert rec == TimeDomainFallback(print, len) and hash(rec) == hash(TimeDomainFallback(print,
                                                                                        len))


@pytest.mark.parametrize("name", ["start", "averaged_rate"])
def test_the_documented_calls_bind_to_the_operations_fretwear_provides(name):
    """Each call as documented (positional arguments, then keyword-only ones) binds to the
    signature of the time-domain operation passed by the analysis layer; passing a
    documented keyword-only argument by position does not (the drivers must name it)."""
    from fretwear.timedomain.fallback import FALLBACK

    positional, keywords = documented_call(name)
    assert positional[:2] == ["model", "frequency"] and keywords
    sig = inspect.signature(getattr(FALLBACK, name))
    sig.bind(*positional, **dict.fromkeys(keywords))
    with pytest.raises(TypeError):
        sig.bind(*positional, *keywords)
