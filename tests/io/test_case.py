"""Case files: every validation message names the key, the value and what is expected.

The messages are compared with the exact wording users see (`fretwear run` prints them on
one line), since their wording is the interface.
"""

import math
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from fretwear.analyses.registry import analysis_tables
from fretwear.analyses.run import case_docs, load_case
from fretwear.errors import InputError
from fretwear.io.case import build_model, validate

BASE = """\
title = "small beam"

[model]
type = "rectangle"
length = 0.1
height = 0.01
nx = 6
ny = 2
thickness = 0.01

[material]
E = 210e9
nu = 0.3
rho = 7800.0

[damping]
loss_factor = 0.001

[[springs]]
at = "bottom_left"
direction = "x"
stiffness = 1e4

[[loads]]
boundary = "top"
pressure = 1e4

[[loads]]
boundary = "right"
pressure = 1e4
waveform = "sin"

[contact]
boundary = "bottom"
normal = [0.0, -1.0]
mu = 0.3
wear_coefficient = 1e-11

[observed]
Pe = [0.1, 0.005]

[analysis]
type = "frf"
f_min = 10.0
f_max = 1e5
n_points = 3
"""


def write(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def error_of(tmp_path: Path, text: str, build: bool = False) -> str:
    """The message of the InputError that loading (and building) ``text`` raises."""
    with pytest.raises(InputError) as info:
        case = load_case(write(tmp_path, text))
        if build:
            build_model(case)
    return str(info.value)


def test_valid_case_loads_with_defaults_and_builds(tmp_path):
    case = load_case(write(tmp_path, BASE))
    assert case.title == "small beam"
    assert case.model_kind == "mesh"
    assert case.analysis == {
        "type": "frf", "f_min": 10.0, "f_max": 1e5, "n_points": 3, "spacing": "log",
        "interfaces": ["sliding", "stuck"], "method": "direct",
    }
    assert case.output == {"figures": True, "figure_format": "png", "vtu": True}
    assert case.model["loads"][0]["waveform"] == "constant"
    assert case.model["contact"][0]["gap"] == 0.0  # [contact]: a list of one interface
    assert case.output_dir() == tmp_path / "case-results"
    model = build_model(case)
    assert model.contact.n_nodes == 7  # nx + 1 nodes on the bottom face
    assert model.thickness == 0.01
    assert [p.name for p in model.observed] == ["Pe"]
    assert model.D is not None and model.C is None


def test_unknown_top_level_key_suggests_the_close_match(tmp_path):
    msg = error_of(tmp_path, BASE.replace("[material]", "[materal]"))
    assert msg.startswith("unknown key 'materal' in [top level]; expected one of: title, "
                          "model, material, damping,")
    assert msg.endswith("(did you mean 'material'?)")


def test_unknown_nested_key_names_its_table(tmp_path):
    msg = error_of(tmp_path, BASE.replace("nu = 0.3", "nuu = 0.3"))
    assert msg == ("unknown key 'nuu' in [material]; expected one of: E, nu, rho "
                   "(did you mean 'nu'?)")


def test_unknown_key_in_an_array_of_tables_names_the_item(tmp_path):
    msg = error_of(tmp_path, BASE.replace('waveform = "sin"', 'wavefrom = "sin"'))
    assert msg.startswith("unknown key 'wavefrom' in [loads[2]];")
    assert msg.endswith("(did you mean 'waveform'?)")


def test_wrong_type(tmp_path):
    msg = error_of(tmp_path, BASE.replace("E = 210e9", 'E = "210e9"'))
    assert msg == 'material.E = "210e9": expected a number > 0, got a string'
    msg = error_of(tmp_path, BASE.replace("nx = 6", "nx = 6.0"))
    assert msg == "model.nx = 6.0: expected an integer >= 1, got a number"


def test_poisson_ratio_of_one_half_is_refused(tmp_path):
    msg = error_of(tmp_path, BASE.replace("nu = 0.3", "nu = 0.5"))
    assert msg == "material.nu = 0.5: expected a number in (-1, 0.5)"


def test_negative_young_modulus(tmp_path):
    msg = error_of(tmp_path, BASE.replace("E = 210e9", "E = -210e9"))
    assert msg == "material.E = -210000000000.0: expected a number > 0"


def test_out_of_range_in_an_array_item(tmp_path):
    msg = error_of(tmp_path, BASE.replace("stiffness = 1e4", "stiffness = -1.0"))
    assert msg == 'springs[1].stiffness = -1.0: expected a number in (0, 1e+20] or inf (also "inf")'


def test_missing_required_key(tmp_path):
    msg = error_of(tmp_path, BASE.replace("mu = 0.3\n", ""))
    assert msg == ("missing required key 'contact.mu' (Coulomb friction coefficient: "
                   "a number >= 0)")
    msg = error_of(tmp_path, BASE.replace("[contact]", "[contacts]"))
    assert msg.endswith("(did you mean 'contact'?)")


def test_wrong_choice_suggests(tmp_path):
    msg = error_of(tmp_path, BASE.replace('direction = "x"', 'direction = "X"'))
    assert msg == ('springs[1].direction = "X": expected one of "x", "y", "z" or a list of '
                   '2 or 3 numbers (did you mean "x"?)')
    msg = error_of(tmp_path, BASE.replace('type = "rectangle"', 'type = "rectangel"'))
    assert msg == ('model.type = "rectangel": expected one of "rectangle", "box", "blocks", '
                   '"mesh", "matrices" (did you mean "rectangle"?)')


def test_unknown_boundary_is_reported_with_its_key(tmp_path):
    msg = error_of(tmp_path, BASE.replace('boundary = "bottom"', 'boundary = "botom"'),
                   build=True)
    assert msg == ('contact.boundary = "botom": expected one of "bottom", "left", "right", '
                   '"top" (did you mean "bottom"?)')
    msg = error_of(tmp_path, BASE.replace('boundary = "top"', 'boundary = "tpo"'), build=True)
    assert msg.startswith('loads[1].boundary = "tpo": expected one of')


def test_vector_size_is_checked_against_the_mesh(tmp_path):
    msg = error_of(tmp_path, BASE.replace("Pe = [0.1, 0.005]", "Pe = [0.1, 0.005, 0.0]"),
                   build=True)
    assert msg == "observed.Pe = [0.1, 0.005, 0.0]: expected 2 components for a 2D model"


def test_rules_across_keys(tmp_path):
    msg = error_of(tmp_path, BASE.replace("pressure = 1e4\n\n[[loads]]",
                                          "pressure = 1e4\ntraction = [1.0, 0.0]\n\n[[loads]]"))
    assert msg == ("[loads[1]]: give exactly one of 'pressure', 'traction', 'force' "
                   "(got 'pressure', 'traction')")
    msg = error_of(tmp_path, BASE.replace('waveform = "sin"', 'waveform = "fourier"'))
    assert msg.startswith('[loads[2]]: waveform = "fourier" needs coefficients')
    msg = error_of(tmp_path, BASE.replace("f_max = 1e5", "f_max = 5.0"))
    assert msg == "analysis.f_max = 5.0: expected a value above f_min = 10.0 Hz"


def test_fourier_coefficients_and_infinite_spring(tmp_path):
    text = BASE.replace('waveform = "sin"', 'waveform = "fourier"\ncoefficients = {"1" = '
                        "[0.0, 1.0], \"3\" = [0.0, -0.1]}")
    text = text.replace("stiffness = 1e4", 'stiffness = "inf"')
    text = text.replace('at = "bottom_left"', 'at = "top_left"')  # contact DOFs can't be fixed
    case = load_case(write(tmp_path, text))
    assert case.model["springs"][0]["stiffness"] == math.inf
    model = build_model(case)
    assert model.loads[1].coefficients == {1: (0.0, 1.0), 3: (0.0, -0.1)}
    assert model.fixed_dofs.tolist() == [2 * 14]  # x of the top-left node, (nx + 1) * ny


def test_unregistered_analysis_lists_the_available_ones(tmp_path):
    msg = error_of(tmp_path, BASE.replace('type = "frf"', 'type = "no-such-analysis"'))
    assert msg.startswith('analysis.type = "no-such-analysis": expected one of "modes", "frf"')


def test_invalid_toml_and_missing_file(tmp_path):
    msg = error_of(tmp_path, BASE.replace("nu = 0.3", "nu = "))
    assert msg.startswith("case.toml: invalid TOML: ")
    with pytest.raises(InputError, match="does not exist"):
        load_case(tmp_path / "nope.toml")


# --- matrices models: DOF lists and relative paths ------------------------------------------
MATRICES = """\
[model]
type = "matrices"
K = "K.mtx"
M = "M.mtx"

[contact]
normal_dofs = [0, 2]
tangential_dofs = [1, 3]
mu = 0.2

[output]
directory = "out"

[analysis]
type = "modes"
"""


def matrices_folder(tmp_path: Path) -> Path:
    folder = tmp_path / "model"
    folder.mkdir()
    K = sp.diags([np.full(6, 2.0), np.full(5, -1.0), np.full(5, -1.0)], [0, -1, 1])
    scipy.io.mmwrite(folder / "K.mtx", K.tocoo())
    scipy.io.mmwrite(folder / "M.mtx", sp.identity(6).tocoo())
    return folder


def test_relative_paths_start_from_the_case_folder(tmp_path, monkeypatch):
    folder = matrices_folder(tmp_path)
    path = write(folder, MATRICES)
    monkeypatch.chdir(tmp_path)  # not the case folder
    case = load_case(Path("model") / "case.toml")
    assert case.model_kind == "matrices"
    assert case.model["model"]["K"] == folder.resolve() / "K.mtx"
    assert case.output_dir() == folder.resolve() / "out"
    assert case.output_dir("elsewhere") == (tmp_path / "elsewhere").resolve()
    assert case.path == path.resolve()


def test_missing_matrix_file(tmp_path):
    folder = matrices_folder(tmp_path)
    msg = error_of(folder, MATRICES.replace('"M.mtx"', '"Mass.mtx"'))
    assert msg.startswith('model.M = "Mass.mtx": expected the path of an existing file (no file '
                          "at ")


def test_empty_contact_set(tmp_path):
    folder = matrices_folder(tmp_path)
    msg = error_of(folder, MATRICES.replace("normal_dofs = [0, 2]", "normal_dofs = []"))
    assert msg == ("contact.normal_dofs = []: expected a non-empty list of integers >= 0 "
                   "(no repeats)")


def test_mesh_sections_are_unknown_in_a_matrices_case(tmp_path):
    folder = matrices_folder(tmp_path)
    msg = error_of(folder, MATRICES + "\n[material]\nE = 1.0\nnu = 0.3\n")
    assert msg.startswith("unknown key 'material' in [top level]; expected one of: title, "
                          "model, damping, loads, contact, observed, analysis, output")


def test_validate_a_dict():
    out = validate({"model": {"type": "box", "lx": 1.0, "ly": 1.0, "lz": 1.0, "nx": 1,
                              "ny": 1, "nz": 1},
                    "material": {"E": 1.0, "nu": 0.0},
                    "contact": {"boundary": "zmin", "mu": 0.1},
                    "analysis": {"type": "modes"}}, analysis_tables())
    assert out["material"]["rho"] == 0.0
    assert out["analysis"] == {"type": "modes", "n_modes": 10, "interfaces": ["sliding", "stuck"]}
    assert out["damping"] == {"loss_factor": 0.0, "rayleigh_mass": 0.0,
                              "rayleigh_stiffness": 0.0}


def test_case_files_doc_is_up_to_date():
    """The committed docs/case-files.md equals what the schemas generate (the repository's
    file, found from this test file: the package may be installed elsewhere)."""
    committed = (Path(__file__).resolve().parents[2] / "docs" / "case-files.md").read_text(
        encoding="utf-8")
    assert committed == case_docs(), (
        "docs/case-files.md is out of date; regenerate it with\n"
        "  python -c 'from fretwear.analyses.run import write_case_docs; write_case_docs()'"
    )


def test_matrices_case_reproduces_the_mesh_case(tmp_path):
    """The beam exported as matrices and described by a `matrices` case gives the same FRF
    as the mesh case (same K, M, D, loads, contact DOFs): agreement to rounding."""
    from fretwear import linear

    mesh_model = build_model(load_case(write(tmp_path, BASE)))
    folder = tmp_path / "mtx"
    folder.mkdir()
    for key in ("K", "M", "D"):
        scipy.io.mmwrite(folder / f"{key}.mtx", getattr(mesh_model, key).tocoo())
    for i, load in enumerate(mesh_model.loads):
        np.savetxt(folder / f"f{i}.txt", load.vector)
    c = mesh_model.contact
    first = 1  # Matlab numbering in the case file
    text = f"""\
[model]
type = "matrices"
K = "K.mtx"
M = "M.mtx"
D = "D.mtx"
first_dof = {first}

[[loads]]
file = "f0.txt"

[[loads]]
file = "f1.txt"
waveform = "sin"

[contact]
normal_dofs = {(c.dofs[:, 1] + first).tolist()}
tangential_dofs = {(c.dofs[:, 0] + first).tolist()}
normal_sign = -1
area = {c.area.tolist()}
mu = 0.3

[observed]
Pe = {(mesh_model.observed[0].dofs + first).tolist()}

[analysis]
type = "frf"
f_min = 10.0
f_max = 1e5
"""
    model = build_model(load_case(write(folder, text)))
    np.testing.assert_array_equal(model.contact.dofs, c.dofs[:, ::-1])  # [normal, tangent]
    np.testing.assert_array_equal(model.observed[0].dofs, mesh_model.observed[0].dofs)
    freqs = [100.0, 3e4]
    for interface in ("sliding", "stuck"):
        a = linear.frf(mesh_model, freqs, interface=interface).observed["Pe"]
        b = linear.frf(model, freqs, interface=interface).observed["Pe"]
        np.testing.assert_allclose(b, a, rtol=1e-9)


def test_note_when_an_observed_point_is_not_a_node(tmp_path):
    from fretwear.io.case import observed_notes

    case = load_case(write(tmp_path, BASE))
    assert observed_notes(case, build_model(case)) == []  # ny = 2: a node at h/2
    case = load_case(write(tmp_path, BASE.replace("ny = 2", "ny = 3")))
    assert observed_notes(case, build_model(case)) == [
        "note: observed.Pe = [0.1, 0.005] is not a mesh node; reporting the nearest node, "
        "at (0.1, 0.00333333)"
    ]


def test_two_interfaces_in_one_case(tmp_path):
    """Two [[contact]] blocks (the bottom on a rigid flat, the top under a rigid plate) build
    one contact record with each node's interface and friction coefficient; a repeated name
    and a key of node-to-node contact without a partner are refused with one line."""
    two = BASE.replace('''[contact]
boundary = "bottom"
normal = [0.0, -1.0]
mu = 0.3
wear_coefficient = 1e-11
''', '''[[contact]]
boundary = "bottom"
mu = 0.3
name = "flat"

[[contact]]
boundary = "top"
mu = 0.5
name = "plate"
''').replace('''[[loads]]
boundary = "top"
pressure = 1e4
''', "")
    model = build_model(load_case(write(tmp_path, two)))
    c = model.contact
    assert c.names() == ["flat", "plate"]
    np.testing.assert_array_equal(c.mu_nodes(), [0.3] * 7 + [0.5] * 7)
    np.testing.assert_array_equal(c.frame[c.interface_index() == 1, 0],
                                  [[0.0, 1.0]] * 7)  # the top's outward normal
    msg = error_of(tmp_path, two.replace('name = "plate"', 'name = "flat"'), build=True)
    assert msg == "contact: two interfaces are named 'flat'; expected distinct names"
    msg = error_of(tmp_path, two.replace('name = "plate"', 'name = "plate"\ntolerance = 1e-6'))
    assert msg == "[contact[2]]: 'tolerance' needs 'partner'"


def test_materials_of_bodies(tmp_path):
    """[materials.<body>] on the damper example's mesh (three bodies): the damper in steel
    gives the stiffness of the one-material model (the same elements assembled body by
    body, to rounding); the damper in a material twice as stiff changes only the damper's
    rows; an unknown body is named."""
    import shutil

    from fretwear.examples import EXAMPLES_DIR

    shutil.copy(EXAMPLES_DIR / "platform-damper.msh", tmp_path)
    text = (EXAMPLES_DIR / "platform-damper-frf.toml").read_text()
    one = build_model(load_case(write(tmp_path, text)))
    steel = "\n[materials.damper]\nE = 210e9\nnu = 0.3\nrho = 7800.0\n"
    head, tail = text.split("[damping]", 1)
    same = build_model(load_case(write(tmp_path, head + steel + "\n[damping]" + tail)))
    scale = abs(one.K).max()
    assert abs(same.K - one.K).max() <= 1e-12 * scale
    stiff = build_model(load_case(write(tmp_path, head + steel.replace("210e9", "420e9")
                                        + "\n[damping]" + tail)))
    changed = np.unique((abs(stiff.K - one.K) > 1e-9 * scale).nonzero()[0]) // 2
    damper = one.mesh.node_sets["damper"]
    assert changed.size and np.all(np.isin(changed, damper))
    msg = error_of(tmp_path, head + steel.replace("damper]", "dampr]") + "\n[damping]" + tail,
                   build=True)
    assert msg.startswith('materials.dampr = "dampr": expected one of')
# --- connectors: contact stiffness and prescribed normal loads ------------------------------
def test_connector_keys_of_a_mesh_case(tmp_path):
    """Stiffness per unit area becomes each node's stiffness times its area; a prescribed
    pressure becomes each node's normal force times its area (the nodal areas are the
    model's own, so the comparison is with the interface's area field)."""
    text = BASE.replace("wear_coefficient = 1e-11", "wear_coefficient = 1e-11\n"
                        "normal_stiffness = 1e12\ntangential_stiffness = 5e11\n"
                        "normal_pressure = 2e6\nnormal_waveform = \"cos\"")
    c = build_model(load_case(write(tmp_path, text))).contact
    np.testing.assert_allclose(c.kn, 1e12 * c.area, rtol=1e-15)
    np.testing.assert_allclose(c.kt, 5e11 * c.area, rtol=1e-15)
    np.testing.assert_allclose(c.normal_load.vector, 2e6 * c.area, rtol=1e-15)
    assert c.normal_load.waveform == "cos"
    rigid = build_model(load_case(write(tmp_path, BASE))).contact
    assert rigid.kn is None and rigid.kt is None and rigid.normal_load is None
    assert not rigid.has_connectors


def test_jenkins_oscillator_from_a_matrices_case(tmp_path):
    """The issue's Jenkins oscillator (one DOF, no normal DOF, kt in series with the slider
    under a prescribed normal force) from a case file equals the one built in Python."""
    folder = tmp_path / "m"
    folder.mkdir()
    scipy.io.mmwrite(folder / "K.mtx", sp.coo_matrix(np.array([[1.0]])))
    scipy.io.mmwrite(folder / "M.mtx", sp.coo_matrix(np.array([[1.0]])))
    (folder / "f.txt").write_text("0.2\n")
    text = ('[model]\ntype = "matrices"\nK = "K.mtx"\nM = "M.mtx"\n'
            '[[loads]]\nfile = "f.txt"\nwaveform = "cos"\n'
            '[contact]\ntangential_dofs = [0]\nmu = 0.5\nnormal_load = 1.0\nkt = 0.5\n'
            '[analysis]\ntype = "modes"\n')
    model = build_model(load_case(write(folder, text)))
    c = model.contact
    assert c.prescribed_nodes().tolist() == [True]
    np.testing.assert_array_equal(c.kt, [0.5])
    assert c.kn is None
    assert model.ndof == 2  # the added normal DOF, held at zero by its load


def test_matrices_contact_needs_normal_dofs_or_a_normal_load(tmp_path):
    folder = matrices_folder(tmp_path)
    msg = error_of(folder, MATRICES.replace("normal_dofs = [0, 2]\n", ""))
    assert msg.startswith("[contact]: missing 'normal_dofs'")
    msg = error_of(folder, MATRICES.replace("mu = 0.2", "mu = 0.2\nkt = 0.0"))
    assert msg.startswith("contact.kt = 0.0: expected")


@pytest.mark.parametrize("line, message", [
    ("normal_load = -1.0", "contact.normal_load = -1.0: expected a number >= 0"),
    ("normal_load = [1.0, -2.0]", "contact.normal_load"),
])
def test_prescribed_normal_load_in_tension_is_refused(tmp_path, line, message):
    """A prescribed normal load is compressive: a negative one (tension, a slip threshold
    mu N < 0 that the friction law cannot mean) was accepted silently; now one InputError
    names the key (the same rule holds for a mesh contact's normal_pressure)."""
    folder = tmp_path / "m"
    folder.mkdir()
    scipy.io.mmwrite(folder / "K.mtx", sp.coo_matrix(np.eye(2)))
    scipy.io.mmwrite(folder / "M.mtx", sp.coo_matrix(np.eye(2)))
    text = ('[model]\ntype = "matrices"\nK = "K.mtx"\nM = "M.mtx"\n'
            f'[contact]\ntangential_dofs = [0, 1]\nmu = 0.5\n{line}\nkt = 0.5\n'
            '[analysis]\ntype = "modes"\n')
    with pytest.raises(InputError, match=message.replace("[", r"\[")) as err:
        load_case(write(folder, text))
    assert "\n" not in str(err.value)


LAP = """
title = "2D lap joint of two plates meshed apart"

[model]
type = "blocks"
thickness = 0.01

[[model.blocks]]
name = "lower"
size = [0.04, 0.004]
elements = [16, 2]

[[model.blocks]]
name = "upper"
size = [0.04, 0.004]
elements = [12, 2]
origin = [0.02, 0.004]

[material]
E = 210e9
nu = 0.3
rho = 7800.0

[materials.upper]
E = 70e9
nu = 0.33
rho = 2700.0

[[fixed]]
at = "lower.bottom"

[[springs]]
at = "upper.right"
direction = "x"
stiffness = 1e7

[[springs]]
at = "upper.right"
direction = "y"
stiffness = 1e8

[[loads]]
boundary = "upper.top"
region = {x = [0.02, 0.04]}
pressure = 2e7

[[contact]]
boundary = "upper.bottom"
region = {x = [0.02, 0.04]}
partner = "lower.top"
mu = 0.3

[analysis]
type = "periodic"
frequency = 500.0
"""


def test_two_block_lap_joint_in_a_case_file(tmp_path):
    """`type = "blocks"`: two structured plates placed apart and joined, the upper one in its
    own material; the contact and the pressure on the overlap only (`region`), paired by
    mortar (the nodes do not match). Checked against closed forms: the node count of the
    overlap (7 nodes of 3.33 mm elements), its area (20 mm x 10 mm), the pressure's resultant
    (p x that area) and the mass of the upper plate (its own density: 2700 / 7800 of the
    steel plate's)."""
    model = build_model(load_case(write(tmp_path, LAP)))
    c = model.contact
    assert c.n_nodes == 7 and c.segments is not None
    np.testing.assert_allclose(c.area.sum(), 0.02 * 0.01, rtol=1e-14)
    f = model.loads[0].vector.reshape(-1, 2)
    np.testing.assert_allclose(f[:, 1].sum(), -2e7 * 0.02 * 0.01, rtol=1e-14)
    assert {"lower", "upper", "upper.top_left"} <= set(model.mesh.node_sets)
    steel = build_model(load_case(write(tmp_path, LAP.replace("rho = 2700.0",
                                                              "rho = 7800.0"))))
    upper = np.asarray(model.mesh.node_sets["upper"])
    dofs = (2 * upper[:, None] + np.arange(2)).ravel()
    np.testing.assert_allclose(model.M[dofs].sum() / steel.M[dofs].sum(), 2700 / 7800,
                               rtol=1e-14)


@pytest.mark.parametrize("change, message", [
    (("elements = [12, 2]", "elements = [12, 2, 1]"),
     "model.blocks[2].elements = [12, 2, 1]: expected 2 components, like size"),
    (('size = [0.04, 0.004]\nelements = [12, 2]\norigin = [0.02, 0.004]',
      'size = [0.04, 0.004, 0.01]\nelements = [12, 2, 1]\norigin = [0.02, 0.004, 0.0]'),
     "model.blocks = [\"lower\", \"upper\"]: expected blocks of one dimension (all 2D sizes "
     "or all 3D)"),
    (("region = {x = [0.02, 0.04]}\npartner", "region = {x = [0.04, 0.02]}\npartner"),
     "contact[1].region.x = [0.04, 0.02]: expected a range [lo, hi] with lo <= hi"),
    (("region = {x = [0.02, 0.04]}\npartner", "region = {w = [0.02, 0.04]}\npartner"),
     "contact[1].region: key 'w' is not valid; expected axes \"x\", \"y\", \"z\""),
    (('partner = "lower.top"', 'partner = "lower.top"\npairing = "mortar-ish"'),
     "contact[1].pairing = \"mortar-ish\": expected one of \"auto\", \"node-to-node\", "
     "\"mortar\", \"node-to-segment\" (did you mean \"mortar\"?)"),
])
def test_bad_joint_keys_get_one_line(tmp_path, change, message):
    assert LAP.replace(*change) != LAP
    assert error_of(tmp_path, LAP.replace(*change), build=True) == message


def test_legal_but_unusual_magnitudes_are_named(tmp_path):
    """E = 210 (Pa: steel's modulus in GPa written as Pa), a density in g/cm^3 and mu = 5 run,
    each with one warning naming the key; the shipped beam's values give none (the ranges
    of fretwear.limits.USUAL hold every shipped example)."""
    from fretwear.io.case import unusual_notes

    assert unusual_notes(load_case(write(tmp_path, BASE))) == []
    text = (BASE.replace("E = 210e9", "E = 210").replace("rho = 7800.0", "rho = 7.8")
            .replace("mu = 0.3", "mu = 5.0"))
    notes = unusual_notes(load_case(write(tmp_path, text)))
    assert [n.split(" = ")[0] for n in notes] == ["warning: material.E", "warning: material.rho",
                                                "warning: contact.mu"]
    assert notes[0].startswith("warning: material.E = 210 Pa is below the usual range")
    assert notes[0].endswith("a unit mistake?")


def test_shipped_examples_have_no_unusual_magnitudes():
    from fretwear.examples import EXAMPLES_DIR
    from fretwear.io.case import unusual_notes

    for path in sorted(EXAMPLES_DIR.glob("*.toml")):
        assert unusual_notes(load_case(path)) == [], path.name


def test_unusual_values_of_a_case_are_said_once(tmp_path, recwarn):
    """A case file's unusual value is a line naming its key (above), not also a Python
    warning with a source line."""
    build_model(load_case(write(tmp_path, BASE.replace("E = 210e9", "E = 210"))))
    assert not [w for w in recwarn if "usual range" in str(w.message)]
