"""The Python builders of the paper's models (fretwear.examples.builders) against the shipped
case files they claim to equal, and against the paper's dimensions.

References: the case files ``beam-linear-frf.toml`` and ``stromberg1997.toml`` read and built
by the case-file path (``fretwear run``'s own), and the beams' mass, load resultants and
contact area computed by hand from the dimensions the docstrings quote.
"""

from __future__ import annotations

import numpy as np
import pytest

from fretwear.analyses.run import load_case
from fretwear.examples import example_path
from fretwear.examples.builders import paper_beam, stromberg_beam
from fretwear.io.case import build_model


def assert_same_model(a, b):
    """Equal matrices, loads, contact arrays and observed points (exact: both are built by
    the same assembly from the same numbers)."""
    for name in ("K", "M", "C", "D"):
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert (x != y).nnz == 0, name
    assert [(ld.name, ld.waveform) for ld in a.loads] == [(ld.name, ld.waveform) for ld in b.loads]
    for la, lb in zip(a.loads, b.loads, strict=True):
        np.testing.assert_array_equal(la.vector, lb.vector)
    for field in ("dofs", "frame", "gap", "area", "coords"):
        np.testing.assert_array_equal(getattr(a.contact, field), getattr(b.contact, field))
    for field in ("mu_nodes", "wear_nodes"):
        np.testing.assert_array_equal(getattr(a.contact, field)(), getattr(b.contact, field)())
    np.testing.assert_array_equal(a.fixed_dofs, b.fixed_dofs)
    assert [(p.name, p.dofs.tolist()) for p in a.observed] == \
        [(p.name, p.dofs.tolist()) for p in b.observed]


@pytest.mark.parametrize("build, example", [(paper_beam, "beam-linear-frf"),
                                            (stromberg_beam, "stromberg1997")])
def test_each_builder_is_its_shipped_case_file(build, example):
    assert_same_model(build(), build_model(load_case(example_path(example))))


@pytest.mark.parametrize("build, L, h, w, P, Q, mu", [
    (paper_beam, 0.1, 0.01, 0.01, 1e4, 1e4, 0.3),
    (stromberg_beam, 0.05, 0.005, 0.005, 50e6, 20e6, 0.2)])
def test_the_beams_have_the_papers_dimensions_and_loads(build, L, h, w, P, Q, mu):
    """Mass rho L h w, the static load P L w pressing down and the end load Q h w along x,
    the contact area L w on the bottom face with mu, and the observed point at (L, h/2).
    1e-12: sums of a few hundred consistent nodal values (exact for uniform loads)."""
    model = build()
    ux = np.ones(model.ndof)
    ux[1::2] = 0.0  # a rigid translation along x: u^T M u is the total mass
    assert ux @ (model.M @ ux) == pytest.approx(7800.0 * L * h * w, rel=1e-12)
    static = model.load_harmonics(1)[0].real.reshape(-1, 2).sum(axis=0)
    np.testing.assert_allclose(static, [0.0, -P * L * w], atol=1e-12 * P * L * w)
    end = next(ld for ld in model.loads if ld.name == "Q").vector.reshape(-1, 2).sum(axis=0)
    np.testing.assert_allclose(end, [-Q * h * w, 0.0], atol=1e-12 * Q * h * w)
    assert model.contact.area.sum() == pytest.approx(L * w, rel=1e-12)
    np.testing.assert_array_equal(model.contact.mu_nodes(), mu)
    assert np.all(model.contact.coords[:, 1] == 0.0)
    pe = model.observed_point("Pe")
    np.testing.assert_allclose(pe.coords, [L, h / 2], rtol=1e-14)
