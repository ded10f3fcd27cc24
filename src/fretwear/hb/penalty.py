"""The DLFT penalty ``eps`` [N/m] from its rule: one function for every solver and analysis.

The penalty of the DLFT contact law (paper eq. 23) is given by a rule, spelt the same in case
files and in Python:

* ``"auto"``: the spectral radius of ``Z_r`` over the kept harmonics at the frequency of the
  solve (largest ``|eigenvalue|`` of ``Z_r(n w)``, ``n = 0, h1, .., hk``): the paper's rule
  (section 3.2). In a sweep it is applied point by point.
* ``"static"``: the spectral radius of the static reduced stiffness ``K_r = Z_r(0)``, the same
  at every frequency.
* ``"top"``: the spectral radius of ``Z_r`` at the *highest kept harmonic* ``hk w``: the
  stiffness the contact sees at the truncation of the balance. Chosen from measurements
  (docs/theory.md, "The penalty eps"; docs/studies/eps-rule.md): on a rigid Coulomb contact
  behind a mass the answer at finite H improves as eps grows, and the top harmonic's inertia
  gives a large eps there; behind a contact spring (a Jenkins element) the contact sees at
  most that spring at high frequency, and eps near it is the most accurate value measured,
  where the per-frequency maximum over the harmonics (``"auto"``) picks the resonance and
  ``"static"`` a value far too small for a contact behind a mass. A sweep takes one ``"top"``
  eps for all its points: the median of the rule at :data:`SWEEP_SAMPLES` frequencies
  spread over its band (:func:`sweep_penalty`). On an interface whose law acts through one
  contact stiffness ``k`` on every row (a Jenkins element ``kt`` under a prescribed normal
  load; ``kn = kt`` on a unilateral contact), ``"top"`` is ``k`` itself, the limit of the
  spectral radius at high harmonics: with ``eps = k`` the DLFT balance is exactly the
  alternating frequency-time balance of the spring-slider law (:func:`spring_penalty`). The
  other rules give ``k`` there too: it removes the penalty's effect on the answer.
* ``"stiff"``: :data:`STIFF_FACTOR` (10) times ``"top"`` (not the default). On a rigid
  contact the DLFT balance at ``eps`` is that of a spring ``eps`` in series with a Coulomb
  slider on a structure whose compliance is ``Z_r^-1 - 1 / eps`` (the identity of
  :func:`spring_penalty` read backwards): harmonic by harmonic the structure the slider
  drives is off by the factor ``1 / (1 - Z_r / eps)``. ``"top"`` makes that factor 1/2 at
  the highest harmonic of a contact behind a mass (``Z_r ~ -(hk w)^2 m``, ``eps = |Z_r|``);
  ten times it, 1/1.1, and ``(n / hk)^2 / 10`` of the stiffness at a lower harmonic ``n``.
  Measured against the event-driven reference of the two-DOF chain on a rigid contact
  (docs/studies/eps-rule.md): the peak error falls from -7.9 % to -5.0 % at 7 harmonics (the
  truncation's own is -3.4 %) and from -4.0 % to -2.1 % at 15; pyHarm 1.2.2 with the eps its
  user gives has -5.15 % and -3.55 %. It costs robustness on the paper's beam at 76-82 kHz
  (the worn-FRF example: 8 of 17 points converged against 37 of 37 with ``"top"``), so the
  sweeps' default (``"contact"``) takes it only on rigid sliders under a prescribed load.
* ``"contact"`` (the sweeps' default): ``"stiff"`` where every row of the law is a rigid
  slider under a prescribed normal load (:func:`rigid_slider`), ``"top"`` elsewhere. Under
  a prescribed load the law's force is bounded by ``mu N`` whatever eps is, and the
  accuracy argument of ``"stiff"`` holds (problem (b) of benchmarks/peers.py: -5.0 % and
  -2.1 % peak error at 7 and 15 harmonics, pyHarm -5.15 % and -3.55 %); with a unilateral
  normal row (the paper's beam) eps also sets the normal force's stiffness, where ten times
  ``"top"`` loses points (above), so it keeps ``"top"``. Measurements: docs/studies/eps-rule.md;
  the argument: docs/theory.md, "The penalty eps".
* a positive number [N/m], used as given.

Rows of nodes with a prescribed normal load (no unilateral normal contact) are left out: their
normal equation is linear and does not involve eps. The spectral radius is exact (eigenvalues)
for blocks up to :data:`EXACT_SIZE` rows and estimated by power iteration on ``Z^H Z`` (the
largest singular value, equal to the spectral radius for the normal matrices of undamped or
proportionally damped structures, an upper bound otherwise) above: cheap at 3000 rows.
"""

