"""The size audit: every array that grows with an input is refused before it is allocated,
in one line with the estimate and the machine's memory (fretwear.resources.require_memory),
one test per family: the modal, blocked and cyclic condensers, the structure's dense
matrices (Hill's method, nonlinear modes), Hill's eigenproblem, the EPMC arrays, the linear
FRF and modes of a sector, the whole disk and its mesh and harmonics, mistuning factors, and
the history of a worn-state march.

How: the inputs are built on this machine, then the machine is said to hold 1 KiB
(``machine_memory`` patched; ``require_memory`` reads it at each call), and the call must be
refused by the family's own check, named in its message. Each call here is small: without
its check it would run and return (the test fails), so the check is what refuses it, before
anything is computed. Where the message's estimate is compared with a figure, the figure is
the family's largest array written out by hand from the sizes of the model (an independent
lower bound: the estimate adds temporaries and must not fall below the array itself).
"""

from __future__ import annotations

import re

import numpy as np
import pytest
from helpers.cyclic import sector_model
from helpers.models import truss
from helpers.wear_block import block

from fretwear import resources
from fretwear.errors import InputError
from fretwear.hb.cyclic import cyclic_condenser, cyclic_frf, cyclic_modes
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.modal import BlockedModalCondenser, ModalCondenser
from fretwear.hb.nonlinear_modes import nonlinear_mode
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.hb.stability import HillProblem
from fretwear.model.cyclic import disk_harmonics, disk_mesh, whole_disk
from fretwear.model.mistuning import mistuning, random_mistuning
from fretwear.wear.worn_state import WornStateOptions, worn_state

TINY = 1024  # bytes: the machine the refused calls are said to run on


def tiny(monkeypatch):
    monkeypatch.setattr(resources, "machine_memory", lambda: TINY)


def refused(call, *words) -> float:
    """The estimate [bytes] of the one-line refusal of ``call()``, after checking that the
    message names the machine's memory and each of ``words``; the message gives it to three
    significant digits, so the figure returned is the largest value that rounds to it."""
    with pytest.raises(InputError) as err:
        call()
    msg = str(err.value)
    assert "\n" not in msg and "needs about" in msg and "this machine has" in msg, msg
    for w in words:
        assert w in msg, (w, msg)
    return float(re.search(r"needs about ([0-9.e+-]+) GiB", msg).group(1)) * 2**30 * 1.005


@pytest.fixture(scope="module")
def sector():
    return sector_model(8)[0]


def test_modal_condensers_refuse_what_cannot_fit(monkeypatch):
    """The dense modal condenser (``Psi``, n_i x m, and the projected m x m blocks), the
    blocked one (its projected m x m blocks of K and M) and a reduced model on 1000 harmonic
    orders (one complex m x m block per order) are refused; the reduced model's estimate is at
    least its ``Z_r`` blocks, 16 nb m^2 bytes."""
    model = truss()
    m = int(model.contact.dofs.size)
    ni = model.ndof - m - len(model.fixed_dofs)
    built = ModalCondenser(model, 200.0, 3, modes=4, tol=1e3)  # before the machine shrinks
    tiny(monkeypatch)
    est = refused(lambda: ModalCondenser(model, 200.0, 3, modes=4, tol=1e3),
                  "a modal condensation of", "interior", "contact DOFs")
    assert est >= 8.0 * ni * m
    est = refused(lambda: BlockedModalCondenser(model, 200.0, 3, modes=4, tol=1e3),
                  "a blocked modal condensation")
    assert est >= 8.0 * 2 * m * m
    est = refused(lambda: built.reduced(2 * np.pi * 100.0, np.arange(1000)),
                  "a modal condensation on 1000 harmonic orders (up to 999)")
    assert est >= 16.0 * 1000 * m * m


def test_cyclic_family_refuses_what_cannot_fit(monkeypatch, sector):
    """On the annulus sector: the cyclic condenser's reduced model, the sector's FRF (one
    complex row of its DOFs per frequency: 16 nf ndof bytes at least) and modes, the whole
    disk and its mesh and harmonics (N copies), and the mistuning factors of 10^10 sectors."""
    cond = cyclic_condenser(sector, 1)
    ndof = sector.model.ndof
    U = np.zeros((2, ndof), dtype=complex)
    tiny(monkeypatch)
    refused(lambda: cond.reduced(2 * np.pi * 100.0, np.arange(3)), "3 harmonic orders")
    est = refused(lambda: cyclic_frf(sector, 1, np.linspace(10.0, 100.0, 50)),
                  "a sector FRF of 50 frequencies")
    assert est >= 16.0 * 50 * ndof
    refused(lambda: cyclic_modes(sector, 1, 4), "4 modes of harmonic index 1")
    refused(lambda: whole_disk(sector, 1), "the whole disk of 8 sectors")
    refused(lambda: disk_mesh(sector), "the mesh of 8 sectors")
    est = refused(lambda: disk_harmonics(sector, 1, [0, 1], U), "the harmonics of 8 sectors")
    assert est >= 8 * U.nbytes
    refused(lambda: mistuning(100), "the mistuning factors of 100 sectors")
    monkeypatch.undo()  # this one does not fit on any machine: 3 x 10^10 doubles at least
    refused(lambda: random_mistuning(10**10, 0.01, 1), "10,000,000,000 sectors")


def test_dense_structure_hill_and_nonlinear_modes_refuse_what_cannot_fit(monkeypatch):
    """The dense structure matrices of Hill's method and nonlinear modes (at least K on
    every free DOF, 8 n^2 bytes), Hill's matrices (``T(s)``, complex, (m H)^2) and the EPMC's
    Jacobian (its unknowns squared), each refused by its own check (the structure passed
    in, built before the machine shrinks)."""
    model = truss()
    basis = FourierBasis.up_to(3, 16)
    dyn = structure_dynamics(model)
    red = condense(model, 100.0, basis.orders)
    prob = DLFTProblem(red, model.contact, basis, eps=1e7)
    n_free = dyn.m + dyn.q
    tiny(monkeypatch)
    est = refused(lambda: structure_dynamics(model), "the dense structure matrices")
    assert est >= 8.0 * n_free**2
    est = refused(lambda: HillProblem(prob, np.zeros((prob.m, prob.H)), dyn),
                  "Hill's method on")
    assert est >= 16.0 * (prob.m * prob.H) ** 2
    est = refused(lambda: nonlinear_mode(model, basis, [1e-6, 2e-6], dyn=dyn),
                  "a nonlinear mode of", "at 2 amplitudes")
    assert est >= 8.0 * ((dyn.m + 1) * basis.size) ** 2


def test_worn_state_history_that_cannot_fit_is_refused():
    """max_steps = 2^62: the history of the march (a record of the contact's Fourier
    coefficients per step) cannot fit on any machine; refused before the first solve, on
    the machine as it is."""
    est = refused(lambda: worn_state(block(), FourierBasis.up_to(1, 16), quasi_static=True,
                                     options=WornStateOptions(max_steps=2**62)),
                  "max_steps = 4,611,686,018,427,387,904")
    assert est >= 2.0**62 * 8 * 2 * 11 * 2 * 3  # nc = 11 nodes, d = 2, H = 3: U and lam
