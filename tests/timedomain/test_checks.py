"""The argument checks of the time-domain solvers (fretwear.timedomain.checks): what is
accepted, and one InputError naming the argument and what is expected for the rest.

References: the rules as the solvers document them (a rigid unilateral contact on distinct,
free DOFs with mu >= 0; positive finite numbers; integer counts; one finite wear depth per
contact node), each probed just inside and just outside.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.models import chain

from fretwear.errors import InputError
from fretwear.timedomain.checks import c_float, check_contact, count, node_wear, positive


def test_positive_numbers():
    """Real numbers in (0, 1e20]; strings are refused as the API refuses them (no silent
    conversion of "2.5"), as are bools."""
    assert positive(5e-324, "h") == 5e-324 and positive(np.float32(2.5), "h") == 2.5
    for bad in (0.0, -1.0, math.nan, math.inf, 1e21):
        with pytest.raises(InputError, match=r"^h = .*; expected a positive finite number "
                                             r"\(at most 1e\+20\)$"):
            positive(bad, "h")
    for bad in ("x", "2.5", True):
        with pytest.raises(InputError, match=r"^h = .*; expected a positive number$"):
            positive(bad, "h")


def test_counts_are_integers_from_their_minimum():
    """numpy integers count; booleans and floats (even 3.0) do not: a count is a number of
    things."""
    assert count(np.int64(3), "n") == 3 and type(count(np.int32(3), "n")) is int
    assert count(0, "n", minimum=0) == 0
    for bad in (True, 3.0, "3", None):
        with pytest.raises(InputError, match=r"^n = .*; expected an integer >= 1$"):
            count(bad, "n")
    for bad in (0, 2**62 + 1):
        with pytest.raises(InputError, match=r"^n = \d+; expected an integer >= 1 \(and at "
                                             r"most 2\^62\)$"):
            count(bad, "n")


def test_c_float_is_a_contiguous_float_copy_of_any_layout():
    a = np.arange(12).reshape(3, 4).T  # a strided int view
    b = c_float(a)
    assert b.dtype == np.float64 and b.flags.c_contiguous
    np.testing.assert_array_equal(b, a)


def test_contacts_the_time_domain_solver_takes():
    """The chain's single rigid contact passes; each of the contacts the solver cannot take
    is refused with its reason: a DOF shared by two nodes, a fixed contact DOF, a negative
    friction coefficient, contact stiffness."""
    check_contact(chain())
    m = chain()
    m.contact.dofs = np.array([[0, 1], [1, 2]])
    m.contact.frame = np.tile(np.eye(2), (2, 1, 1))
    with pytest.raises(InputError, match="a DOF belongs to two contact nodes"):
        check_contact(m)
    m = chain()
    m.fixed_dofs = np.array([1])
    with pytest.raises(InputError, match="contact DOF 1 is also a fixed DOF"):
        check_contact(m)
    m = chain(mu=-0.1)
    with pytest.raises(InputError, match=r"contact.mu = -0.1; expected a friction coefficient"):
        check_contact(m)
    m = chain()
    m.contact.kt = np.array([1e6])
    with pytest.raises(InputError, match="contact stiffness .* harmonic balance only"):
        check_contact(m)
    m = chain()
    m.contact.dofs = np.array([[0, 1, 2, 3]])
    with pytest.raises(InputError, match=r"contact.dofs has shape \(1, 4\)"):
        check_contact(m)


def test_node_wear_is_one_finite_depth_per_node_and_a_copy():
    assert node_wear(None, 3).tolist() == [0.0, 0.0, 0.0]
    w = np.array([1e-6, 0.0, 2e-6])
    got = node_wear(w, 3)
    got[0] = 5.0
    assert w[0] == 1e-6  # the caller's array is not changed through the result
    for bad in (np.zeros(2), np.zeros((3, 1)), np.array([0.0, np.nan, 0.0])):
        with pytest.raises(InputError, match=r"wear has shape .*; expected \(3,\) finite"):
            node_wear(bad, 3)
