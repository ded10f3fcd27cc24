"""The public API (``fretwear.__all__``, loaded lazily): every name resolves, and has a
docstring; every public function that takes a frequency says it is in Hz."""

from __future__ import annotations

import inspect

import pytest

import fretwear

NAMES = [n for n in fretwear.__all__ if n != "__version__"]


@pytest.mark.parametrize("name", NAMES)
def test_public_name_resolves_and_is_documented(name):
    obj = getattr(fretwear, name)
    assert obj is not None
    doc = inspect.getdoc(obj)
    assert doc and len(doc.split()) >= 5, f"fretwear.{name} has no docstring"


@pytest.mark.parametrize("name", [n for n in NAMES if inspect.isfunction(getattr(fretwear, n))])
def test_frequencies_are_in_hz(name):
    func = getattr(fretwear, name)
    params = inspect.signature(func).parameters
    if {"frequency", "f_min", "frequencies_hz"} & set(params):
        assert "[Hz]" in inspect.getdoc(func), f"fretwear.{name}: frequency unit not stated"
    assert "omega" not in params, f"fretwear.{name} takes omega: public functions take Hz"


def test_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nothing_here'"):
        fretwear.nothing_here  # noqa: B018
