"""The checks of the model records handed to the public API (fretwear.model.checks): every
field of a Model, its contact, loads and observed points, a Mesh and a sector, refused in one
InputError naming the field, never a deep error; the records fretwear builds pass.

The reference is the record itself: each test breaks one field of a valid record in the way
a hostile user would (a string, NaN, a wrong shape, a DOF out of range) and expects the
message to name that field. No solve runs."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.sparse as sp

import fretwear as fw
from fretwear.errors import InputError
from fretwear.model.checks import check_mesh, check_model, check_sector, model_argument


@pytest.fixture(scope="module")
def model():
    return fw.from_matrices(np.diag([3e6, 1e6, 5e5]), np.diag([0.3, 0.1, 0.05]),
                            contact=fw.ContactDofs(normal_dofs=[1], tangential_dofs=[2], mu=0.3),
                            loads=[fw.Load(np.array([1.0, 0.0, 0.0]), "cos", name="F")],
                            observed={"tip": [0]})


def test_models_built_by_fretwear_pass(model):
    """A model of user matrices, a mesh model and a sector pass unchanged."""
    assert check_model(model) is model
    mesh = fw.rectangle(0.02, 0.01, 4, 2)
    check_mesh(mesh)
    check_model(fw.from_mesh(mesh, fw.Material(210e9, 0.3, 7800.0), thickness=0.01,
                             supports=[fw.Spring("top_left", "x", 1e7)],
                             contact=fw.ContactSpec("bottom", mu=0.3)))
    check_sector(fw.lumped_blisk(4))


@pytest.mark.parametrize("field, value, named", [
    ("K", "1", "model.K"),
    ("K", sp.csr_matrix(np.diag([1.0, math.nan, 1.0])), "model.K"),
    ("M", sp.csr_matrix(np.eye(2)), "model.M"),
    ("loads", [fw.Load(np.ones(2), "cos")], "model.loads[0].vector"),
    ("loads", [fw.Load(np.ones(3), "square")], "model.loads[0].waveform"),
    ("observed", [fw.ObservedPoint("p", np.array([7]), np.zeros(1))], "model.observed[0].dofs"),
    ("fixed_dofs", np.array([-1]), "model.fixed_dofs"),
    ("contact", None, "model.contact"),
])
def test_a_broken_model_field_is_named(model, field, value, named):
    with pytest.raises(InputError) as err:
        check_model(dataclasses.replace(model, **{field: value}))
    assert named in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("field, value", [
    ("dofs", np.array([[5, 2]])), ("gap", np.array([math.nan])), ("area", np.array([0.0])),
    ("mu", -1.0), ("frame", np.ones((1, 3, 3))), ("wear_coefficient", math.inf),
])
def test_a_broken_contact_field_is_named(model, field, value):
    contact = dataclasses.replace(model.contact, **{field: value})
    with pytest.raises(InputError, match=f"model.contact.{field}"):
        check_model(dataclasses.replace(model, contact=contact))


def test_a_broken_mesh_and_a_wrong_argument_kind():
    """A mesh with a NaN point or a cell of a node that does not exist, and a public
    function handed None for its model or its sector (an ArgumentTypeError, which is also a
    TypeError)."""
    mesh = fw.rectangle(0.02, 0.01, 4, 2)
    points = mesh.points.copy()
    points[0, 0] = math.nan
    with pytest.raises(InputError, match="mesh.points"):
        check_mesh(dataclasses.replace(mesh, points=points))
    with pytest.raises(InputError, match="mesh.cells"):
        check_mesh(dataclasses.replace(mesh, cells=mesh.cells + 1000))

    @model_argument
    def f(model, sector=None):
        return "ran"

    with pytest.raises(TypeError, match="model = None"):
        f(None)
    with pytest.raises(InputError, match="sector = 3"):
        f(fw.lumped_blisk(4).model, sector=3)
