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
    """``"message"`` (an InputError or a ConvergenceError, or Python's TypeError for a wrong
    call), ``"accepted"`` (the call returned), ``"accepted with a warning"`` (it returned
    with a warning of fretwear, e.g. an UnusualValueWarning naming the value: not silent),
    ``"hang"`` (beyond the CPU time limit of the case-file survey) or
    ``"deep error: <type>"``."""
    from helpers.hostile import TIME_LIMIT, Hang, cpu_time_limit

    try:
        with warnings.catch_warnings(record=True) as caught, cpu_time_limit(TIME_LIMIT):
            warnings.simplefilter("always")
            thunk()
    except Hang:
        return "hang"
    except (fw.InputError, fw.ConvergenceError):  # a one-line message of fretwear
        return "message"
    except TypeError as exc:  # Python's own: a missing or unexpected argument
        return "message" if "argument" in str(exc) else f"deep error: TypeError: {exc}"
    except Exception as exc:  # noqa: BLE001 (the survey classifies every escape)
        return f"deep error: {type(exc).__name__}: {exc}"[:160]
    named = [w for w in caught if issubclass(w.category, UserWarning)]
    return "accepted with a warning" if named else "accepted"


#: the public name each target of :func:`targets` calls (and the others it takes part in)
COVERS = {"rectangle": ("rectangle",), "box": ("box",), "Material": ("Material",),
          "Damping": ("Damping",), "ContactSpec": ("ContactSpec",), "from_mesh": ("from_mesh",),
          "ContactDofs": ("ContactDofs", "from_matrices"), "FourierBasis": ("FourierBasis",),
          "FourierBasis.up_to": ("FourierBasis",), "SolveOptions": ("SolveOptions",),
          "SweepOptions": ("SweepOptions",), "WearOptions": ("WearOptions",),
          "modes": ("modes",), "modes f_max": ("modes",), "frf": ("frf",), "transformed": (),
          "read_mesh": ("read_mesh",)}


def all_calls(folder) -> list[tuple[str, str, str, object, object]]:
    """``(label, public name, argument, wrong value, thunk)`` of every hostile call: those of
    :func:`calls` (each argument by each of :data:`VALUES`) and those of every other public
    name (tests/helpers/hostile_api_more.py, each argument by each of its ``FEW`` values;
    ``folder`` holds the files they read and write)."""
    from helpers import hostile_api_more as more

    out = []
    for name, func, valid in targets():
        for key in valid:
            for value in VALUES:
                args = {**valid, key: value}
                out.append((f"{name}({key}={value!r})"[:80], name, key, value,
                            lambda f=func, a=args: f(**a)))
    objects = more.Objects(folder)
    for label, name, func, valid in more.targets(objects):
        if not valid:  # no argument to get wrong: the call itself, once
            out.append((f"{label}()", name, "", None, lambda f=func: f()))
        for key in valid:
            for value in more.FEW:
                args = {**valid, key: value}
                out.append((f"{label}({key}={value!r})"[:80], name, key, value,
                            lambda f=func, a=args: f(**a)))
    return out


def covered(folder_targets=None) -> set:
    """The public names the calls of :func:`all_calls` cover, with those checked otherwise
    (hostile_api_more.NOT_CALLED)."""
    from helpers import hostile_api_more as more

    names = {n for v in COVERS.values() for n in v} | set(more.NOT_CALLED)
    if folder_targets is not None:
        names |= {name for _, name, _, _ in folder_targets}
    return names


def _is(value, *options) -> bool:
    return any(type(value) is type(o) and value == o for o in options)


def legal(name: str, key: str, value) -> str:
    """Why a call with ``key = value`` that returned is legal ("" when it is not: a silent
    accept of a wrong input). The reasons are the documented meaning of the value."""
    if key == "":
        return "a call without arguments"
    if value is None and (name, key) in _NONE_MEANS:
        return f"None is the documented default of {key}: {_NONE_MEANS[(name, key)]}"
    for (names, keys, values), why in _LEGAL:
        if (name in names or names == "*") and (key in keys or keys == "*") and any(
                _is(value, v) for v in values):
            return why
    return ""


