"""Linear models: FE meshes (scikit-fem) or user matrices, loads, springs, contact interface."""

from fretwear.model.core import ContactInterface, Load, Mesh, Model, ObservedPoint

__all__ = ["ContactInterface", "Load", "Mesh", "Model", "ObservedPoint"]
