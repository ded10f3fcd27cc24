"""Checks of the model records a user hands to the public API (a :class:`~.core.Model`, its
contact, loads and observed points, a :class:`~.core.Mesh`): every field of the right kind,
shape, finiteness and range, so that a wrong record is one
:class:`~fretwear.errors.InputError` naming the field, never a deep error inside numpy or
scipy. Models built by fretwear (``from_mesh``, ``from_matrices``, the case files) always
pass; the checks cost one pass over the matrices' stored values.

:func:`model_argument` applies :func:`check_model` to the ``model`` argument (and
:func:`check_sector` to ``sector``) of a public function.
"""

from __future__ import annotations

import functools
import inspect

import numpy as np
import scipy.sparse as sp

from fretwear.errors import InputError
from fretwear.model.core import WAVEFORMS, ContactInterface, Load, Mesh, Model, ObservedPoint
from fretwear.validate import ArgumentTypeError, whole

#: the largest magnitude of a whole-number argument (as the case files' integer keys)
INTEGER_MAX = 2**62


def whole_number(value, what: str, low: int | None = None) -> int:
    """``value`` as an int after checking it is an integer (not a bool, float or string) of
    magnitude at most :data:`INTEGER_MAX` and ``>= low``."""
    return whole(value, what, low=-INTEGER_MAX if low is None else low, high=INTEGER_MAX)


def amplitudes(value, what: str, *, nan: bool = False) -> np.ndarray:
    """A non-empty array of real or complex amplitudes, finite (NaN allowed with ``nan``:
    an entry not computed), of moduli as given."""
    a = _array(value, what, kind="c", allow_nan=nan)
    if not a.size:
        raise InputError(f"{what} is empty; expected at least one amplitude")
    if nan and not np.any(np.isfinite(a)):
        raise InputError(f"{what} holds no finite value")
    return a


def _array(value, what: str, *, kind: str = "f", shape=None, low=None, positive=False,
           allow_nan=False):
    """``value`` as an array after checking its kind (``"f"`` real, ``"c"`` real or complex,
    ``"i"`` integer), ``shape`` (None entries free), finiteness and bounds."""
    if isinstance(value, str | bytes) or value is None:
        raise InputError(f"{what} = {value!r}; expected an array of numbers")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        raise InputError(f"{what}: expected an array of numbers") from None
    ok = {"f": "iuf", "c": "iufc", "i": "iu"}[kind]
    if a.dtype.kind not in ok:
        raise InputError(f"{what} holds {a.dtype} values; expected "
                         + ("whole numbers" if kind == "i" else "real numbers"))
    if shape is not None and (a.ndim != len(shape) or any(
            s is not None and n != s for n, s in zip(a.shape, shape, strict=True))):
        want = "(" + ", ".join("n" if s is None else str(s) for s in shape) + ")"
        raise InputError(f"{what} has shape {a.shape}; expected {want}")
    if a.dtype.kind in "fc" and not np.all(np.isfinite(a) | (allow_nan & np.isnan(a))):
        raise InputError(f"{what} holds non-finite values (nan or inf); expected finite ones")
    if low is not None and a.size and np.any(a.real < low):
        raise InputError(f"{what} holds {a.real.min():g}; expected values >= {low:g}")
    if positive and a.size and np.any(a.real <= 0):
        raise InputError(f"{what} holds {a.real.min():g}; expected values > 0")
    return a


def _matrix(value, what: str, n: int | None):
    """Check a structural matrix: sparse or dense, square (``n`` x ``n``), finite, real."""
    if sp.issparse(value):
        if value.ndim != 2 or value.shape[0] != value.shape[1] or (
                n is not None and value.shape[0] != n):
            raise InputError(f"{what} has shape {value.shape}; expected a square matrix"
                             + (f" of {n} rows" if n is not None else ""))
        _array(value.data, f"{what} (its stored values)")
        return value.shape[0]
    if not isinstance(value, np.ndarray):
        raise ArgumentTypeError(f"{what} = {_short(value)}; expected a scipy.sparse matrix or "
                                "a numpy array")
    _array(value, what, shape=(n, n) if n is not None else (None, None))
    if value.shape[0] != value.shape[1]:
        raise InputError(f"{what} has shape {value.shape}; expected a square matrix")
    return value.shape[0]


def _dofs(value, what: str, ndof: int, shape=None):
    a = _array(value, what, kind="i", shape=shape)
    if a.size and (a.min() < 0 or a.max() >= ndof):
        raise InputError(f"{what} holds DOF {int(a.min() if a.min() < 0 else a.max())}; "
                         f"expected DOFs in [0, {ndof - 1}] (the model has {ndof})")
    return a


def check_contact(c, ndof: int, what: str = "model.contact") -> None:
    """Check a :class:`ContactInterface` against a model of ``ndof`` DOFs."""
    if not isinstance(c, ContactInterface):
        raise ArgumentTypeError(f"{what} = {_short(c)}; expected a ContactInterface")
    dofs = _dofs(c.dofs, f"{what}.dofs", ndof, shape=(None, None))
    nc, d = dofs.shape
    if nc < 1 or d not in (1, 2, 3):
        raise InputError(f"{what}.dofs has shape {dofs.shape}; expected (nodes >= 1, 1 to 3 "
                         "components)")
    _array(c.frame, f"{what}.frame", shape=(nc, d, d))
    _array(c.gap, f"{what}.gap", shape=(nc,))
    _array(c.area, f"{what}.area", shape=(nc,), positive=True)
    for name in ("mu", "wear_coefficient", "partner_wear_coefficient"):
        v = _array(getattr(c, name), f"{what}.{name}", low=0.0)
        if v.ndim > 1 or (v.ndim == 1 and v.shape[0] != nc):
            raise InputError(f"{what}.{name} has shape {v.shape}; expected one value or one "
                             f"per contact node ({nc})")
    _array(c.coords, f"{what}.coords", shape=(nc, None))
    if not isinstance(c.name, str):
        raise InputError(f"{what}.name = {_short(c.name)}; expected a string")


