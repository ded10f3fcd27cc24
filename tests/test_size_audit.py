"""The size audit: every array that grows with an input is refused before it is allocated,
in one line with the estimate and the machine's memory, one test per family of
tests/helpers/hostile_sizes.py (the exact, modal, blocked and cyclic condensers, the
sector's FRF and modes, the whole and the mistuned disk, its mesh and harmonics, mistuning
factors, the structure's dense matrices, Hill's matrices, the EPMC arrays, the linear modes
and the history of a worn-state march).

Each call is small and is made on a machine said to hold 1 KiB (or cannot fit on any
machine as it is): without its check it would run and return, and the test fails. The
message must name the family's own check (not an earlier one) and its estimate must be at
least the family's largest array written out by hand from the model's sizes (an independent
lower bound); the helper's docstring says how.
"""

from __future__ import annotations

import pytest
from helpers import hostile_sizes


@pytest.fixture(scope="module")
def calls():
    return {c.family: c for c in hostile_sizes.size_calls()}


FAMILIES = ("exact condensation", "modal condenser (Psi)", "blocked modal condenser",
            "modal reduced model", "cyclic condenser", "sector FRF", "sector modes",
            "whole disk", "mistuned disk", "disk mesh", "disk harmonics", "mistuning factors",
            "random mistuning", "structure's dense matrices", "Hill's matrices",
            "nonlinear mode (EPMC)", "linear modes (Lanczos)", "linear modes (dense)",
            "worn-state history")


def test_every_family_is_listed(calls):
    """The families tested are the helper's, all of them (a call added there is tested)."""
    assert set(calls) == set(FAMILIES)


@pytest.mark.parametrize("family", FAMILIES)
def test_a_size_that_cannot_fit_is_refused_by_its_own_check(calls, family):
    assert hostile_sizes.verdict(calls[family]) == "refused"
