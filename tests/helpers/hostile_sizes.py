"""Sizes that cannot fit, one call per family of arrays that grow with an input (the size
audit of docs/studies/hostile-inputs.md): each must be refused by its own check, in one line
with the estimate and the machine's memory (fretwear.resources.require_memory), before the
arrays are allocated.

Shared by tests/test_size_audit.py and the survey (studies/hostile_inputs.py). How: the
inputs are built on this machine, then (for the calls marked ``tiny``) the machine is said to
hold :data:`TINY` bytes (``fretwear.resources.machine_memory`` replaced; ``require_memory``
reads it at each call) and the call, small, must be refused: without its check it would run
and return. The calls not marked ``tiny`` cannot fit on any machine as they are. ``bound`` is
the family's largest array written out by hand from the sizes of the model (an independent
lower bound of the estimate, which adds temporaries).
"""

from __future__ import annotations

import contextlib
import re
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from fretwear import resources
from fretwear.errors import InputError

TINY = 1024  # bytes: the machine the ``tiny`` calls are said to run on


@dataclass
class SizeCall:
    family: str
    call: Callable
    words: tuple  # what the message must name
    bound: float = 0.0  # bytes: the estimate is at least this
    tiny: bool = True


@contextlib.contextmanager
def machine_of(nbytes: int):
    """``resources.machine_memory`` says ``nbytes`` in the body."""
    old = resources.machine_memory
    resources.machine_memory = lambda: nbytes
    try:
        yield
    finally:
        resources.machine_memory = old


def verdict(c: SizeCall) -> str:
    """"refused" (one line naming the estimate, the machine's memory and ``c.words``, the
    estimate at least ``c.bound``), else what happened instead."""
    try:
        with machine_of(TINY) if c.tiny else contextlib.nullcontext():
            c.call()
    except InputError as exc:
        msg = str(exc)
        if "\n" in msg or "needs about" not in msg or "this machine has" not in msg:
            return f"another message: {msg}"
        missing = [w for w in c.words if w not in msg]
        if missing:
            return f"another check: {msg}"
        # three significant digits in the message: the largest value that rounds to it
        est = float(re.search(r"needs about ([0-9.e+-]+) GiB", msg).group(1)) * 2**30 * 1.005
        if est < c.bound:
            return f"estimate {est:.3g} B below the array itself ({c.bound:.3g} B): {msg}"
        return "refused"
    except Exception as exc:  # noqa: BLE001 - any other outcome is the finding
        return f"deep error: {type(exc).__name__}: {exc}"[:300]
    return "accepted"


