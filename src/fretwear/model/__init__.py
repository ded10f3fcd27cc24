"""Linear models: FE meshes (scikit-fem) or user matrices, loads, springs, contact interfaces."""

from fretwear.model.build import (
    ContactSpec,
    Damping,
    Material,
    NodalForce,
    Spring,
    Traction,
    from_mesh,
)
from fretwear.model.core import ContactInterface, Load, Mesh, Model, ObservedPoint
from fretwear.model.fem import assemble
from fretwear.model.interfaces import combine, relative_model
from fretwear.model.loads import (
    boundary_load,
    boundary_measure,
    nodal_areas,
    nodal_force,
    resultant,
)
from fretwear.model.matrices import ContactDofs, from_matrices, read_matrix_market
from fretwear.model.mesh import box, join, rectangle, transformed
from fretwear.model.mesh import read as read_mesh
from fretwear.model.supports import check_supported, rigid_motion_check

__all__ = [
    "ContactDofs",
    "ContactInterface",
    "ContactSpec",
    "Damping",
    "Load",
    "Material",
    "Mesh",
    "Model",
    "NodalForce",
    "ObservedPoint",
    "Spring",
    "Traction",
    "assemble",
    "boundary_load",
    "boundary_measure",
    "box",
    "check_supported",
    "combine",
    "from_matrices",
    "from_mesh",
    "join",
    "nodal_areas",
    "nodal_force",
    "read_matrix_market",
    "read_mesh",
    "rectangle",
    "relative_model",
    "resultant",
    "rigid_motion_check",
    "transformed",
]
