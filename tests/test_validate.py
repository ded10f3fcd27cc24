"""Arguments of the public API checked as the case files check their keys (fretwear.validate):
one InputError naming the argument, never a deep error or a silent acceptance.

Each hostile call of issue 30 (item 8) is made here and must raise an InputError whose message
names the argument; the reference is the issue's list of calls that were accepted or failed
deep inside. The legal neighbour of each refused value is also checked where the refusal
could overreach (a numpy scalar, a static basis). No solve runs: every check is up front.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
from helpers.studies import base_case, study_file

import fretwear as fw
from fretwear import validate
from fretwear.analyses.run import load_case
from fretwear.errors import InputError
from fretwear.io.case import build_model


@pytest.fixture(scope="module")
def beam():
    mesh = fw.rectangle(0.1, 0.01, nx=4, ny=1)
    model = fw.from_mesh(mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
                         supports=[fw.Spring(at="bottom_left", direction="x", stiffness=1e4)],
                         loads=[fw.Traction("right", pressure=1e4, waveform="sin")],
                         contact=fw.ContactSpec("bottom", mu=0.3),
                         observed={"tip": (0.1, 0.01)})
    return mesh, model


def _contact_dofs(**changes):
    args = dict(normal_dofs=[1], tangential_dofs=[2], gap=0.0, area=1e-4, mu=0.3)
    args.update(changes)
    K, M = np.diag([3e6, 1e6, 5e5]), np.diag([0.3, 0.1, 0.0])
    return fw.from_matrices(K, M, contact=fw.ContactDofs(**args))


HOSTILE = {
    "thickness": lambda mesh, model: fw.from_mesh(mesh, fw.Material(210e9, 0.3, 7800.0),
                                                  thickness="1",
                                                  contact=fw.ContactSpec("bottom", mu=0.3)),
    "gap": lambda mesh, model: _contact_dofs(gap="0"),
    "frequencies_hz": lambda mesh, model: fw.frf(model, ["100"]),
    "tolerance": lambda mesh, model: fw.ContactSpec("bottom", mu=0.3, tolerance="1"),
    "nh": lambda mesh, model: fw.FourierBasis.up_to(0, 16),
    "harmonics": lambda mesh, model: fw.FourierBasis((), 16),
    "f_max": lambda mesh, model: fw.modes(model, 3, f_max=-1),
    "n_modes": lambda mesh, model: fw.modes(model, 2.5),
    "model": lambda mesh, model: fw.modes(None, 3),
    "energy_coefficient": lambda mesh, model: fw.WearOptions(law="energy").check(),
    "partner_energy_coefficient": lambda mesh, model: fw.WearOptions(
        partner_energy_coefficient=1e-9),
    "shift": lambda mesh, model: fw.model.transformed(mesh, np.eye(2), (math.nan, 0.0)),
    "rotation": lambda mesh, model: fw.model.transformed(mesh, "eye"),
    "normal_pressure": lambda mesh, model: fw.ContactSpec("bottom", mu=0.3,
                                                          normal_pressure=math.inf),
    "normal_waveform": lambda mesh, model: fw.ContactSpec("bottom", mu=0.3,
                                                          normal_pressure=1e6,
                                                          normal_waveform="square"),
    "path": lambda mesh, model: fw.read_mesh(None),
    "tol": lambda mesh, model: fw.SolveOptions(tol=math.nan),
    "resume": lambda mesh, model: fw.SweepOptions(resume="yes"),
}


@pytest.mark.parametrize("name", list(HOSTILE))
def test_hostile_api_call_is_one_input_error_naming_the_argument(beam, name):
    with pytest.raises(InputError, match=name) as err:
        HOSTILE[name](*beam)
    assert "\n" not in str(err.value)


def test_legal_neighbours_still_pass(beam):
    """What the checks must not refuse: numpy scalars, an int thickness, the static basis,
    a normal waveform with its pressure, a plain path."""
    mesh, model = beam
    assert validate.number(np.float32(2.0), "x") == 2.0
    assert validate.whole(np.int64(3), "n") == 3
    fw.from_mesh(mesh, fw.Material(210e9, 0.3, 7800.0), thickness=np.float64(0.01),
                 supports=[("top", "all")], contact=fw.ContactSpec("bottom", mu=0.3))
    assert fw.FourierBasis.static().harmonics == ()
    assert fw.ContactSpec("bottom", mu=0.3, normal_pressure=1e6,
                          normal_waveform="cos").normal_waveform == "cos"
    assert fw.modes(model, 2, f_max=1e9).frequency_hz.size >= 1


@pytest.mark.parametrize("value", ["1", True, None, math.nan, math.inf, [1.0]])
def test_number_refuses_what_is_not_a_finite_real(value):
    with pytest.raises(InputError, match="^x = "):
        validate.number(value, "x")


def test_range_messages():
    with pytest.raises(InputError, match=r"x = 0; expected a value > 0 and <= 1"):
        validate.number(0, "x", low=0.0, open_low=True, high=1.0)
    with pytest.raises(InputError, match="expected a whole number >= 1"):
        validate.whole(0, "n", low=1)
    with pytest.raises(InputError, match="holds -1; expected values >= 0"):
        validate.reals([1.0, -1.0], "a", low=0.0)
    with pytest.raises(TypeError):  # an ArgumentTypeError is a TypeError too
        validate.instance(None, int, "k", "an int")


# --- studies: workers, scheduler and sizes refused before anything starts ------------------
@pytest.mark.parametrize("args, match", [
    ({"workers": 10**6}, "workers = 1000000"),
    ({"workers": 0}, "workers = 0"),
    ({"workers": -1}, "workers = -1"),
    ({"workers": 2.0}, "workers = 2.0"),
    ({"scheduler": 8786}, "scheduler = 8786"),
])
def test_run_study_arguments(tmp_path, args, match):
    base_case(tmp_path)
    path = study_file(tmp_path, "[grid]\ncontact.mu = [0.1]\n")
    with pytest.raises(InputError, match=match):
        fw.run_study(path, tmp_path / "out", **args)
    assert not (tmp_path / "out").exists()


GRID_40_6 = "[grid]\n" + "".join(
    f"{k} = {[round(0.1 + 0.01 * i, 2) for i in range(40)]}\n"
    for k in ("contact.mu", "damping.loss_factor", "material.nu", "model.thickness",
              "material.E", "material.rho"))


@pytest.mark.parametrize("body", [
    GRID_40_6,
    '[samples]\nn = 1000000000\nseed = 1\n[samples.vary]\n'
    'contact.mu = {distribution = "uniform", low = 0.1, high = 0.5}\n',
], ids=["grid-40^6", "samples-1e9"])
def test_study_too_large_is_refused_before_expanding(tmp_path, body):
    """40^6 grid members and 1e9 samples (the issue's sizes): refused from the member count
    alone, in well under a second (expanding them would take hours or all the memory)."""
    from fretwear.study.members import expand
    from fretwear.study.spec import read_study

    base_case(tmp_path)
    with pytest.raises(InputError, match="members; expected at most"):
        expand(read_study(study_file(tmp_path, body)))


# --- case files: keys checked for meaning ---------------------------------------------------
MESH_CASE = """\
[model]
type = "rectangle"
length = 0.1
height = 0.01
nx = 4
ny = 1
thickness = 0.01
[material]
E = 210e9
nu = 0.3
rho = 7800.0
[[springs]]
at = "bottom_left"
direction = "x"
stiffness = 1e4
[contact]
boundary = "bottom"
mu = 0.3
{contact}
[analysis]
type = "modes"
"""


def _case_error(tmp_path, text: str, name: str = "case.toml") -> str:
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(InputError) as err:
        build_model(load_case(path))
    assert "\n" not in str(err.value)
    return str(err.value)


def test_normal_waveform_without_a_normal_load_is_refused(tmp_path):
    msg = _case_error(tmp_path, MESH_CASE.format(contact='normal_waveform = "cos"'))
    assert "'normal_waveform' = 'cos' needs 'normal_pressure'" in msg


@pytest.mark.parametrize("line, key", [("normal_load = [1.0, 1.0, 1.0]", "normal_load"),
                                       ("area = [1.0, 1.0, 1.0]", "area"),
                                       ("gap = [0.0, 0.0, 0.0]", "gap")])
def test_matrices_contact_lists_longer_than_the_contact_nodes(tmp_path, line, key):
    """Two contact nodes, three values: a broadcasting traceback before."""
    scipy.io.mmwrite(tmp_path / "K.mtx", sp.coo_matrix(np.eye(2)))
    scipy.io.mmwrite(tmp_path / "M.mtx", sp.coo_matrix(np.eye(2)))
    text = ('[model]\ntype = "matrices"\nK = "K.mtx"\nM = "M.mtx"\n'
            f'[contact]\ntangential_dofs = [0, 1]\nmu = 0.5\nnormal_load = 1.0\n{line}\n'
            '[analysis]\ntype = "modes"\n')
    if key == "normal_load":
        text = text.replace("normal_load = 1.0\n", "")
    msg = _case_error(tmp_path, text)
    assert msg.startswith(f"model.contact.{key} has 3 values; expected one, or one per "
                          "contact node (2")


def test_material_of_a_set_without_a_whole_cell(tmp_path):
    """A boundary's node set holds no whole cell: the material would apply to nothing."""
    mesh = fw.rectangle(0.1, 0.01, nx=4, ny=1)
    with pytest.raises(InputError, match="node set 'top' holds no whole cell"):
        fw.from_mesh(mesh, {"top": fw.Material(210e9, 0.3, 7800.0),
                            None: fw.Material(210e9, 0.3, 7800.0)}, thickness=0.01,
                     supports=[("top", "all")], contact=fw.ContactSpec("bottom", mu=0.3))


def test_unusual_material_and_friction_warn_in_python():
    """The Python records say what a case file says (fretwear.limits.unusual)."""
    with pytest.warns(UserWarning, match="Material: E = 210 Pa is below the usual range"):
        fw.Material(210.0, 0.3, 7800.0)
    with pytest.warns(UserWarning, match="contact 'contact': mu = 5 is above the usual"):
        fw.ContactSpec("bottom", mu=5.0)


def test_hostile_api_calls_never_end_in_a_deep_error():
    """Every argument of the survey's targets (tests/helpers/hostile_api.py) replaced by each
    wrong value: an InputError (or Python's own TypeError for a wrong call) or a legal value
    accepted, never another exception (the issue counted 7 + 6 deep errors)."""
    from helpers import hostile_api

    deep = [f"{label} -> {out}" for label, thunk in hostile_api.calls()
            if (out := hostile_api.outcome(thunk)).startswith("deep")]
    assert deep == []


def test_gap_larger_than_any_structure_is_refused():
    """gap = 1e308 m (the survey's one case whose solves overflowed with warnings on stderr):
    one InputError, on both routes; a gap of 1 mm still passes."""
    with pytest.raises(InputError, match="gap = 1e.308 m; expected a value >= -100000"):
        fw.ContactSpec("bottom", mu=0.3, gap=1e308)
    with pytest.raises(InputError, match="gap .m.: 1e.300; expected magnitudes <= 100000"):
        _contact_dofs(gap=1e300)
    assert fw.ContactSpec("bottom", mu=0.3, gap=1e-3).gap == 1e-3


def test_the_hostile_api_survey_covers_every_public_name():
    """Every name of fretwear.__all__ is called by the API survey (tests/helpers/
    hostile_api.py and hostile_api_more.py) or checked without calls (the version string and
    the exceptions), so a name added to the API without its hostile calls fails here. The
    reference is fretwear.__all__ itself."""
    from helpers import hostile_api, hostile_api_more

    names = {n for v in hostile_api.COVERS.values() for n in v}
    names |= set(hostile_api_more.TARGET_NAMES) | set(hostile_api_more.NOT_CALLED)
    assert set(fw.__all__) <= names, sorted(set(fw.__all__) - names)
    assert hostile_api_more.check_not_called() == []
