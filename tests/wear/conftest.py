"""The partial-slip block of tests/helpers/wear_block.py, condensed and solved once per test
module of tests/wear/."""

from __future__ import annotations

import pytest
from helpers.wear_block import BASIS, block

from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.preload import static_anchor
from fretwear.hb.reduce import condense


@pytest.fixture(scope="module")
def blk():
    m = block()
    red = condense(m, 1.0, BASIS.orders, quasi_static=True)
    return m, red, static_anchor(m)


@pytest.fixture(scope="module")
def sol_block(blk):
    m, red, anc = blk
    sol = solve_periodic(m, BASIS, quasi_static=True, reduced=red, anchor=anc,
                         options=SolveOptions(tol=1e-12))
    st = sol.stats
    assert st.success
    return sol