def size_calls() -> list[SizeCall]:
    """One call (or a few) per family, on small models of tests/helpers."""
    from fretwear.hb.cyclic import cyclic_condenser, cyclic_frf, cyclic_modes
    from fretwear.hb.dynamics import structure_dynamics
    from fretwear.hb.fourier import FourierBasis
    from fretwear.hb.modal import BlockedModalCondenser, ModalCondenser
    from fretwear.hb.nonlinear_modes import nonlinear_mode
    from fretwear.hb.problem import DLFTProblem
    from fretwear.hb.reduce import condense, exact_condenser
    from fretwear.hb.stability import HillProblem
    from fretwear.linear import modes
    from fretwear.model import ContactSpec, Material, box, from_mesh
    from fretwear.model.cyclic import disk_harmonics, disk_mesh, whole_disk
    from fretwear.model.mistuning import mistuned_disk, mistuning, random_mistuning
    from fretwear.wear.worn_state import WornStateOptions, worn_state
    from helpers.cyclic import sector_model
    from helpers.models import truss
    from helpers.wear_block import block

    model = truss()
    m = int(model.contact.dofs.size)
    ni = model.ndof - m - len(model.fixed_dofs)
    modal = ModalCondenser(model, 200.0, 3, modes=4, tol=1e3)
    basis = FourierBasis.up_to(3, 16)
    dyn = structure_dynamics(model)
    prob = DLFTProblem(condense(model, 100.0, basis.orders), model.contact, basis, eps=1e7)
    sector = sector_model(8)[0]
    cyc = cyclic_condenser(sector, 1)
    ndof = sector.model.ndof
    U = np.zeros((2, ndof), dtype=complex)
    solid = from_mesh(box(0.01, 0.01, 0.002, 10, 10, 2), Material(210e9, 0.3, 7800.0),
                      supports=[("zmin", "all")], contact=ContactSpec("zmax", mu=0.3,
                                                                      gap=1.0))  # 726 free DOFs
    w = 2 * np.pi * 100.0
    return [
        SizeCall("exact condensation", lambda: exact_condenser(model).reduced(
            w, np.arange(1000)), ("1000 harmonic orders",), 16.0 * 1000 * m * m),
        SizeCall("modal condenser (Psi)", lambda: ModalCondenser(
            model, 200.0, 3, modes=4, tol=1e3), ("a modal condensation of",), 8.0 * ni * m),
        SizeCall("blocked modal condenser", lambda: BlockedModalCondenser(
            model, 200.0, 3, modes=4, tol=1e3), ("a blocked modal condensation",),
                 8.0 * 2 * m * m),
        SizeCall("modal reduced model", lambda: modal.reduced(w, np.arange(1000)),
                 ("a modal condensation on 1000 harmonic orders",), 16.0 * 1000 * m * m),
        SizeCall("cyclic condenser", lambda: cyc.reduced(w, np.arange(3)),
                 ("3 harmonic orders",)),
        SizeCall("sector FRF", lambda: cyclic_frf(sector, 1, np.linspace(10.0, 100.0, 50)),
                 ("a sector FRF of 50 frequencies",), 16.0 * 50 * ndof),
        SizeCall("sector modes", lambda: cyclic_modes(sector, 1, 4),
                 ("4 modes of harmonic index 1",)),
        SizeCall("whole disk", lambda: whole_disk(sector, 1), ("the whole disk of 8 sectors",)),
        SizeCall("mistuned disk", lambda: mistuned_disk(sector, 1, mistuning(8)),
                 ("the whole disk of 8 sectors",)),
        SizeCall("disk mesh", lambda: disk_mesh(sector), ("the mesh of 8 sectors",)),
        SizeCall("disk harmonics", lambda: disk_harmonics(sector, 1, [0, 1], U),
                 ("the harmonics of 8 sectors",), 8.0 * U.nbytes),
        SizeCall("mistuning factors", lambda: mistuning(100),
                 ("the mistuning factors of 100 sectors",), 3 * 8.0 * 100),
        SizeCall("random mistuning", lambda: random_mistuning(10**10, 0.01, 1),
                 ("10,000,000,000 sectors",), 3 * 8.0 * 10**10, tiny=False),
        SizeCall("structure's dense matrices", lambda: structure_dynamics(model),
                 ("the dense structure matrices",), 8.0 * (dyn.m + dyn.q) ** 2),
        SizeCall("Hill's matrices", lambda: HillProblem(prob, np.zeros((prob.m, prob.H)), dyn),
                 ("Hill's method on",), 16.0 * (prob.m * prob.H) ** 2),
        SizeCall("nonlinear mode (EPMC)", lambda: nonlinear_mode(
            model, basis, [1e-6, 2e-6], dyn=dyn), ("a nonlinear mode of", "at 2 amplitudes"),
                 8.0 * ((dyn.m + 1) * basis.size) ** 2),
        SizeCall("linear modes (Lanczos)", lambda: modes(solid, 4), ("4 modes of",),
                 8.0 * 4 * solid.ndof),
        SizeCall("linear modes (dense)", lambda: modes(solid, 10**6),
                 ("the dense eigenproblem of",), 8.0 * 2 * 726**2),
        SizeCall("worn-state history", lambda: worn_state(
            block(), FourierBasis.up_to(1, 16), quasi_static=True,
            options=WornStateOptions(max_steps=2**62)),
                 ("max_steps = 4,611,686,018,427,387,904",), 2.0**62 * 8 * 2 * 11 * 2 * 3,
                 tiny=False),
    ]