#: (public name, argument) -> what None means there
_NONE_MEANS = {
    ("ContactSpec", "tolerance"): "the pairing tolerance computed from the model size",
    ("modes f_max", "f_max"): "n_modes modes, not a frequency band",
    ("transformed", "shift"): "no translation",
    ("modal_condenser", "modes"): "the modes below the cutoff",
    ("simulate_wear", "options"): "the default WearOptions",
    ("worn_state", "options"): "the default WornStateOptions",
    ("RunControl", "checkpoint"): "no checkpoint file",
    ("incremental_wear", "wear_coefficient"): "the model's contact wear coefficient",
    ("mistuning", "young"): "no mistuning of Young's modulus (all factors 1)",
    ("WearResult", "initial"): "no initial solution (a run resumed from its last state)",
    ("WearResult", "final"): "no final solution (a run that stopped before a balance)",
    ("InitialState", "U0"): "start from rest",
    ("InitialState", "V0"): "start from rest",
    ("set_blas_threads", "n"): "the BLAS library's own setting",
    ("write_results", "basis"): "the result's own basis (5 harmonics for a time integration)",
    ("plot", "basis"): "the result's own basis (5 harmonics for a time integration)",
}

#: ((names or "*", arguments or "*", values), why the values are legal there)
_LEGAL = (
    (("*", ("length", "height", "lx", "ly", "lz", "thickness"), (2.5,)),
     "2.5 m is a size inside the documented range [1e-9, 1e5] m"),
    (("Material", ("E",), (2.5,)), "E = 2.5 Pa is inside [1, 1e13] Pa (with an "
     "UnusualValueWarning: a unit mistake?)"),
    (("Material", ("nu",), (0, -1e-12)), "a Poisson ratio in (-1, 0.5): 0 (cork) and slightly "
     "negative (auxetic) are real materials"),
    (("Material", ("rho",), (0, 2.5)), "rho = 0 is a massless (quasi-static) model; 2.5 kg/m^3 "
     "is inside the range (with an UnusualValueWarning)"),
    (("Damping", "*", (0, 2.5)), "0 is no damping of that kind; 2.5 is inside the documented "
     "range (a loss factor <= 10, Rayleigh coefficients >= 0)"),
    (("ContactSpec", ("boundary",), ("1",)), "a boundary name: checked against the mesh by "
     "from_mesh, which refuses '1' (refused later, at its use)"),
    ((("ContactSpec", "ContactDofs"), ("mu",), (0, 2.5)),
     "mu = 0 is a frictionless contact; 2.5 is legal (UnusualValueWarning above 2)"),
    ((("ContactSpec", "ContactDofs"), ("gap",), (0, -1, -1e-12, 2.5)),
     "a gap >= 0 is open, < 0 an interference; |gap| up to 1e5 m (the size range)"),
    ((("ContactSpec",), ("wear_coefficient", "normal_pressure", "tolerance"), (0, 2.5)),
     "0 (no wear, no prescribed pressure, exact pairing) and 2.5 are inside the ranges "
     "(an UnusualValueWarning names a coefficient outside the usual range)"),
    ((("ContactSpec",), ("normal_stiffness",), (math.inf, 2.5)),
     "inf is a rigid contact (the default); 2.5 Pa/m is a soft contact layer"),
    ((("ContactDofs",), ("area",), (2.5,)), "an area of 2.5 m^2 per node"),
    ((("SweepOptions",), ("resume",), (True,)), "resume = True continues from a checkpoint "
     "(none here: the sweep starts)"),
    ((("SweepOptions",), ("max_bisections",), (0,)), "0: no halving of a failed step"),
    ((("WearOptions",), ("tolerance", "max_cycles", "plateau_rate"), (2.5,)),
     "2.5 is inside the range of the option"),
    ((("WearOptions",), ("max_cycles",), (math.inf,)), "max_cycles = inf: no cycle limit "
     "(another criterion stops the run)"),
    ((("WearOptions",), ("plateau_rate",), (0,)), "plateau_rate = 0: never stop on a plateau"),
    ((("modes f_max",), ("f_max",), (2.5,)), "the modes below 2.5 Hz (none: an empty result, "
     "said so)"),
    ((("frf",), ("frequencies_hz",), (2.5,)), "one frequency, 2.5 Hz"),
    ((("whole_disk", "cyclic_condenser", "cyclic_frf", "mistuned_disk"), ("engine_order",),
      (-1,)), "a negative engine order is the wave travelling the other way"),
    ((("Traction",), ("pressure",), (-1,)), "a negative pressure pulls (a traction load)"),
    ((("ObservedPoint",), ("coords",), ([],)), "the coordinates of a point of user matrices "
     "(none: the point is DOFs only)"),
    ((("Load", "ObservedPoint"), ("name",), ("1",)), "'1' is a valid name (any string)"),
    ((("WearResult",), ("message",), ("1",)), "a message is any string"),
    ((("RunControl",), ("checkpoint",), ("1",)), "'1' is a relative file path (a file named 1)"),
    ((("blade_amplitudes",), ("amplitude",), (-1,)), "a (complex) amplitude of -1 m: its modulus "
     "1 m is taken"),
)
