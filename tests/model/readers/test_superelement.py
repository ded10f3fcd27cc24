"""Craig-Bampton superelements of the 2D block on a rigid flat (boundary = the contact nodes)
against the full model: every interior mode kept is the model in other coordinates (modes,
periodic solution and wear step to 1e-10); truncated, the modes are Rayleigh-Ritz upper bounds
that converge as modes are added. A superelement written as DMIG with its modal coordinates on
scalar points (as Nastran's EXTSEOUT punches it) reads back as a model."""

import numpy as np
import pytest
from helpers import fe_files as ff
from helpers.blocks import block

from fretwear import simulate_wear, solve_periodic
from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.linear import modes
from fretwear.model.core import Load
from fretwear.model.readers import FEMatrices, craig_bampton, from_fe, read_fe
from fretwear.wear import WearOptions

BASIS = FourierBasis.up_to(3, 32)
F_HZ = 2000.0


@pytest.fixture(scope="module")
def full():
    model = block(2, 0.01)
    model.contact.wear_coefficient = 1e-12
    return model


def _superelement_model(model, n_modes):
    fe = FEMatrices(model.K, model.M, ff.dofmap_of(model), D=model.D)
    contact = ff.contacts_of(model)
    se = craig_bampton(fe, np.concatenate([c.nodes for c in contact]), n_modes=n_modes,
                       fixed=model.fixed_dofs)
    loads = [Load(se.reduce(ld.vector), ld.waveform, ld.coefficients, ld.name)
             for ld in model.loads]
    return se, from_fe(se.fe, contact=contact, nodes=ff.node_table(model), loads=loads)


def test_all_modes_kept_is_exact(full):
    """Stuck-interface frequencies, contact harmonics and the worn depths of one wear step
    equal the full model's to 1e-10 relative (the transformation is square)."""
    se, cb = _superelement_model(full, None)
    assert cb.ndof == full.ndof and se.fe.dofs.component[-1] == 0
    f0 = modes(full, 6, interface="stuck").frequency_hz
    f1 = modes(cb, 6, interface="stuck").frequency_hz
    np.testing.assert_allclose(f1, f0, rtol=1e-10)
    s0, s1 = (solve_periodic(m, BASIS, F_HZ, eps=1e12) for m in (full, cb))
    for what in ("U", "lam"):
        a, b = getattr(s1, what), getattr(s0, what)
        assert abs(a - b).max() <= 1e-10 * abs(b).max(), what
    opts = WearOptions(max_steps=1)
    w0, w1 = (simulate_wear(m, BASIS, F_HZ, options=opts).final_wear for m in (full, cb))
    assert w0.max() > 0 and abs(w1 - w0).max() <= 1e-10 * w0.max()


def test_truncated_modes_converge_from_above(full):
    """With 4, 8, 16 of the 28 interior modes the sliding-interface frequencies (the stuck ones
    are the fixed-interface modes, exact by construction) are upper bounds
    of the full model's (Rayleigh-Ritz, to rounding) whose largest error falls as modes are
    added (measured 2.2e-2, 2.9e-3, 2.7e-5 on the first three); with 16 the periodic contact
    forces at 2 kHz are within 1e-5 of the largest (measured 1.3e-6; 3.9e-5 with 2 modes,
    3e-8 with 20)."""
    f0 = modes(full, 3, interface="sliding").frequency_hz
    errors = []
    for nm in (4, 8, 16):
        _, cb = _superelement_model(full, nm)
        f = modes(cb, 3, interface="sliding").frequency_hz
        assert np.all(f >= f0 * (1 - 1e-12))
        errors.append(float(np.max(f / f0 - 1)))
    assert errors[0] > errors[1] > errors[2] and errors[2] < 1e-4
    s0, s1 = (solve_periodic(m, BASIS, F_HZ, eps=1e12) for m in (full, cb))
    assert abs(s1.lam - s0.lam).max() <= 1e-5 * abs(s0.lam).max()


def test_superelement_through_dmig(full, tmp_path):
    """The all-modes superelement written as DMIG (boundary grids + modal scalar points, 10
    digits) reads back with its DOF map and gives the stuck frequencies to 1e-8 (the rounding
    of 10-digit numbers, amplified)."""
    se, cb = _superelement_model(full, None)
    ff.write_dmig(tmp_path / "se.pch", {"KAAX": se.fe.K, "MAAX": se.fe.M}, se.fe.dofs)
    back = read_fe(tmp_path / "se.pch")
    order = np.lexsort((se.fe.dofs.component, se.fe.dofs.node))
    np.testing.assert_array_equal(back.dofs.node, se.fe.dofs.node[order])
    model = from_fe(back, contact=ff.contacts_of(full))
    np.testing.assert_allclose(modes(model, 4, interface="stuck").frequency_hz,
                               modes(cb, 4, interface="stuck").frequency_hz, rtol=1e-8)


def test_bad_superelement_input(full):
    fe = FEMatrices(full.K, full.M, ff.dofmap_of(full))
    with pytest.raises(InputError, match="boundary: node 999"):
        craig_bampton(fe, [999])
    with pytest.raises(InputError, match="n_modes = 99"):
        craig_bampton(fe, [1, 2], n_modes=99)
