"""The documented ranges of input values (fretwear.limits): what is accepted, what is refused
with one message, and whether the ranges keep the matrices inside double precision as the
module says.

References: the ranges as the module documents them (RANGES, LOSS_FACTOR_MAX), and the
magnitudes of finite-element entries (stiffness ~ E L, mass ~ rho L^3) worked out here from
the range ends.
"""

import math
import re

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.limits import LOSS_FACTOR_MAX, RANGES, ZERO_ALLOWED, check_loss_factor, check_range


@pytest.mark.parametrize("f", [5e-324, 1e-9, 2e10])
def test_frequency_outside_the_documented_range_is_refused(f):
    """Reference: fretwear.limits.RANGES["frequency"] = 0, or [1e-6, 1e10] Hz (5e-324 Hz made
    the period infinite and the solve fail deep inside LAPACK)."""
    from fretwear.limits import check_range

    with pytest.raises(InputError, match=r"frequency = .* Hz: expected 0 or a magnitude in "
                                         r"\[1e-06, 1e\+10\] Hz"):
        check_range(f, "frequency", "frequency")
    assert check_range(0.0, "frequency", "frequency") == 0.0


@pytest.mark.parametrize("kind", sorted(RANGES))
def test_the_ends_of_each_range_are_in_and_a_hair_beyond_is_out(kind):
    """Both ends belong to the range, in either sign (a magnitude); one part in 1e9 beyond
    either end is refused, and so are NaN, infinities and non-numbers. 0 is accepted exactly
    for the kinds documented as ZERO_ALLOWED (massless, static). Exact comparisons: the
    checks compare floats with the stated ends."""
    lo, hi, unit, _ = RANGES[kind]
    for v in (lo, hi, -lo, -hi, math.sqrt(lo * hi)):
        assert check_range(v, kind, "v") == v
    for v in (lo * (1 - 1e-9), hi * (1 + 1e-9), -hi * (1 + 1e-9), math.nan, math.inf):
        with pytest.raises(InputError, match=rf"v = .* {re.escape(unit)}: expected"):
            check_range(v, kind, "v")
    with pytest.raises(InputError, match=r"v = 'abc' is not a number"):
        check_range("abc", kind, "v")
    if kind in ZERO_ALLOWED:
        assert check_range(0, kind, "v") == 0.0
    else:
        with pytest.raises(InputError, match="expected a magnitude"):
            check_range(0.0, kind, "v")


def test_the_ranges_keep_finite_element_entries_between_1e_minus_60_and_1e60():
    """The module's claim, recomputed from the range ends: an element of size L of a
    material of modulus E and density rho has stiffness entries ~ E L [N/m] and mass
    entries ~ rho L^3 [kg] (3D; a 2D element of thickness L the same), so the dynamic
    stiffness holds E L and (2 pi f)^2 rho L^3. Every combination of range ends (zero
    excluded) must stay within [1e-60, 1e60]; the factor 1e60 is the module's, far inside
    double precision (1e-308..1e308), so no margin is needed in the comparison."""
    L = np.array(RANGES["length"][:2])
    E = np.array(RANGES["modulus"][:2])
    rho = np.array(RANGES["density"][:2])
    f = np.array(RANGES["frequency"][:2])
    stiff = np.outer(E, L).ravel()
    inertia = np.multiply.outer(np.multiply.outer((2 * np.pi * f) ** 2, rho), L**3).ravel()
    for entries in (stiff, inertia):
        assert np.all(entries >= 1e-60) and np.all(entries <= 1e60), entries


def test_loss_factor_from_zero_to_its_documented_maximum():
    """[0, LOSS_FACTOR_MAX] accepted with both ends, anything else refused in one message
    naming the argument (NaN included: it fails every comparison)."""
    assert check_loss_factor(0) == 0.0
    assert check_loss_factor(LOSS_FACTOR_MAX) == LOSS_FACTOR_MAX
    assert check_loss_factor("1e-3") == 1e-3
    for bad in (-1e-300, LOSS_FACTOR_MAX * (1 + 1e-12), math.nan, math.inf):
        with pytest.raises(InputError, match=r"eta = .*expected a value in \[0, 10\]"):
            check_loss_factor(bad, "eta")
    with pytest.raises(InputError, match=r"eta = None is not a number"):
        check_loss_factor(None, "eta")
