"""Python API calls a hostile user makes: each argument of a small valid call replaced by a
wrong value (a string for a number, NaN, infinities, zero, negative, huge, None, an empty
sequence...), one at a time.

Shared by tests/test_validate.py and the survey (studies/hostile_inputs.py --api). Every
call must end in an InputError (or the TypeError Python raises for a wrong keyword), never a
deep error; a call that returns is counted as accepted, to be read (some values are legal:
0 is a valid gap).
"""

from __future__ import annotations

import math
import warnings

import numpy as np

import fretwear as fw

#: the wrong values tried for every argument
VALUES = ("1", "", None, True, math.nan, math.inf, -math.inf, 0, -1, -1e-12, 1e300, 10**30,
          2.5, (), [], [math.nan], ["1"], {"a": 1}, object())


def _mesh():
    return fw.rectangle(0.02, 0.01, 4, 2)


def _model():
    return fw.from_mesh(_mesh(), fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
                        supports=[fw.Spring("top_left", "x", 1e7)],
                        loads=[fw.Traction("right", pressure=1e5, waveform="cos")],
                        contact=fw.ContactSpec("bottom", mu=0.3), observed={"tip": (0.02, 0.01)})


def _chain(**contact):
    args = dict(normal_dofs=[1], tangential_dofs=[2], gap=0.0, area=1e-4, mu=0.3)
    args.update(contact)
    return fw.from_matrices(np.diag([3e6, 1e6, 5e5]), np.diag([0.3, 0.1, 0.0]),
                            contact=fw.ContactDofs(**args))


def targets():
    """(name, function of keyword arguments, the valid keyword arguments) of every call."""
    mesh, model = _mesh(), _model()
    mat = fw.Material(210e9, 0.3, 7800.0)
    return [
        ("rectangle", fw.rectangle, dict(length=0.02, height=0.01, nx=4, ny=2)),
        ("box", fw.box, dict(lx=0.02, ly=0.01, lz=0.01, nx=2, ny=1, nz=1)),
        ("Material", fw.Material, dict(E=210e9, nu=0.3, rho=7800.0)),
        ("Damping", fw.Damping, dict(loss_factor=0.01, rayleigh_mass=0.0,
                                     rayleigh_stiffness=0.0)),
        ("ContactSpec", fw.ContactSpec, dict(boundary="bottom", mu=0.3, gap=0.0,
                                             wear_coefficient=1e-13, tolerance=1e-6,
                                             normal_pressure=1e6, normal_waveform="cos",
                                             normal_stiffness=1e12)),
        ("from_mesh", lambda **k: fw.from_mesh(mesh, **k),
         dict(material=mat, thickness=0.01, supports=[fw.Spring("top_left", "x", 1e7)],
              contact=fw.ContactSpec("bottom", mu=0.3))),
        ("ContactDofs", _chain, dict(gap=0.0, area=1e-4, mu=0.3)),
        ("FourierBasis", fw.FourierBasis, dict(harmonics=(1, 2), n_samples=16)),
        ("FourierBasis.up_to", fw.FourierBasis.up_to, dict(nh=3, n_samples=16)),
        ("SolveOptions", fw.SolveOptions, dict(tol=1e-8, max_iter=50)),
        ("SweepOptions", fw.SweepOptions, dict(resume=False, max_bisections=4)),
        ("WearOptions", fw.WearOptions, dict(tolerance=0.05, max_cycles=1e6, max_steps=10,
                                             plateau_rate=1e-3)),
        ("modes", lambda **k: fw.modes(**k), dict(model=model, n_modes=2)),
        ("modes f_max", lambda **k: fw.modes(model, **k), dict(f_max=1e9)),
        ("frf", lambda **k: fw.frf(**k), dict(model=model, frequencies_hz=[1e3, 2e3])),
        ("transformed", lambda **k: fw.model.transformed(mesh, **k),
         dict(rotation=np.eye(2), shift=(0.0, 0.0))),
        ("read_mesh", fw.read_mesh, dict(path="missing.msh")),
    ]


def calls():
    """(label, thunk) of every hostile call: each argument of each target replaced by each
    of :data:`VALUES`."""
    out = []
    for name, func, valid in targets():
        for key in valid:
            for value in VALUES:
                args = {**valid, key: value}
                out.append((f"{name}({key}={value!r})"[:80],
                            lambda f=func, a=args: f(**a)))
    return out


def outcome(thunk) -> str:
    """``"message"`` (an InputError, or Python's TypeError for a wrong call), ``"accepted"``
    (the call returned) or ``"deep error: <type>"``."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            thunk()
    except fw.InputError:
        return "message"
    except TypeError as exc:  # Python's own: a missing or unexpected argument
        return "message" if "argument" in str(exc) else f"deep error: TypeError: {exc}"
    except Exception as exc:  # noqa: BLE001 (the survey classifies every escape)
        return f"deep error: {type(exc).__name__}: {exc}"[:160]
    return "accepted"