from __future__ import annotations

import math
from numbers import Real

import numpy as np

from fretwear.errors import InputError
from fretwear.hb.connectors import connect, springs, stiffness
from fretwear.hb.reduce import Reduced, condense, condenser_for
from fretwear.model.core import Model

#: the rules :func:`penalty` accepts besides a positive number [N/m]
RULES = ("auto", "static", "top", "stiff", "contact")
#: blocks up to this size get exact eigenvalues; larger ones a power-iteration estimate
EXACT_SIZE = 256
#: weight of the cold (random) start added to a warm start (:func:`radius_max`)
WARM_MIX = 1.0
#: frequencies of a sweep's band at which ``"top"`` is evaluated (its median is the sweep's eps)
SWEEP_SAMPLES = 5
#: ``"stiff"`` is this many times ``"top"``: the penalty's compliance ``1 / eps`` at most this
#: fraction of the structure's at every kept harmonic where the stiffness grows with the
#: harmonic (a contact behind a mass); docs/theory.md, "The penalty eps"
STIFF_FACTOR = 10.0


def radius(Z: np.ndarray, rows=None) -> float:
    """Spectral radius [N/m] of one (m, m) block ``Z`` (restricted to ``rows`` if given):
    exact up to :data:`EXACT_SIZE` rows, else the largest singular value by power iteration
    on ``Z^H Z`` until it changes by less than 1e-3 (at most 20 iterations: ample for a
    penalty whose effect is measured over decades)."""
    return radius_max([Z], rows)


def radius_max(blocks, rows=None) -> float:
    """The largest :func:`radius` [N/m] of the (m, m) ``blocks`` (e.g. ``Z_r`` at every kept
    harmonic). Above :data:`EXACT_SIZE` rows each block's power iteration starts from the
    previous block's converged vector plus the cold start: the blocks ``Z_r(n w)`` of one
    solve share their stiffest modes (the mesh-scale ones, far above the kept harmonics), so
    after the first block each converges in about six iterations instead of 18 (1024 contact
    nodes, 7 harmonics)."""
    best, v = 0.0, None
    for Z in blocks:
        sigma, v = _radius(np.asarray(Z), rows, v)
        best = max(best, sigma)
    return best