def check_load(load, ndof: int, what: str) -> None:
    """Check a :class:`Load` against a model of ``ndof`` DOFs."""
    if not isinstance(load, Load):
        raise ArgumentTypeError(f"{what} = {_short(load)}; expected a fretwear Load")
    _array(load.vector, f"{what}.vector", kind="c", shape=(ndof,))
    if not isinstance(load.waveform, str) or load.waveform not in WAVEFORMS:
        raise InputError(f"{what}.waveform = {load.waveform!r}; expected one of "
                         f"{list(WAVEFORMS)}")
    if not isinstance(load.name, str):
        raise InputError(f"{what}.name = {_short(load.name)}; expected a string")


def check_observed(p, ndof: int, what: str) -> None:
    """Check an :class:`ObservedPoint` against a model of ``ndof`` DOFs."""
    if not isinstance(p, ObservedPoint):
        raise ArgumentTypeError(f"{what} = {_short(p)}; expected an ObservedPoint")
    if not isinstance(p.name, str) or not p.name:
        raise InputError(f"{what}.name = {_short(p.name)}; expected a non-empty string")
    dofs = _dofs(p.dofs, f"{what}.dofs", ndof, shape=(None,))
    if not dofs.size:
        raise InputError(f"{what}.dofs is empty; expected at least one DOF")
    _array(p.coords, f"{what}.coords", shape=(None,))


def check_model(model, what: str = "model") -> Model:
    """``model`` after checking it is a :class:`Model` whose every field is sound."""
    if not isinstance(model, Model):
        raise ArgumentTypeError(f"{what} = {_short(model)}: expected a fretwear Model "
                                "(fretwear.from_mesh, fretwear.from_matrices)")
    n = _matrix(model.K, f"{what}.K", None)
    if n < 1:
        raise InputError(f"{what}.K is empty; expected at least one DOF")
    _matrix(model.M, f"{what}.M", n)
    for name in ("C", "D"):
        if getattr(model, name) is not None:
            _matrix(getattr(model, name), f"{what}.{name}", n)
    check_contact(model.contact, n, f"{what}.contact")
    for kind, items, check in (("loads", model.loads, check_load),
                               ("observed", model.observed, check_observed)):
        if not isinstance(items, list | tuple):
            raise InputError(f"{what}.{kind} = {_short(items)}; expected a list")
        for i, item in enumerate(items):
            check(item, n, f"{what}.{kind}[{i}]")
    _dofs(model.fixed_dofs, f"{what}.fixed_dofs", n, shape=(None,))
    return model


def check_mesh(mesh, what: str = "mesh") -> Mesh:
    """``mesh`` after checking it is a :class:`Mesh` with finite points (n, 2 or 3), cells
    of node numbers in range and facets of the boundaries in range."""
    if not isinstance(mesh, Mesh):
        raise ArgumentTypeError(f"{what} = {_short(mesh)}; expected a fretwear Mesh "
                                "(fretwear.rectangle, fretwear.box, fretwear.read_mesh)")
    pts = _array(mesh.points, f"{what}.points", shape=(None, None))
    if pts.shape[1] not in (2, 3) or not pts.shape[0]:
        raise InputError(f"{what}.points has shape {pts.shape}; expected (nodes >= 1, 2 or 3)")
    _dofs(mesh.cells, f"{what}.cells", pts.shape[0], shape=(None, None))
    if not isinstance(mesh.cell_type, str):
        raise InputError(f"{what}.cell_type = {_short(mesh.cell_type)}; expected a string")
    for kind in ("boundaries", "node_sets"):
        sets = getattr(mesh, kind)
        if not isinstance(sets, dict):
            raise InputError(f"{what}.{kind} = {_short(sets)}; expected a dict of name -> "
                             "node numbers")
        for name, nodes in sets.items():
            _dofs(nodes, f"{what}.{kind}[{name!r}]", pts.shape[0])
    return mesh


def check_sector(sector, what: str = "sector"):
    """``sector`` after checking it is a CyclicSector with a sound model."""
    from fretwear.model.cyclic import CyclicSector

    if not isinstance(sector, CyclicSector):
        raise ArgumentTypeError(f"{what} = {_short(sector)}; expected a CyclicSector "
                                "(fretwear.cyclic_sector, fretwear.lumped_blisk)")
    check_model(sector.model, f"{what}.model")
    return sector


def model_argument(func):
    """``func`` with its ``model`` argument checked by :func:`check_model` and its ``sector``
    argument by :func:`check_sector` (when it has them) before it runs."""
    sig = inspect.signature(func)
    names = [n for n in ("model", "sector") if n in sig.parameters]

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        try:
            bound = sig.bind_partial(*args, **kwargs).arguments
        except TypeError:
            return func(*args, **kwargs)  # Python's own message
        for n in names:
            if n in bound:
                (check_model if n == "model" else check_sector)(bound[n], n)
        return func(*args, **kwargs)

    return wrapper


def _short(value, n: int = 60) -> str:
    r = repr(value)
    return r if len(r) <= n else r[: n - 3] + "..."