def _radius(Z: np.ndarray, rows, v):
    """:func:`radius` of one block and the start vector for the next (None when exact)."""
    if rows is not None:
        Z = Z[np.ix_(rows, rows)]
    if Z.shape[0] == 0:
        return 0.0, None
    if Z.shape[0] <= EXACT_SIZE:
        return float(np.max(np.abs(np.linalg.eigvals(Z)))), None
    if np.iscomplexobj(Z) and not np.any(Z.imag):  # undamped: the same iteration in reals,
        Z = np.ascontiguousarray(Z.real)  # half the memory traffic of the complex products
    start = np.random.default_rng(0).standard_normal(Z.shape[0])
    if v is not None and v.shape[0] == Z.shape[0]:
        # the previous block's vector plus the cold start, of equal norms: faster than the
        # cold start where the blocks share their top mode; where they do not, the previous
        # vector alone could be orthogonal to this block's top mode, or dominate a new top
        # mode close above it, and the iteration would stop on the previous one (a tenth
        # of the cold start missed a new top mode up to 1.6 times the previous one on
        # 300 rows; tests/hb/test_penalty.py)
        v = v.real if not np.iscomplexobj(Z) else v
        start = v / np.linalg.norm(v) + WARM_MIX * start / np.linalg.norm(start)
    v = start.astype(Z.dtype)
    sigma = 0.0
    # Z^H Z v without forming Z^H, a block of about 1 MiB of rows at a time so that each
    # block is read from memory once for both products (30 % faster at 3072 rows)
    step = max(1, 2**20 // (Z.shape[1] * Z.itemsize))
    for _ in range(20):
        w = np.zeros_like(v)
        for i in range(0, Z.shape[0], step):
            Zi = Z[i : i + step]
            w += (Zi @ v).conj() @ Zi
        w = w.conj()
        nrm = np.linalg.norm(w)
        if nrm == 0.0:
            return 0.0, None
        sigma_new = math.sqrt(nrm / np.linalg.norm(v))
        v = w / nrm
        if abs(sigma_new - sigma) <= 1e-3 * sigma_new:
            return float(sigma_new), v
        sigma = sigma_new
    return float(sigma), v


def _law_rows(contact, m: int):
    """Reduced rows whose law involves eps: all but the normal rows of nodes with a prescribed
    normal load (None: all rows)."""
    if contact is None or not contact.prescribed_nodes().any():
        return None
    keep = np.ones(m, dtype=bool)
    keep[np.flatnonzero(contact.prescribed_nodes()) * contact.dim] = False
    return np.flatnonzero(keep)


def spring_penalty(contact) -> float | None:
    """The contact stiffness ``k`` [N/m] shared by every row of the law (:func:`_law_rows`) of
    ``contact``, or None when a row is rigid or the rows' springs differ.

    Why ``eps = k`` is exact (hb/connectors.py's notation, harmonic by harmonic, one spring
    ``k`` on every law row): ``Z_x = k - k^2 (Z_r + k)^-1`` and ``F_x = k (Z_r + k)^-1 F_r``,
    so the DLFT predictor ``lambda_u = F_x - Z_x X + eps (X - W)`` (eq. 23) is, for
    ``eps = k``, ``k (U - W)`` with ``U = (Z_r + k)^-1 (F_r + k X)`` the structure's contact
    displacement. The correction (eq. 24-28) applied to ``k (u(t) - w(t))`` is the return
    mapping of a spring ``k`` in series with a Coulomb slider (stick: the force follows
    ``k du``; slip: it sits on the cone); ``lambda_N = max(k (u_N - g), 0)`` on a unilateral
    row. At convergence ``X`` is the slider's motion projected on the kept harmonics and
    ``Z_r U + lambda~ = F_r``: the harmonic balance of the structure with the law's force
    evaluated in the time domain from its truncated displacement, which is the alternating
    frequency-time method with the exact elastic-slider law, no penalty left
    (tests/hb/test_penalty.py compares with an independent implementation)."""
    if contact is None:
        return None
    k = stiffness(contact)
    rows = _law_rows(contact, k.size)
    k = k if rows is None else k[rows]
    if k.size == 0 or not np.all(np.isfinite(k)):
        return None
    if np.max(k) - np.min(k) > 1e-12 * np.max(k):
        return None
    return float(k[0])


def rigid_slider(contact) -> bool:
    """True when every row of the law of ``contact`` (:func:`_law_rows`) is a rigid slider
    under a prescribed normal load: every node has a prescribed normal load (no unilateral
    normal row) and no tangential contact spring (``kt`` None or infinite)."""
    if contact is None or contact.n_nodes == 0 or not contact.prescribed_nodes().all():
        return False
    return bool(np.all(np.isinf(stiffness(contact).reshape(contact.n_nodes, -1)[:, 1:])))


def _factor(rule: str, contact=None) -> float:
    """The multiple of the top harmonic's spectral radius that ``rule`` (``"top"``,
    ``"stiff"`` or ``"contact"``) takes on ``contact``."""
    if rule == "contact":
        return STIFF_FACTOR if rigid_slider(contact) else 1.0
    return STIFF_FACTOR if rule == "stiff" else 1.0


def check_rule(rule) -> str | float:
    """``rule`` if it is one of :data:`RULES` or a positive finite number (as a float);
    otherwise an :class:`~fretwear.errors.InputError` (a ``ValueError``) naming ``eps``."""
    if isinstance(rule, str) and rule in RULES:
        return rule
    if isinstance(rule, Real) and not isinstance(rule, bool):
        value = float(rule)
        if value > 0 and math.isfinite(value):
            return value
    raise InputError(f"eps = {rule!r}: expected \"contact\" (\"stiff\" on rigid sliders under "
                     "a prescribed normal load, \"top\" elsewhere), "
                     f"\"stiff\" ({STIFF_FACTOR:g} x \"top\"), \"top\" "
                     "(spectral radius of Z_r at the highest kept harmonic), \"auto\" (over the "
                     "kept harmonics), \"static\" (of the static K_r) or a positive number "
                     "[N/m]")


def penalty(rule, *, model: Model | None = None, frequency: float = 0.0, orders=None,
            quasi_static: bool = False, reduced: Reduced | None = None,
            contact=None, condenser=None) -> float:
    """The DLFT penalty [N/m] of ``rule`` (module docstring) at the excitation ``frequency``.

    Parameters
    ----------
    rule : ``"auto"``, ``"top"``, ``"stiff"``, ``"contact"``, ``"static"`` or a positive
        number [N/m].
    model : the structure (needed unless ``reduced`` is given).
    frequency, orders, quasi_static : the frequency [Hz], harmonic orders ``[0, h1, .., hk]``
        and inertia setting of the solve (``"auto"``, ``"top"``, ``"stiff"`` and
        ``"contact"``, when ``reduced`` is not given).
    reduced : the condensation of the solve (:func:`fretwear.hb.reduce.condense`) if already
        computed: ``"auto"``, ``"top"``, ``"stiff"`` and ``"contact"`` then take its blocks
        (all but ``"auto"`` the last one); ``"static"`` without a
        ``model`` takes its order-0 block, which is ``K_r`` at every frequency.
    contact : the interface (default ``model.contact``): rows of prescribed normal loads are
        left out.
    condenser : the condenser of ``model`` (:func:`fretwear.hb.reduce.exact_condenser`) when
        the rule condenses it (None: a new exact one).

    Returns
    -------
    eps [N/m], positive.
    """
    rule = check_rule(rule)
    if not isinstance(rule, str):
        return rule
    if contact is None and model is not None:
        contact = model.contact
    if (k := spring_penalty(contact)) is not None:  # every rule: exact on spring rows
        return k
    if rule in ("auto", "top", "stiff", "contact"):
        if reduced is None:
            if model is None or orders is None:
                raise ValueError(f'eps = "{rule}" needs the reduced model or the model and '
                                 "orders")
            orders = np.asarray(orders)
            if rule != "auto":
                orders = orders[-1:]
            reduced = connect(condense(model, frequency, orders, quasi_static=quasi_static,
                                       condenser=condenser), model.contact)
        rows = _law_rows(contact, reduced.m)
        if rule == "auto":
            return radius_max(reduced.Z, rows)
        return _factor(rule, contact) * radius_max(reduced.Z[-1:], rows)
    if model is not None:
        red = connect(condense(model, 0.0, [0], quasi_static=True, condenser=condenser),
                      model.contact)
        return radius(red.Z[0], _law_rows(contact, red.m))
    if reduced is None or int(reduced.orders[0]) != 0:
        raise ValueError('eps = "static" needs the model or a reduced model with order 0')
    return radius(reduced.Z[0], _law_rows(contact, reduced.m))


def sweep_penalty(rule, model: Model, orders, f_min: float, f_max: float, *,
                  spacing: str = "log", condenser=None) -> float | str:
    """The one eps [N/m] of a sweep over ``[f_min, f_max]`` [Hz]: a number as given;
    ``"static"`` as :func:`penalty`; ``"top"`` the median of :func:`penalty` at
    :data:`SWEEP_SAMPLES` frequencies spread over the band (``spacing`` as the sweep's grid),
    ``"stiff"`` :data:`STIFF_FACTOR` times that median, ``"contact"`` the one or the other
    (:func:`rigid_slider`); ``"auto"`` is returned as is (the paper's rule point by point,
    kept for comparison).
    ``condenser``: the sweep's condenser of ``model`` (None: a new exact one)."""
    rule = check_rule(rule)
    if not isinstance(rule, str):
        return rule
    if (k := spring_penalty(model.contact)) is not None:  # every rule: exact on spring rows
        return k
    if rule == "auto":
        return rule
    if rule == "static":
        return penalty(rule, model=model, condenser=condenser)
    # "top", "stiff" and "contact": the median of the top harmonic's radius over the band, times
    # the rule's factor
    grid = (np.geomspace if spacing == "log" else np.linspace)(f_min, f_max, SWEEP_SAMPLES)
    # prepared once for the band
    cond, prepared = condenser_for(model, condenser), springs(model.contact)
    top = np.asarray(orders)[-1:]
    values = []
    for f in grid:
        red = cond.reduced(2 * np.pi * float(f), top, False, float(f))  # = condense(...)
        if prepared is not None:
            red = connect(red, model.contact, prepared)
        values.append(penalty("top", reduced=red, contact=model.contact))
    return _factor(rule, model.contact) * float(np.median(values))
