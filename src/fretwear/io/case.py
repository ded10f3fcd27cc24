"""Case files: a TOML description of a model and an analysis, validated on load (SI units).

:func:`load_case` reads and validates a case file against the schema below (see
:mod:`fretwear.io.schema`); :func:`build_model` turns it into a :class:`~fretwear.model.core.Model`.
Every mistake (wrong value, wrong type, missing or unknown key, unknown boundary name) gives
one :class:`~fretwear.errors.InputError` naming the key path, e.g.
``material.nu = 0.5: expected a number in (-1, 0.5)``.

A model is either a finite element mesh (``model.type`` = ``"rectangle"``, ``"box"`` or
``"mesh"``) or user matrices (``"matrices"``); the sections that describe the interface,
the loads and the observed points differ between the two. The ``[analysis]`` table is
checked against the schema its analysis type registered in :mod:`fretwear.analyses.registry`.
The documentation ``docs/case-files.md`` is generated from these schemas
(:func:`case_docs`, :func:`write_case_docs`).
"""

from __future__ import annotations

import dataclasses
import math
import tomllib
import warnings
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fretwear.errors import InputError
from fretwear.io.schema import (
    MISSING,
    AnyOf,
    Choice,
    Context,
    Dict,
    Field,
    FilePath,
    Flag,
    Integer,
    ListOf,
    Number,
    Table,
    TableList,
    Text,
    Variant,
    Vector,
    exactly_one,
    fail,
    join,
    non_zero,
    render_table,
    requires,
    show,
    suggest,
    table_label,
    unused_keys,
)
from fretwear.limits import LOSS_FACTOR_MAX, UnusualValueWarning, unusual
from fretwear.model.core import WAVEFORMS
from fretwear.model.supports import Unsupported

AXES = ("x", "y", "z")
FIGURE_FORMATS = ("png", "pdf", "svg")


# --- rules across keys ------------------------------------------------------------------
def _fourier_coefficients(out, path):
    """Rule: ``coefficients`` is given exactly when ``waveform = "fourier"``."""
    if out.get("waveform") == "fourier" and not out.get("coefficients"):
        raise InputError(
            f"{table_label(path)}: waveform = \"fourier\" needs coefficients = "
            '{"1" = [a1, b1], ...}'
        )
    if "coefficients" in out and out.get("waveform") != "fourier":
        raise InputError(
            f"{table_label(path)}: 'coefficients' is only used with waveform = \"fourier\" "
            f"(waveform = {show(out.get('waveform'))})"
        )


# --- shared pieces ----------------------------------------------------------------------
_POSITIVE = Number(lo=0, lo_open=True)
_NON_NEG = Number(lo=0)
_DOF = Integer(lo=0)
_WAVEFORM = Field(
    Text(WAVEFORMS),
    '"constant" is a static load; "cos", "sin", "triangle" (amplitude 1, rising like sin) and '
    '"fourier" (with `coefficients`) are periodic in tau = omega t',
    default="constant",
)
_COEFFICIENTS = Field(
    Dict(Vector((2,)), key_ok=lambda k: str(k).isdigit(), key_doc='harmonic numbers "0", "1", ...'),
    'waveform = "fourier" only: g(tau) = sum over n of a_n cos(n tau) + b_n sin(n tau), written '
    '{"1" = [a1, b1], "3" = [a3, b3]} ("0" gives the mean; its b is ignored)',
)
_LOAD_NAME = Field(Text(), "label used in output")
_MU = Field(_NON_NEG, "Coulomb friction coefficient", required=True, unit="-")
#: the analyses that wear the interface (read its wear coefficients)
WEAR_ANALYSES = ("wear", "incremental-wear", "worn-state")
_WEAR = Field(_NON_NEG, "Archard wear coefficient k_w (paper eq. 29)", default=0.0, unit="1/Pa",
              used_by=WEAR_ANALYSES)
_CONTACT_NAME = Field(Text(), "label of the interface in output", default="contact")
_CONTACT_K = Number(lo=0, lo_open=True, hi=1e20, allow_inf=True)


def _waveform_needs(load_key: str):
    """Rule: a ``normal_waveform`` other than the default shapes ``load_key`` only: without it,
    the waveform would be ignored."""

    def rule(out: dict, path: str) -> None:
        if out.get("normal_waveform", "constant") != "constant" and load_key not in out:
            raise InputError(f"{table_label(path)}: 'normal_waveform' = "
                             f"{out['normal_waveform']!r} needs {load_key!r} (the waveform "
                             "shapes a prescribed normal load; without it it would be ignored)")

    return rule


_NORMAL_WAVEFORM = Field(Text(tuple(w for w in WAVEFORMS if w != "fourier")),
                         "time history g(omega t) of the prescribed normal load"
                         ' (as loads\' `waveform`; "fourier" is not offered here)',
                         default="constant")
_THICKNESS = Field(
    _POSITIVE,
    "out-of-plane width of a 2D (plane strain) model; the default 1 m gives results per metre "
    "of width",
    default=1.0,
    unit="m",
)

# --- [model] --------------------------------------------------------------------------
FE_FORMATS = ("dmig", "op4", "abaqus", "abaqus-matrix-input", "ansys-full", "matrix-market",
              "harwell-boeing")
_ONE_FILE = ("dmig", "op4", "abaqus", "ansys-full")


def fe_mode(model: Mapping) -> bool:
    """A ``matrices`` model whose rows are named by node id (``format`` or ``dofmap`` given)."""
    return model.get("type") == "matrices" and ("format" in model or "dofmap" in model)


def _matrices_files(out: dict, path: str) -> None:
    """Rules: M is given unless one file holds every matrix; DOF-numbering keys only without
    node ids."""
    fmt = out.get("format", "matrix-market")
    if fmt in _ONE_FILE:
        for key in ("M", "C", "D"):
            if key in out:
                raise InputError(f"{join(path, key)}: format {fmt!r} holds every matrix in "
                                 "`K`; remove this key")
    elif "M" not in out:
        raise InputError(f"missing required key {join(path, 'M')!r} (mass matrix file)")
    if ("format" in out or "dofmap" in out) and out.get("fixed_dofs"):
        raise InputError(f"{join(path, 'fixed_dofs')}: the rows are named by node ids "
                         "(format/dofmap given): hold nodes with [[fixed]] blocks")


BLOCK = Table(
    {
        "name": Field(Text(), "the body's name (prefix of its boundaries and node sets)",
                      required=True),
        "size": Field(ListOf(_POSITIVE, sizes=(2, 3)), "[length, height] of a 2D rectangle "
                      "of 4-node quadrilaterals, or [lx, ly, lz] of a 3D box of 8-node "
                      "hexahedra", required=True, unit="m"),
        "elements": Field(ListOf(Integer(lo=1), sizes=(2, 3)), "number of elements along "
                          "each axis", required=True),
        "origin": Field(Vector(), "position of the corner of least coordinates", unit="m"),
    },
    checks=(lambda out, path: _block_sizes(out, path),),
    doc="A structured block: a rectangle (2D) or a box (3D) with the boundaries of "
    "`type = \"rectangle\"` or `\"box\"`, placed at `origin`.",
)


def _block_sizes(out, path):
    """Rule: ``size``, ``elements`` and ``origin`` have one component per axis."""
    d = len(out["size"])
    for key in ("elements", "origin"):
        if key in out and len(out[key]) != d:
            fail(join(path, key), out[key], f"{d} components, like size")


MODEL_TYPES = {
    "rectangle": Table(
        {
            "length": Field(_POSITIVE, "size along x", required=True, unit="m"),
            "height": Field(_POSITIVE, "size along y", required=True, unit="m"),
            "nx": Field(Integer(lo=1), "number of elements along x", required=True),
            "ny": Field(Integer(lo=1), "number of elements along y", required=True),
            "thickness": _THICKNESS,
        },
        doc="A 2D plane strain rectangle [0, length] x [0, height] of 4-node quadrilaterals. "
        'Boundaries (and node sets): "bottom", "top", "left", "right"; one-node sets '
        '"bottom_left", "bottom_right", "top_left", "top_right".',
    ),
    "box": Table(
        {
            "lx": Field(_POSITIVE, "size along x", required=True, unit="m"),
            "ly": Field(_POSITIVE, "size along y", required=True, unit="m"),
            "lz": Field(_POSITIVE, "size along z", required=True, unit="m"),
            "nx": Field(Integer(lo=1), "number of elements along x", required=True),
            "ny": Field(Integer(lo=1), "number of elements along y", required=True),
            "nz": Field(Integer(lo=1), "number of elements along z", required=True),
        },
        doc="A 3D box [0, lx] x [0, ly] x [0, lz] of 8-node hexahedra. Boundaries (and node "
        'sets): "xmin", "xmax", "ymin", "ymax", "zmin", "zmax".',
    ),
    "blocks": Table(
        {
            "blocks": Field(TableList(BLOCK), "the bodies, one `[[model.blocks]]` each",
                            required=True),
            "thickness": _THICKNESS,
        },
        doc="Several structured bodies placed side by side, each meshed on its own (the nodes "
        "of two faces that touch need not match: `[[contact]]` `pairing`). Boundaries and "
        'node sets are named "<block>.<name>" (e.g. "upper.bottom", "upper.top_left"), and '
        "each block's nodes form a node set named after it, so `[materials.<block>]` gives "
        "a block its own material.",
    ),
    "mesh": Table(
        {
            "file": Field(FilePath(), "mesh file read with meshio (Gmsh .msh v2.2/v4.1, ...)",
                          required=True),
            "thickness": _THICKNESS,
        },
        doc="A mesh file with linear cells (triangle or quad in the plane z = 0: 2D plane "
        "strain; tetra or hexahedron: 3D). Named groups (Gmsh physical groups) of facets "
        "become boundaries, named groups of points become node sets.",
    ),
    "matrices": Table(
        {
            "K": Field(FilePath(), "stiffness matrix (Matrix Market .mtx by default), or the "
                       "one file holding every matrix (`format` dmig, op4, abaqus, ansys-full)",
                       required=True, unit="N/m"),
            "M": Field(FilePath(), "mass matrix (Matrix Market .mtx by default); not with a "
                       "one-file `format`", unit="kg"),
            "C": Field(FilePath(), "viscous damping matrix (Matrix Market .mtx)", unit="N s/m"),
            "D": Field(FilePath(), "hysteretic damping matrix (Matrix Market .mtx): adds i D "
                       "to the dynamic stiffness of harmonics n >= 1", unit="N/m"),
            "fixed_dofs": Field(ListOf(_DOF, unique=True), "DOFs held at zero (Dirichlet; "
                                "DOF numbering only: with node ids use `[[fixed]]`)",
                                default=[]),
            "first_dof": Field(Choice((0, 1)), "number of the first DOF in every DOF list "
                               "of this case file: 0 (Python) or 1 (Matlab, Matrix Market rows)",
                               default=0),
            "format": Field(Text(FE_FORMATS), "the FE code's file format; given (or with "
                            "`dofmap`), every section names nodes by their ids: "
                            '"dmig" (Nastran punch or bulk data), "op4" (ASCII), "abaqus" '
                            '(*SUBSTRUCTURE MATRIX OUTPUT .mtx), "abaqus-matrix-input" '
                            '(*MATRIX GENERATE files), "ansys-full" (needs fretwear[ansys]), '
                            '"harwell-boeing" (ANSYS HBMAT), "matrix-market"'),
            "dofmap": Field(FilePath(), "the node id and component (1-6; 0 a scalar point) of "
                            "each row, one `node component` line a row, or ANSYS's .mapping "
                            "file: for op4, matrix-market and harwell-boeing"),
            "nodes": Field(FilePath(), "the mesh the matrices came from (.bdf, .inp, .cdb): "
                           "node coordinates (output) and node sets (names in sections)"),
            "names": Field(Dict(Text(), key_ok=lambda k: k in ("K", "M", "C", "D"),
                                key_doc='"K", "M", "C", "D"'),
                           "DMIG or OP4 matrix names, e.g. {K = \"KGG\", M = \"MGG\"} "
                           "(default KAAX, MAAX, BAAX, K4AX as EXTSEOUT punches them)"),
        },
        checks=(_matrices_files,),
        doc="User matrices: DOF numbers are row numbers of K (counted from `first_dof`), or, "
        "with `format` or `dofmap`, matrices exported by an FE code whose rows are named by "
        "node id and component: then `[[contact]]`, `[[loads]]`, `[[fixed]]` and `[observed]` "
        "name nodes by id or node set (the `(FE matrices)` sections below).",
    ),
}
MODEL = Variant(MODEL_TYPES, key_doc="kind of model")

# --- mesh models ----------------------------------------------------------------------
MATERIAL = Table(
    {
        "E": Field(_POSITIVE, "Young's modulus", required=True, unit="Pa"),
        "nu": Field(Number(lo=-1, hi=0.5, lo_open=True, hi_open=True), "Poisson's ratio",
                    required=True, unit="-"),
        "rho": Field(_NON_NEG, "density (0: no inertia; modes and FRFs need rho > 0)",
                     default=0.0, unit="kg/m^3"),
    },
    doc="Isotropic linear elastic material.",
)
DAMPING = Table(
    {
        "loss_factor": Field(Number(lo=0, hi=LOSS_FACTOR_MAX), "hysteretic loss factor eta: "
                             "D = eta K on harmonics n >= 1 (no static part; real materials "
                             "stay below 2)",
                             default=0.0, unit="-"),
        "rayleigh_mass": Field(Number(lo=0, hi=1e9), "viscous Rayleigh coefficient a in "
                               "C = a M + b K (up to 1e9: beyond, the damping swamps everything)",
                               default=0.0, unit="1/s"),
        "rayleigh_stiffness": Field(Number(lo=0, hi=1.0), "viscous Rayleigh coefficient b in "
                                    "C = a M + b K (up to 1 s: real structures are below 1e-3)",
                                    default=0.0, unit="s"),
    },
    doc="Structural damping (optional; all zero by default). For a `matrices` model the "
    "Rayleigh part is added to the matrix C and the loss factor to the matrix D.",
)
_AT = AnyOf((Text(), Vector()))
REGION = Field(Dict(ListOf(Number(), sizes=(2,)), key_ok=lambda k: k in AXES,
                    key_doc='axes "x", "y", "z"'),
               "part of the boundary or node set: coordinate ranges, e.g. {x = [0.0, 0.01]} "
               "(a facet belongs when all its nodes lie in the ranges; unnamed axes are "
               "unbounded)", unit="m")


def _ranges(out, path):
    """Rule: each range of ``region`` is ``[lo, hi]`` with ``lo <= hi``."""
    for axis, (lo, hi) in (out.get("region") or {}).items():
        if lo > hi:
            fail(join(join(path, "region"), axis), [lo, hi], "a range [lo, hi] with lo <= hi")


SPRING = Table(
    {
        "at": Field(_AT, "node set or boundary name, or the coordinates [x, y(, z)] of a node",
                    required=True, unit="m"),
        "direction": Field(AnyOf((Text(AXES), Vector())), '"x", "y", "z" or a vector',
                           required=True),
        "stiffness": Field(Number(lo=0, lo_open=True, hi=1e20, allow_inf=True),
                           "total stiffness to the ground, shared equally by the nodes of `at`; "
                           "inf holds them (Dirichlet; axis directions only); finite values up "
                           "to 1e20 (beyond, use inf: the matrices would lose all precision)",
                           required=True, unit="N/m"),
        "region": REGION,
    },
    checks=(non_zero("direction"), _ranges),
    doc="Grounded springs, one `[[springs]]` block each.",
)
FIXED = Table(
    {
        "at": Field(_AT, "node set or boundary name, or the coordinates [x, y(, z)] of a node",
                    required=True, unit="m"),
        "direction": Field(Text(AXES + ("all",)), "the component held at zero", default="all"),
    },
    doc="Dirichlet conditions (held displacement components), one `[[fixed]]` block each.",
)
LOAD_MESH = Table(
    {
        "boundary": Field(Text(), "boundary carrying a distributed load"),
        "pressure": Field(Number(), "pressure on the boundary, positive pushing on the face "
                          "(along the inward normal)", unit="Pa"),
        "traction": Field(Vector(), "traction vector on the boundary", unit="Pa"),
        "at": Field(_AT, "nodal force: node set name or coordinates of a node", unit="m"),
        "force": Field(Vector(), "total force vector, shared equally by the nodes of `at`",
                       unit="N"),
        "waveform": _WAVEFORM,
        "coefficients": _COEFFICIENTS,
        "name": _LOAD_NAME,
        "region": REGION,
    },
    checks=(
        _ranges,
        exactly_one("pressure", "traction", "force"),
        requires("pressure", "boundary", excludes="at"),
        requires("traction", "boundary", excludes="at"),
        requires("force", "at", excludes="boundary"),
        _fourier_coefficients,
    ),
    doc="Loads `F(t) = vector * g(omega t)`, one `[[loads]]` block each: `boundary` with "
    "`pressure` or `traction`, or `at` with `force`.",
)
CONTACT_MESH = Table(
    {
        "boundary": Field(Text(), "boundary in contact with the rigid obstacle, or with the "
                          "`partner` boundary of a second body", required=True),
        "mu": _MU,
        "normal": Field(Vector(), "one normal for every node, pointing from the structure into "
                        "the obstacle (default: the outward normal of the boundary; on a "
                        "curved or multi-flank boundary each node's own, averaged from the "
                        "facets around it)"),
        "tangent": Field(Vector(), "3D: first tangential direction (default: chosen from the "
                         "normal)"),
        "gap": Field(Number(), "initial normal gap (>= 0 open, < 0 interference)", default=0.0,
                     unit="m"),
        "wear_coefficient": _WEAR,
        "name": _CONTACT_NAME,
        "partner": Field(Text(), "two-body contact: the boundary of the second body that "
                         "`boundary` touches (its nodes at the same positions, within "
                         "`tolerance`, or its facets: `pairing`); the contact law acts on "
                         "their relative displacement"),
        "tolerance": Field(_NON_NEG, "largest distance between a node and its partner "
                           "(default 1e-6 times the model size between paired nodes; a tenth "
                           "of the partner's longest facet edge to the partner face for "
                           "mortar and node-to-segment pairs)", unit="m"),
        "partner_wear_coefficient": Field(_NON_NEG, "Archard wear coefficient of the "
                                          "partner's surface (the gap opens by the sum of both "
                                          "worn depths; default 0)", unit="1/Pa",
                                          used_by=WEAR_ANALYSES),
        "normal_stiffness": Field(_CONTACT_K, "normal contact stiffness per unit area, in "
                                  "series with the contact law (a property of the interface, "
                                  "not a regularisation; inf: rigid)", default=math.inf,
                                  unit="Pa/m"),
        "tangential_stiffness": Field(_CONTACT_K, "tangential contact stiffness per unit area "
                                      "(a finite value makes each node a Jenkins element; "
                                      "inf: rigid)", default=math.inf, unit="Pa/m"),
        "normal_pressure": Field(_NON_NEG, "friction under a prescribed normal load: the "
                                 "normal pressure p >= 0, compressive (each node carries p x "
                                 "its area x g(omega t), whatever its normal motion; slip "
                                 "threshold mu times that); absent: unilateral contact",
                                 unit="Pa"),
        "normal_waveform": _NORMAL_WAVEFORM,
        "pairing": Field(Text(("auto", "node-to-node", "mortar", "node-to-segment")),
                         "how the nodes of `boundary` meet the `partner` boundary: "
                         '"node-to-node" (matching nodes), "mortar" (non-matching meshes: '
                         "each node's area-weighted relative displacement, exact for a "
                         'uniform pressure and slip), "node-to-segment" (each node against '
                         'the closest point of a partner facet) or "auto": node-to-node when '
                         "every node has a partner node within `tolerance`, else mortar",
                         default="auto"),
        "region": REGION,
    },
    checks=(non_zero("normal", "tangent"), _ranges,
            requires("partner_wear_coefficient", "partner"),
            requires("tolerance", "partner"), _waveform_needs("normal_pressure")),
    doc="A frictional interface: the nodes of one boundary (or of its `region`) against a "
    "rigid obstacle, or against a second body (`partner`): its matching nodes, or its facets "
    "when the meshes do not match (`pairing`). Several interfaces: one `[[contact]]` block "
    "each, with distinct names (a node belongs to one interface).",
)
OBSERVED_MESH = Dict(AnyOf((Vector(), Text())), key_doc="point names")


def _mistuning_rules(out: dict, path: str) -> None:
    """Rules of ``[cyclic.mistuning]``: a draw has ``std`` and ``seed``; a kind is listed or
    drawn, not both."""
    if ("std" in out) != ("seed" in out):
        have, miss = ("std", "seed") if "std" in out else ("seed", "std")
        raise InputError(f"{table_label(path)}: {have} without {miss}; a random draw takes "
                         "both (std, seed)")
    drawn = out.get("draw", ["young"]) if "std" in out else []
    for kind in drawn:
        if kind in out:
            fail(join(path, kind), out[kind], f"no list: {kind} is drawn (draw = "
                 f"{drawn}); give its factors or draw it, not both")


MISTUNING = Table(
    {
        "young": Field(ListOf(_POSITIVE, non_empty=True), "factor on the stiffness (Young's "
                       "modulus) of each sector, sector 0 first: N numbers (1 = tuned)"),
        "mu": Field(ListOf(_POSITIVE, non_empty=True), "factor on the friction coefficients "
                    "of each sector's contact nodes: N numbers"),
        "wear": Field(ListOf(_POSITIVE, non_empty=True), "factor on the wear coefficients of "
                      "each sector's contact nodes (and of their partners): N numbers"),
        "std": Field(Number(lo=0, hi=0.5, hi_open=True), "a seeded random draw instead: "
                     "factors 1 + std z, z standard normal, of the kinds in `draw`", unit="-"),
        "seed": Field(Integer(lo=0), "seed of the random draw"),
        "draw": Field(ListOf(Text(("young", "mu", "wear")), non_empty=True, unique=True),
                      "the kinds drawn (with std and seed)", default=["young"]),
    },
    checks=(_mistuning_rules,),
    doc="A mistuned disk: the N sectors differ by a factor each on their stiffness, friction "
    "and wear coefficients (listed, or drawn with a seed). The analysis then runs on the whole "
    "disk assembled from the N sectors (fretwear.model.mistuning; the cyclic reduction no "
    "longer holds), every analysis type allowed, with every observed point on every sector "
    "(`<name>@<j>`, sector j). The results attributes `mistuned_sectors` (N), "
    "`engine_order` and `mistuning_young`, `mistuning_mu`, `mistuning_wear` (the factors) "
    "say which disk ran; a study over mistuning patterns (`[ensemble.perturb] "
    "\"cyclic.mistuning.young\" = {absolute = 0.02}` on a base of N ones) reports the "
    "amplification factor of each member and Whitehead's bound (docs/study.md).",
)


def _cyclic_rules(out: dict, path: str) -> None:
    """Rules of ``[cyclic]``: a unit axis, ``|engine_order| < sectors``, two boundaries."""
    axis = out.get("axis")
    if axis is not None and (len(axis) != 3 or abs(math.hypot(*axis) - 1.0) > 1e-9):
        fail(join(path, "axis"), axis, "a unit vector of 3 components (e.g. [0, 0, 1])")
    n, eo = out["sectors"], out["engine_order"]
    if abs(eo) >= n:
        fail(join(path, "engine_order"), eo,
             f"an integer with |engine_order| < sectors = {n} (engine order EO + {n} gives "
             f"the same sector response as EO: give it modulo {n})")
    if out["left"] == out["right"]:
        fail(join(path, "right"), out["right"], "a boundary other than left")


CENTRIFUGAL = Table(
    {
        "speed": Field(_NON_NEG, "rotation speed Omega", required=True, unit="rad/s"),
        "axis": Field(Vector((3,)), "unit vector of the rotation axis (default: that of "
                      "[cyclic], else [0, 0, 1]; 2D: [0, 0, 1] or [0, 0, -1])"),
        "point": Field(Vector(), "a point of the rotation axis (default: that of [cyclic], "
                       "else the origin)", unit="m"),
        "name": Field(Text(), "label of the load in output", default="centrifugal"),
    },
    checks=(non_zero("axis"),),
    doc="Centrifugal loading: the body force rho Omega^2 r (r: the distance vector from the "
    "axis) as a static load (waveform constant) added to the loads, on the undeformed "
    "geometry; spin softening, stress stiffening and Coriolis forces are left out "
    "(docs/theory.md, Centrifugal loading). Mesh models only.",
)

CYCLIC = Table(
    {
        "sectors": Field(Integer(lo=2), "number N of identical sectors of the disk",
                         required=True),
        "engine_order": Field(Integer(), "engine order EO of the travelling-wave excitation "
                              "(sector j lags sector j-1 by EO 2 pi / N; negative: the wave "
                              "travels the other way); |EO| < N", required=True),
        "axis": Field(Vector((3,)), "unit vector of the rotation axis (right-hand rule; 2D: "
                      "[0, 0, 1] or [0, 0, -1])", default=[0.0, 0.0, 1.0]),
        "point": Field(Vector(), "a point of the rotation axis", default=[0.0, 0.0, 0.0],
                       unit="m"),
        "left": Field(Text(), "boundary or node set of the left cyclic boundary (theta = 0)",
                      required=True),
        "right": Field(Text(), "boundary or node set of the right cyclic boundary: left turned "
                       "by +2 pi / N, node by node", required=True),
        "tolerance": Field(_NON_NEG, "largest distance between a turned left node and its "
                           "right node (default 1e-6 times the model size)", unit="m"),
        "mistuning": Field(MISTUNING, "the sectors made to differ (`[cyclic.mistuning]`): the "
                           "whole disk is assembled and run"),
        "neighbour": Field(Text(), "name of the `[[contact]]` block between neighbouring "
                           "sectors (a damper, a shroud): its `boundary` A touches the next "
                           "sector's copy of its `partner` B (B turned by +2 pi / N lands on "
                           "A)"),
    },
    checks=(_cyclic_rules,),
    doc="One sector of a cyclically symmetric disk of N sectors under a travelling wave of "
    "engine order EO (docs/theory.md, Cyclic symmetry): harmonic n lives in the harmonic "
    "index k = n EO mod N and the right boundary is the left one turned and phased. Mesh "
    "models only. Contact and observed nodes lie off the right boundary (it is the next "
    "sector's left one). The condensation is exact, one per harmonic index (`condensation` "
    "is not used). The results attributes `cyclic_sectors` (N), `engine_order` (EO) and "
    "`harmonic_index` (the index k of harmonics 0, 1, .., the highest kept) say which family "
    "each harmonic lives in; the wear is that of every sector (a tuned disk). Analyses: "
    "`cyclic-modes`, `periodic`, `sweep` (without `linear_references`) and `wear`; the others "
    "would leave the cyclic boundaries free and are refused.",
)

# --- matrices models ------------------------------------------------------------------
def _normal_dofs_or_load(out: dict, path: str) -> None:
    """Rule: ``normal_dofs`` is given unless ``normal_load`` is (friction under a known load)."""
    if "normal_dofs" not in out and "normal_load" not in out:
        raise InputError(f"{table_label(path)}: missing 'normal_dofs' (the normal DOF of each "
                         "contact node; or give normal_load for nodes without one)")



_DOFS_OR_FILE = AnyOf((ListOf(_DOF, non_empty=True, unique=True), FilePath()))
LOAD_MATRICES = Table(
    {
        "file": Field(FilePath(), "load vector (Matrix Market .mtx, or a text file of one "
                      "number per DOF)", required=True, unit="N"),
        "waveform": _WAVEFORM,
        "coefficients": _COEFFICIENTS,
        "name": _LOAD_NAME,
    },
    checks=(_fourier_coefficients,),
    doc="Loads `F(t) = vector * g(omega t)`, one `[[loads]]` block each.",
)
CONTACT_MATRICES = Table(
    {
        "normal_dofs": Field(_DOFS_OR_FILE, "normal DOF of each contact node (or a text file "
                             "of them); required unless `normal_load` is given (nodes without "
                             "a normal DOF rub under that load)"),
        "tangential_dofs": Field(
            AnyOf((ListOf(AnyOf((_DOF, ListOf(_DOF, sizes=(2,)))), non_empty=True), FilePath())),
            "tangential DOF of each contact node (2D), or [t1, t2] pairs (3D), or a text file "
            "with one row per node",
            required=True,
        ),
        "mu": _MU,
        "gap": Field(AnyOf((Number(), ListOf(Number(), non_empty=True))),
                     "initial normal gap, one value or one per node", default=0.0, unit="m"),
        "area": Field(AnyOf((_POSITIVE, ListOf(_POSITIVE, non_empty=True))),
                      "tributary area, one value or one per node (turns forces into "
                      "pressures for wear)", default=1.0, unit="m^2"),
        "normal_sign": Field(Choice((1, -1)), "+1 if a positive normal DOF closes the "
                             "gap (moves into the obstacle), -1 otherwise", default=1),
        "wear_coefficient": _WEAR,
        "name": _CONTACT_NAME,
        "kn": Field(AnyOf((_CONTACT_K, ListOf(_CONTACT_K, non_empty=True))),
                    "normal contact stiffness, one value or one per node, in series with the "
                    "contact law (inf: rigid)", default=math.inf, unit="N/m"),
        "kt": Field(AnyOf((_CONTACT_K, ListOf(_CONTACT_K, non_empty=True))),
                    "tangential contact stiffness, one value or one per node (a finite value "
                    "makes each node a Jenkins element; inf: rigid)", default=math.inf,
                    unit="N/m"),
        "normal_load": Field(AnyOf((_NON_NEG, ListOf(_NON_NEG, non_empty=True))),
                             "friction under a prescribed normal load: each node's normal force "
                             "N >= 0 (compressive), one value or one per node (N x g(omega t), "
                             "whatever the normal motion; slip threshold mu N); absent: "
                             "unilateral contact",
                             unit="N"),
        "normal_waveform": _NORMAL_WAVEFORM,
    },
    checks=(_normal_dofs_or_load, _waveform_needs("normal_load")),
    doc="The frictional interface: DOFs of the contact nodes against a rigid obstacle.",
)
OBSERVED_MATRICES = Dict(AnyOf((_DOF, ListOf(_DOF, non_empty=True))), key_doc="point names")

# --- matrices exported by an FE code: everything named by node ids -------------------------
_NODES = AnyOf((ListOf(Integer(lo=0), non_empty=True, unique=True), Text()))
CONTACT_FE = Table(
    {
        "nodes": Field(_NODES, "contact node ids, or the name of a node set of the `nodes` "
                       "file", required=True),
        "partners": Field(_NODES, "two-body contact: each node's partner on the other body, "
                          "ids in the order of `nodes`; or the partner surface, a node set (or "
                          "its ids with `pairing` mortar or node-to-segment): each node paired "
                          "with the set's node at its position, or with the faces of the "
                          "`nodes` file's elements on the set when the meshes do not match"),
        "pairing": Field(Text(("auto", "node-to-node", "mortar", "node-to-segment")),
                         "how `nodes` meet the partner surface: \"node-to-node\", \"mortar\", "
                         "\"node-to-segment\" (on the faces of the `nodes` file's elements) "
                         "or \"auto\": node-to-node when every node has a partner at its "
                         "position, else mortar", default="auto"),
        "tolerance": Field(_NON_NEG, "largest distance between a node and its partner point "
                           "(mortar and node-to-segment; default a tenth of the partner's "
                           "longest facet edge)", unit="m"),
        "normal": Field(Vector(), "the normal of every node, pointing from its body into the "
                        "obstacle (or the partner's body); the tangents are chosen from it. "
                        "Default: from the `nodes` file's elements, the outward normal of "
                        "their faces on the contact nodes (each node's own on a curved "
                        "face), as for a meshed model"),
        "mu": _MU,
        "gap": Field(Number(), "initial normal gap (>= 0 open, < 0 interference)", default=0.0,
                     unit="m"),
        "area": Field(AnyOf((_POSITIVE, ListOf(_POSITIVE, non_empty=True),
                             Text(("mesh",)))),
                      "tributary area, one value or one per node; \"mesh\": the consistent "
                      "nodal areas of the `nodes` file's element faces on the contact nodes, "
                      "as for a meshed model (2D: times `thickness`)", default=1.0,
                      unit="m^2"),
        "thickness": Field(_POSITIVE, "out-of-plane thickness of a 2D model, for area = "
                           "\"mesh\"", default=1.0, unit="m"),
        "wear_coefficient": _WEAR,
        "partner_wear_coefficient": Field(_NON_NEG, "Archard coefficient of the partners' "
                                          "surface", default=0.0, unit="1/Pa",
                                          used_by=WEAR_ANALYSES),
        "name": _CONTACT_NAME,
    },
    checks=(requires("tolerance", "partners"),),
    doc="A frictional interface on nodes of the exported matrices, one `[[contact]]` block "
    "each (all node-to-rigid, or all with `partners`).",
)
LOAD_FE = Table(
    {
        "nodes": Field(_NODES, "loaded node ids, or a node set", required=True),
        "force": Field(Vector(), "force vector on every node of `nodes`", required=True,
                       unit="N"),
        "waveform": _WAVEFORM,
        "coefficients": _COEFFICIENTS,
        "name": _LOAD_NAME,
    },
    checks=(_fourier_coefficients,),
    doc="Nodal forces `F(t) = force * g(omega t)` on each node, one `[[loads]]` block each.",
)
FIXED_FE = Table(
    {
        "nodes": Field(_NODES, "held node ids, or a node set", required=True),
        "direction": Field(Text(AXES + ("all",)), 'the component held at zero ("all": every '
                           "component of the nodes in the matrices)", default="all"),
    },
    doc="Held components of nodes, one `[[fixed]]` block each.",
)
OBSERVED_FE = Dict(AnyOf((Integer(lo=0), Text())), key_doc="point names")

# --- [output] and the whole file --------------------------------------------------------
OUTPUT = Table(
    {
        "directory": Field(Text(), "folder for the results (relative to the case file); "
                           'default "<case name>-results" beside the case file'),
        "figures": Field(Flag(), "write figures", default=True),
        "figure_format": Field(Text(FIGURE_FORMATS), "figure file format", default="png"),
        "vtu": Field(Flag(), "write ParaView files (.vtu/.pvd) of fields when the model has a "
                     "mesh (or is FE matrices with their node file, model.nodes)",
                     default=True, used_by=("modes", "periodic", "wear")),
        "whole_disk": Field(Flag(), "a sector ([cyclic]): also the whole disk rebuilt from "
                            "the sector in ParaView, every sector turned: `periodic-disk.pvd` "
                            "of a periodic analysis (each harmonic n phased by "
                            "e^{i n EO j 2 pi / N}), `wear-disk.pvd` of a wear run (every "
                            "sector with the sector's wear: the tuned assumption); a sweep "
                            "writes no ParaView fields; default false",
                            used_by=("periodic", "wear")),
    },
    doc="Where and what to write. `fretwear run -o DIR` overrides `directory`.",
)


# --- which analyses read which keys ----------------------------------------------------
#: every analysis type (the registry's, fretwear.analyses.registry; a test checks both agree)
ANALYSES = ("modes", "frf", "cyclic-modes", "periodic", "sweep", "nonlinear-modes",
            "transient", "incremental-wear", "wear", "worn-state")
#: the analyses that solve the contact law (friction, gaps, contact stiffness, prescribed
#: normal loads); the linear ones (modes, frf, cyclic-modes) hold the interface or leave it
#: free (fretwear.linear: "free", "sliding", "stuck"), whatever those keys say
CONTACT_LAW_ANALYSES = tuple(a for a in ANALYSES if a not in ("modes", "frf", "cyclic-modes"))
#: the analyses that read the loads: not the modes (free vibration)
LOADED_ANALYSES = tuple(a for a in ANALYSES if a not in ("modes", "cyclic-modes"))
#: the analyses that read the damping: not the modes (undamped) nor the incremental wear
#: (quasi-static load steps: no inertia, no damping)
DAMPED_ANALYSES = tuple(a for a in LOADED_ANALYSES if a != "incremental-wear")
#: the analyses of a sector's own model (cyclic-modes: the disk's modes from the sector's
#: matrices alone, every nodal diameter, contact free, no observed point)
NOT_CYCLIC_MODES = tuple(a for a in ANALYSES if a != "cyclic-modes")

#: (table, key, the analyses that read it): the keys that some analyses do not read; given to
#: another (and not left at its default), the key is named (:func:`ignored_notes`). Every
#: other key is read by every analysis. Top-level tables: :data:`_TOP_READERS`.
_READERS = (
    *((t, k, CONTACT_LAW_ANALYSES) for t in (CONTACT_MESH, CONTACT_MATRICES, CONTACT_FE)
      for k in ("mu", "gap", "area", "normal_stiffness", "tangential_stiffness",
                "normal_pressure", "normal_waveform", "kn", "kt", "normal_load")
      if k in t.fields),
    (MODEL.tables()["matrices"], "C", DAMPED_ANALYSES),
    (MODEL.tables()["matrices"], "D", DAMPED_ANALYSES),
    (CYCLIC, "engine_order", NOT_CYCLIC_MODES),
    (CYCLIC, "mistuning", NOT_CYCLIC_MODES),
    (CYCLIC, "neighbour", NOT_CYCLIC_MODES),
)
for _table, _key, _readers in _READERS:
    _table.fields[_key] = dataclasses.replace(_table.fields[_key], used_by=_readers)
#: top-level key of the case file -> the analyses that read it (the others: every one)
_TOP_READERS = {"damping": DAMPED_ANALYSES, "loads": LOADED_ANALYSES,
                "observed": NOT_CYCLIC_MODES}

_TITLE = Field(Text(), "one line describing the case (used in figures and results)")


def _case_table(model_kind: str, analyses: Mapping[str, Table]) -> Table:
    if model_kind == "fe":
        fields = {
            "title": _TITLE,
            "model": Field(MODEL, "the structure", required=True),
            "damping": Field(DAMPING, "structural damping"),
            "fixed": Field(TableList(FIXED_FE), "held node components", default=[]),
            "loads": Field(TableList(LOAD_FE), "nodal forces", default=[]),
            "contact": Field(TableList(CONTACT_FE), "the frictional interfaces",
                             required=True),
            "observed": Field(OBSERVED_FE, "nodes (id or one-node set) whose motion is "
                              "reported", default={}),
        }
    elif model_kind == "matrices":
        fields = {
            "title": _TITLE,
            "model": Field(MODEL, "the structure", required=True),
            "damping": Field(DAMPING, "structural damping"),
            "loads": Field(TableList(LOAD_MATRICES), "loads", default=[]),
            "contact": Field(CONTACT_MATRICES, "the frictional interface", required=True),
            "observed": Field(OBSERVED_MATRICES, "DOFs whose motion is reported", default={}),
        }
    else:
        fields = {
            "title": _TITLE,
            "model": Field(MODEL, "the structure", required=True),
            "material": Field(MATERIAL, "elastic material", required=True),
            "damping": Field(DAMPING, "structural damping"),
            "springs": Field(TableList(SPRING), "grounded springs", default=[]),
            "fixed": Field(TableList(FIXED), "held displacement components", default=[]),
            "loads": Field(TableList(LOAD_MESH), "loads", default=[]),
            "contact": Field(TableList(CONTACT_MESH), "the frictional interfaces", required=True),
            "observed": Field(OBSERVED_MESH, "points whose motion is reported", default={}),
            "materials": Field(Dict(MATERIAL, key_doc="body (node set) names"),
                               "materials of some bodies, by the name of the node set that "
                               "holds a body (e.g. a Gmsh physical volume); a cell with all "
                               "its nodes in such a set takes its material, the others take "
                               "[material]", default={}),
            "cyclic": Field(CYCLIC, "cyclic symmetry: the model is one sector of a disk"),
            "centrifugal": Field(CENTRIFUGAL, "centrifugal loading at a rotation speed"),
        }
    for key, readers in _TOP_READERS.items():
        fields[key] = dataclasses.replace(fields[key], used_by=readers)
    fields["analysis"] = Field(Variant(dict(analyses), key_doc="analysis type"),
                               "what to compute", required=True)
    fields["output"] = Field(OUTPUT, "what to write")
    return Table(fields)


def validate(raw: Mapping, analyses: Mapping[str, Table], base_dir: Path | str = ".") -> dict:
    """Validate a parsed case file; return the normalised dict (defaults filled in).

    ``analyses`` maps each analysis type to the schema of its ``[analysis]`` table (the
    registry of :mod:`fretwear.analyses` passes its own). Relative file paths are resolved
    against ``base_dir`` (the case file's folder).

    Raises
    ------
    InputError
        At the first mistake, naming its key path.
    """
    raw = {"damping": {}, "output": {}, **raw}  # absent tables get their defaults
    return _case_table(_model_kind(raw), analyses).check(raw, "", Context(Path(base_dir)))


def _model_kind(raw: Mapping) -> str:
    """``"fe"``, ``"matrices"`` or ``"mesh"``: which tables the case file has."""
    model = raw.get("model")
    kind = model.get("type") if isinstance(model, Mapping) else None
    if kind == "matrices" and fe_mode(model):
        kind = "fe"
    return kind if kind in ("matrices", "fe") else "mesh"


#: the tables whose keys say how to run (an ignored one is a warning); the others describe the
#: model (an ignored one, such as a wear coefficient kept in a file run for its FRF, is a note)
_RUN_TABLES = ("analysis", "output")


def ignored_notes(case: Case, analyses: Mapping[str, Table]) -> list[str]:
    """One line for every key of the case file that its analysis does not read (declared by
    the schema: :attr:`fretwear.io.schema.Field.used_by`, found by
    :func:`fretwear.io.schema.unused_keys`), naming the key and the analyses that read it."""
    kind = case.analysis["type"]
    lines = []
    for path, value, used_by in unused_keys(_case_table(_model_kind(case.raw), analyses),
                                            case.raw, kind):
        level = "warning" if path.split(".")[0].split("[")[0] in _RUN_TABLES else "note"
        others = [a for a in analyses if a not in used_by]
        readers = (f"only by {', '.join(used_by)}" if len(used_by) <= len(others)
                   else f"read by every analysis but {', '.join(others)}")
        lines.append(f"{level}: {path} = {show(value)} is not used by a {kind} analysis "
                     f"({readers}): it is ignored")
    given = case.raw["analysis"]
    table = analyses[kind].fields if kind in analyses else {}
    for keys, applies, why in _OVERRIDDEN:
        if not applies(case.raw, given):
            continue
        for key in keys:
            f = table.get(key)
            if f is not None and key in given and not (f.default is not MISSING
                                                        and given[key] == f.default):
                lines.append(f"warning: analysis.{key} = {show(given[key])} is not used: "
                             f"{why}: it is ignored")
    return lines + _load_notes(case.raw.get("loads"), kind)


def _load_notes(loads, kind: str) -> list[str]:
    """The loads an FRF or a nonlinear mode leaves unread, one note each: the FRF takes the
    harmonic 1 of the loads (a constant load is ignored), the nonlinear mode, a free
    vibration, only their static part (the periodic part of a waveform is ignored)."""
    if kind not in ("frf", "nonlinear-modes") or not isinstance(loads, list):
        return []
    out = []
    for i, ld in enumerate(loads):
        if not isinstance(ld, Mapping):
            continue
        wf = ld.get("waveform", "constant")
        name = show(ld.get("name", f"{i + 1}"))
        if kind == "frf" and wf == "constant":
            out.append(f"note: load {name} (waveform \"constant\") is not used by a frf "
                       "analysis (the response to the harmonic 1 of the loads): it is ignored")
        elif kind == "nonlinear-modes" and wf != "constant":
            out.append(f"note: load {name} (waveform {show(wf)}) is not used by a "
                       "nonlinear-modes analysis beyond its static part (a free vibration, "
                       "preloaded by the static loads): its periodic part is ignored")
    return out


_MODAL_KEYS = ("condensation_modes", "condensation_cutoff", "condensation_tol")
#: (keys of [analysis], when they go unread (case as written, its [analysis]), why): keys that
#: another key makes unread
_OVERRIDDEN = (
    (("n_modes",), lambda raw, a: "f_max" in a, "f_max is given (every mode up to it)"),
    (("condensation", *_MODAL_KEYS), lambda raw, a: "cyclic" in raw,
     "a sector ([cyclic]) is condensed exactly, one condensation per harmonic index"),
    (_MODAL_KEYS, lambda raw, a: "cyclic" not in raw and a.get("condensation") == "exact",
     'condensation = "exact" (the keys of the modal condensation)'),
)


# --- loading ----------------------------------------------------------------------------
_MODEL_SECTIONS = ("model", "material", "damping", "springs", "fixed", "loads", "contact",
                   "observed", "materials", "cyclic", "centrifugal")


@dataclass(frozen=True)
class Case:
    """A validated case file.

    Attributes
    ----------
    path : the case file (absolute).
    title : its title (the file name when it has none).
    text : the file text (stored in the results file).
    raw : the parsed TOML, as written.
    model : the validated sections that define the model (``model``, ``material``,
        ``damping``, ``springs``, ``fixed``, ``loads``, ``contact``, ``observed``; those of
        the model kind), with defaults filled in and file paths absolute.
    analysis : the validated ``[analysis]`` table (with ``type``).
    output : the validated ``[output]`` table.

    How a case is run (results folder, ``--resume``, progress bars) is not part of it: see
    :class:`fretwear.analyses.base.RunContext`.
    """

    path: Path
    title: str
    text: str
    raw: dict
    model: dict
    analysis: dict
    output: dict

    @property
    def folder(self) -> Path:
        return self.path.parent

    @property
    def name(self) -> str:
        """The case file name without its extension."""
        return self.path.stem

    @property
    def model_kind(self) -> str:
        """``"matrices"`` or ``"mesh"`` (rectangle, box or mesh file)."""
        return "matrices" if self.model["model"]["type"] == "matrices" else "mesh"

    def output_dir(self, override: Path | str | None = None) -> Path:
        """Results folder: ``override`` (relative to the working directory), else
        ``output.directory`` (relative to the case file), else ``<name>-results`` beside it."""
        if override is not None:
            return Path(override).expanduser().resolve()
        d = self.output.get("directory")
        if d is None:
            return self.folder / f"{self.name}-results"
        d = Path(d).expanduser()
        return d if d.is_absolute() else (self.folder / d).resolve()


def read_toml(path: Path | str) -> tuple[str, dict]:
    """The text and the parsed content of a TOML file; every failure is an InputError."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError(f"case file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read case file {str(path)!r}: {exc}") from None
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path.name}: invalid TOML: {exc}") from None
    return text, raw


def load_case(path: Path | str, analyses: Mapping[str, Table]) -> Case:
    """Read and validate a case file.

    Parameters
    ----------
    path : the ``.toml`` case file; relative paths inside it start from its folder.
    analyses : analysis type -> schema of its ``[analysis]`` table
        (:func:`fretwear.analyses.load_case` passes the registered ones).

    Returns
    -------
    Case

    Raises
    ------
    InputError
        The file is missing or is not TOML, or a value is wrong (the message names the key).
    """
    path = Path(path).expanduser().resolve()
    text, raw = read_toml(path)
    v = validate(raw, analyses, path.parent)
    return Case(
        path=path,
        title=v.get("title") or path.stem,
        text=text,
        raw=raw,
        model={k: v[k] for k in _MODEL_SECTIONS if k in v},
        analysis=v["analysis"],
        output=v["output"],
    )


# --- building the model -------------------------------------------------------------------
def build_model(case: Case):
    """The :class:`~fretwear.model.core.Model` a validated case describes.

    Names (boundaries, node sets, observed points) and vector sizes are checked against
    the mesh here so that the message names the case-file key.
    """
    if case.model_kind == "matrices" and fe_mode(case.model["model"]):
        from fretwear.io.fe_case import build_from_fe

        return build_from_fe(case.model, case.title)
    if case.model_kind == "matrices":
        return _build_from_matrices(case.model, case.title)
    with warnings.catch_warnings():  # said by key instead (unusual_notes)
        warnings.simplefilter("ignore", UnusualValueWarning)
        return _build_from_mesh(case.model, case.title, given=case.raw["model"])


#: case-file key -> kind of :data:`fretwear.limits.USUAL` it is checked against
_USUAL_KEYS = {"E": "modulus", "rho": "density", "mu": "friction",
               "wear_coefficient": "wear_coefficient",
               "partner_wear_coefficient": "wear_coefficient", "pressure": "pressure",
               "normal_pressure": "pressure"}


def unusual_notes(case: Case) -> list[str]:
    """Lines for legal values that are almost surely a unit mistake (``E = 210`` [Pa], a
    density in g/cm^3, ``mu = 5``...), named by their key: :func:`fretwear.limits.unusual`."""
    notes = []

    def walk(value, path: str):
        if isinstance(value, Mapping):
            for k, v in value.items():
                sub = f"{path}.{k}" if path else str(k)
                if k in _USUAL_KEYS and not isinstance(v, Mapping | list | bool):
                    note = unusual(v, _USUAL_KEYS[k], sub)
                    if note:
                        notes.append(f"warning: {note}")
                else:
                    walk(v, sub)
        elif isinstance(value, list):
            for i, v in enumerate(value):  # one block: named as the file names it
                walk(v, f"{path}[{i + 1}]" if len(value) > 1 else path)

    walk({k: v for k, v in case.model.items() if k != "analysis"}, "")
    return notes


def observed_notes(case: Case, model, rtol: float = 1e-6) -> list[str]:
    """Lines telling where an observed point was moved to the nearest mesh node.

    A point given by coordinates is the node nearest to them; when that node is farther than
    ``rtol`` times the model size, the user should know which point is reported.
    """
    if model.mesh is None:
        return []
    size = float(np.linalg.norm(np.ptp(model.mesh.points, axis=0)))
    notes = []
    for name, where in case.model.get("observed", {}).items():
        if not isinstance(where, list):
            continue
        node = np.asarray(model.observed_point(name).coords, dtype=float)
        if np.linalg.norm(node - np.asarray(where, dtype=float)) > rtol * size:
            at = ", ".join(f"{c:.6g}" for c in node)
            notes.append(f"note: observed.{name} = {show(where)} is not a mesh node; "
                         f"reporting the nearest node, at ({at})")
    return notes


def _make_mesh(spec: dict):
    from fretwear.model import mesh as meshes

    kind = spec["type"]
    if kind == "rectangle":
        return meshes.rectangle(spec["length"], spec["height"], spec["nx"], spec["ny"])
    if kind == "box":
        return meshes.box(spec["lx"], spec["ly"], spec["lz"], spec["nx"], spec["ny"], spec["nz"])
    if kind == "blocks":
        return _blocks(spec["blocks"])
    return meshes.read(spec["file"])


def _blocks(blocks: list):
    """One mesh of the structured ``[[model.blocks]]``
    (:func:`fretwear.model.mesh.join`)."""
    from fretwear.model import mesh as meshes

    dims = {len(b["size"]) for b in blocks}
    if len(dims) > 1:
        fail("model.blocks", [b["name"] for b in blocks],
             "blocks of one dimension (all 2D sizes or all 3D)")
    parts = []
    for b in blocks:
        origin = b.get("origin", [0.0] * len(b["size"]))
        if len(b["size"]) == 2:
            m = meshes.rectangle(*b["size"], *b["elements"], origin=origin)
        else:
            m = meshes.box(*b["size"], *b["elements"], origin=origin)
        parts.append((b["name"], m))
    return meshes.join(*parts)


def _check_name(name: str, path: str, names) -> None:
    names = sorted(names)
    if name not in names:
        fail(path, name, "one of " + ", ".join(show(n) for n in names), suggest(name, names, show))


def _check_vector(value, path: str, dim: int) -> None:
    if isinstance(value, list) and len(value) != dim:
        fail(path, value, f"{dim} components for a {dim}D model")


def _check_against_mesh(m: dict, mesh, given: Mapping) -> None:
    """Names and vector sizes of the mesh-model sections, with key paths in messages."""
    dim = mesh.dim
    bnames = list(mesh.boundaries)
    anywhere = sorted(set(mesh.boundaries) | set(mesh.node_sets))
    for section in ("springs", "fixed"):
        for i, item in enumerate(m.get(section, [])):
            path = f"{section}[{i + 1}]"
            if isinstance(item["at"], str):
                _check_name(item["at"], f"{path}.at", anywhere)
            _check_vector(item["at"], f"{path}.at", dim)
            _check_vector(item.get("direction"), f"{path}.direction", dim)
            if item.get("direction") == "z" and dim == 2:
                fail(f"{path}.direction", "z", 'one of "x", "y" for a 2D model')
    for i, load in enumerate(m.get("loads", [])):
        path = f"loads[{i + 1}]"
        if "boundary" in load:
            _check_name(load["boundary"], f"{path}.boundary", bnames)
        if isinstance(load.get("at"), str):
            _check_name(load["at"], f"{path}.at", anywhere)
        for key in ("at", "traction", "force"):
            _check_vector(load.get(key), f"{path}.{key}", dim)
    many = len(m["contact"]) > 1
    for i, contact in enumerate(m["contact"]):
        path = f"contact[{i + 1}]" if many else "contact"
        for key in ("boundary", "partner"):
            if key not in contact:
                continue
            _check_name(contact[key], f"{path}.{key}", bnames)
            if len(mesh.boundaries[contact[key]]) == 0:
                fail(f"{path}.{key}", contact[key], "a boundary with at least one facet")
        for key in ("normal", "tangent"):
            _check_vector(contact.get(key), f"{path}.{key}", dim)
    for name, where in m.get("observed", {}).items():
        if isinstance(where, str):
            _check_name(where, f"observed.{name}", mesh.node_sets)
        _check_vector(where, f"observed.{name}", dim)
    spec = m["model"]
    if spec["type"] in ("mesh", "blocks") and dim == 3 and "thickness" in given:
        fail("model.thickness", spec["thickness"], "no thickness for a 3D mesh")


def _build_from_mesh(m: dict, title: str, given: Mapping):
    from fretwear.model import build

    mesh = _make_mesh(m["model"])
    _check_against_mesh(m, mesh, given)
    mat = m["material"]
    material = build.Material(mat["E"], mat["nu"], mat["rho"])
    if m.get("materials"):
        for body in m["materials"]:
            _check_name(body, f"materials.{body}", mesh.node_sets)
        material = {**{body: build.Material(v["E"], v["nu"], v["rho"])
                       for body, v in m["materials"].items()}, None: material}
    damp = m["damping"]
    springs = [build.Spring(_at(s["at"]), s["direction"], s["stiffness"],
                            region=s.get("region"))
               for s in m.get("springs", [])]
    fixed = [(_at(f["at"]), f["direction"]) for f in m.get("fixed", [])]
    loads = []
    for i, ld in enumerate(m.get("loads", [])):
        name = ld.get("name") or f"load{i + 1}"
        coefficients = _coefficients(ld.get("coefficients"))
        if "force" in ld:
            loads.append(build.NodalForce(_at(ld["at"]), ld["force"], waveform=ld["waveform"],
                                          name=name, region=ld.get("region"), **coefficients))
        else:
            loads.append(build.Traction(ld["boundary"], pressure=ld.get("pressure"),
                                        traction=ld.get("traction"), waveform=ld["waveform"],
                                        name=name, region=ld.get("region"), **coefficients))
    contact = [build.ContactSpec(c["boundary"], c["mu"], normal=c.get("normal"),
                                 tangent=c.get("tangent"), gap=c["gap"],
                                 wear_coefficient=c["wear_coefficient"],
                                 name=c["name"], partner=c.get("partner"),
                                 tolerance=c.get("tolerance"),
                                 partner_wear_coefficient=c.get("partner_wear_coefficient", 0.0),
                                 normal_stiffness=c["normal_stiffness"],
                                 tangential_stiffness=c["tangential_stiffness"],
                                 normal_pressure=c.get("normal_pressure"),
                                 normal_waveform=c["normal_waveform"],
                                 pairing=c["pairing"], region=c.get("region"))
               for c in m["contact"]]
    observed = {k: _at(v) for k, v in m.get("observed", {}).items()} or None
    thickness = m["model"].get("thickness", 1.0) if mesh.dim == 2 else 1.0
    cyc = m.get("cyclic")
    neighbour = cyc.get("neighbour") if cyc else None
    if neighbour is not None:
        names = [c.name for c in contact]
        _check_name(neighbour, "cyclic.neighbour", names)
        spec = contact[names.index(neighbour)]
        if spec.partner is None or spec.partner == spec.boundary:
            fail("cyclic.neighbour", neighbour, "a [[contact]] block with a partner boundary "
                 f"other than its boundary {spec.boundary!r} (the damper pairs a boundary "
                 "with the next sector's copy of another one)")
        contact = [c for c in contact if c.name != neighbour]
    # a body held only by its contacts, one with the next sector (a damper between two
    # platforms), is checked once that contact is added (model.cyclic.neighbour_contact)
    make = build.from_mesh if neighbour is None else build.unchecked_from_mesh
    try:
        model = make(
            mesh,
            material,
            thickness=thickness,
            damping=build.Damping(damp["loss_factor"], damp["rayleigh_mass"],
                                  damp["rayleigh_stiffness"]),
            supports=[*springs, *fixed],
            loads=loads,
            contact=contact,
            observed=observed,
            name=title,
        )
    except Unsupported as exc:  # the remedy as case-file blocks, not Python
        raise exc.in_case_file() from None
    if m.get("centrifugal"):
        model = _spin(model, m["centrifugal"], cyc or {})
    return model if cyc is None else _sector(model, cyc, spec if neighbour else None)


def _spin(model, spin: dict, cyc: dict):
    """``model`` with the ``[centrifugal]`` load added (axis and point: those of ``spin``,
    else of ``[cyclic]``, else z through the origin)."""
    from fretwear.model.rotation import centrifugal_load

    axis = spin.get("axis", cyc.get("axis", [0.0, 0.0, 1.0]))
    point = spin.get("point", cyc.get("point", [0.0, 0.0, 0.0]))
    try:
        load = centrifugal_load(model, spin["speed"], axis=axis, point=point,
                                name=spin["name"])
    except InputError as exc:
        raise InputError(f"centrifugal: {exc}") from None
    return dataclasses.replace(model, loads=[*model.loads, load])


def _sector(model, cyc: dict, neighbour):
    """The sector model of ``[cyclic]``, its :class:`~fretwear.model.cyclic.CyclicSector` in
    ``model.meta["cyclic"]`` and its engine order in ``model.meta["engine_order"]`` (read by
    :func:`fretwear.analyses.common.condenser_of`); mistakes name the ``cyclic`` keys."""
    from fretwear.model.cyclic import cyclic_sector, neighbour_contact

    mesh = model.mesh
    anywhere = sorted(set(mesh.boundaries) | set(mesh.node_sets))
    for key in ("left", "right"):
        _check_name(cyc[key], f"cyclic.{key}", anywhere)
    if mesh.dim == 2 and (cyc["axis"][0] != 0 or cyc["axis"][1] != 0):
        fail("cyclic.axis", cyc["axis"], "[0, 0, 1] or [0, 0, -1] for a 2D model")
    try:
        sector = cyclic_sector(model, cyc["sectors"], cyc["left"], cyc["right"],
                               axis=cyc["axis"], point=cyc["point"],
                               tolerance=cyc.get("tolerance"))
        if neighbour is not None:
            sector = neighbour_contact(sector, neighbour)
    except Unsupported as exc:  # the remedy as case-file blocks, not Python
        raise InputError(f"cyclic: {exc.in_case_file()}") from None
    except InputError as exc:
        raise InputError(f"cyclic: {exc}") from None
    sector.model.meta["cyclic"] = sector
    sector.model.meta["engine_order"] = int(cyc["engine_order"])
    if cyc.get("mistuning") is not None:
        return _mistuned(sector, cyc)
    return sector.model


def _mistuned(sector, cyc: dict):
    """The whole disk of ``[cyclic.mistuning]`` (its factors listed or drawn)."""
    from fretwear.model.mistuning import KINDS, mistuned_disk, mistuning, random_mistuning

    mt = cyc["mistuning"]
    n = sector.n_sectors
    factors = {}
    if "std" in mt:
        drawn = random_mistuning(n, mt["std"], mt["seed"], tuple(mt["draw"]))
        factors = {k: getattr(drawn, k) for k in mt["draw"]}
    for kind in KINDS:
        if kind in mt:
            if len(mt[kind]) != n:
                fail(f"cyclic.mistuning.{kind}", mt[kind], f"{n} factors (one per sector; "
                     f"sectors = {n})")
            factors[kind] = mt[kind]
    return mistuned_disk(sector, int(cyc["engine_order"]), mistuning(n, **factors))


def _at(value):
    return tuple(value) if isinstance(value, list) else value


def _coefficients(coeffs) -> dict:
    """``{"coefficients": {n: (a, b)}}`` for a Fourier waveform, else ``{}``."""
    if not coeffs:
        return {}
    return {"coefficients": {int(k): (float(v[0]), float(v[1])) for k, v in coeffs.items()}}


def _read_dofs(value, path: str, base: int) -> np.ndarray:
    """DOF numbers from a list or a text file, shifted to count from 0."""
    if isinstance(value, Path):
        try:
            arr = np.loadtxt(value, dtype=float, ndmin=1)
        except (OSError, ValueError) as exc:
            raise InputError(f"{path}: cannot read DOF numbers from {str(value)!r}: {exc}") \
                from None
        if arr.size == 0 or np.any(arr != np.round(arr)):
            fail(path, str(value), "a text file of integer DOF numbers")
        arr = arr.astype(np.int64)
    else:
        arr = np.asarray(value, dtype=np.int64)
    arr = arr - base
    if np.any(arr < 0):
        fail(path, value if not isinstance(value, Path) else str(value),
             f"DOF numbers >= {base} (first_dof = {base})")
    return arr


def _read_vector(path: Path, key: str, n: int) -> np.ndarray:
    from fretwear.model.matrices import read_matrix_market

    try:
        if path.suffix.lower() == ".mtx":
            v = read_matrix_market(path)
            v = v.toarray() if hasattr(v, "toarray") else np.asarray(v)
        else:
            v = np.loadtxt(path, dtype=float, ndmin=1)
    except (OSError, ValueError) as exc:
        raise InputError(f"{key}: cannot read {str(path)!r}: {exc}") from None
    v = np.asarray(v, dtype=float).reshape(-1)
    if v.size != n:
        fail(key, str(path), f"a vector of {n} values (one per DOF of K), got {v.size}")
    return v


def _build_from_matrices(m: dict, title: str):
    from fretwear.model.build import Damping
    from fretwear.model.core import Load
    from fretwear.model.matrices import ContactDofs, from_matrices, read_matrix_market

    spec = m["model"]
    base = spec["first_dof"]
    K = read_matrix_market(spec["K"])
    M = read_matrix_market(spec["M"])
    C = read_matrix_market(spec["C"]) if "C" in spec else None
    D = read_matrix_market(spec["D"]) if "D" in spec else None
    damp = m["damping"]
    if damp["rayleigh_mass"] or damp["rayleigh_stiffness"]:
        rayleigh = damp["rayleigh_mass"] * M + damp["rayleigh_stiffness"] * K
        C = rayleigh if C is None else C + rayleigh
    if damp["loss_factor"]:
        D = damp["loss_factor"] * K if D is None else D + damp["loss_factor"] * K
    ndof = K.shape[0]
    loads = []
    for i, ld in enumerate(m.get("loads", [])):
        vec = _read_vector(ld["file"], f"loads[{i + 1}].file", ndof)
        loads.append(Load(vec, ld["waveform"], _coefficients(ld.get("coefficients")).get(
            "coefficients"), ld.get("name") or f"load{i + 1}"))
    c = m["contact"]
    normal = (_read_dofs(c["normal_dofs"], "contact.normal_dofs", base)
              if "normal_dofs" in c else None)
    tangential = _read_dofs(c["tangential_dofs"], "contact.tangential_dofs", base)
    observed = {name: _read_dofs(d if isinstance(d, list) else [d], f"observed.{name}",
                                 base).tolist()
                for name, d in m.get("observed", {}).items()}
    gap, area = c["gap"], c["area"]
    for key in ("normal_load", "gap", "area", "kn", "kt"):
        if isinstance(c.get(key), list) and len(c[key]) not in (1, len(tangential)):
            raise InputError(f"model.contact.{key} has {len(c[key])} values; expected one, or "
                             f"one per contact node ({len(tangential)}, the rows of "
                             "tangential_dofs)")
    contact = ContactDofs(
        normal_dofs=normal,
        tangential_dofs=tangential,
        mu=c["mu"],
        gap=np.asarray(gap, dtype=float) if isinstance(gap, list) else gap,
        area=np.asarray(area, dtype=float) if isinstance(area, list) else area,
        normal_sign=c["normal_sign"],
        wear_coefficient=c["wear_coefficient"],
        normal_load=(None if "normal_load" not in c else
                     Load(np.broadcast_to(np.asarray(c["normal_load"], float),
                                          (len(tangential),)).copy(), c["normal_waveform"],
                          None, "normal load")),
        kn=_per_node_or_none(c["kn"]),
        kt=_per_node_or_none(c["kt"]),
    )
    return from_matrices(
        K,
        M,
        contact=contact,
        damping=Damping(C=C, D=D),
        loads=loads,
        fixed_dofs=_read_dofs(spec["fixed_dofs"], "model.fixed_dofs", base),
        observed=observed or None,
        name=title,
    )


def _per_node_or_none(value):
    """A contact stiffness of a case file: None when rigid everywhere (inf), else the value(s)."""
    a = np.asarray(value, dtype=float)
    return None if np.all(np.isinf(a)) else a


# --- documentation --------------------------------------------------------------------------
_DOC_HEAD = """\
# Case files

<!-- Generated by fretwear.io.case.write_case_docs() from the schema in src/fretwear/io/case.py
and the analysis schemas registered in src/fretwear/analyses/: do not edit by hand. -->

A case file is a [TOML](https://toml.io) file that describes a model, an analysis and what to
write. Run it with `fretwear run CASE.toml`; the shipped examples (`fretwear example list`) are
case files too. Units are SI throughout (m, kg, s, N, Pa, Hz).

Every key is checked when the file is loaded: a wrong value, a wrong type, a missing required
key or an unknown key (a typo) stops the run with one line naming the key, e.g.

```
error: material.nu = 0.5: expected a number in (-1, 0.5)
error: unknown key 'materal' in [top level]; expected one of: title, model, material, ... \
(did you mean 'material'?)
```

A complete example with every modelling choice commented: `fretwear example show
beam-linear-frf`.

Items of arrays of tables are numbered from 1 in messages: `loads[2]` is the second
`[[loads]]` block. Relative file paths are relative to the folder of the case file.

A model is either a finite element mesh (`model.type` = `"rectangle"`, `"box"` or `"mesh"`)
or user matrices (`"matrices"`). The sections `[contact]`, `[[loads]]` and `[observed]`
differ between the two; `[material]` and `[[springs]]` exist for meshes only, `[[fixed]]` for
meshes and for matrices exported by an FE code (`format` or `dofmap` in `[model]`: the
sections then name nodes by id, see "Exporting matrices from an FE code").

## Top level

| key | what |
|---|---|
| `title` | one line describing the case (optional) |
| `[model]` | the structure (required) |
| `[material]` | elastic material (meshes, required) |
| `[damping]` | structural damping (optional) |
| `[[springs]]` | grounded springs (meshes, optional) |
| `[[fixed]]` | held displacement components (meshes, FE matrices; optional) |
| `[[loads]]` | loads (optional) |
| `[contact]` | the frictional interface, or `[[contact]]` blocks for several (required) |
| `[observed]` | points (meshes) or DOFs (matrices) whose motion is reported (optional) |
| `[materials.<body>]` | material of the cells of node set `<body>` (meshes, optional) |
| `[analysis]` | what to compute (required) |
| `[output]` | where and what to write (optional) |
"""


_DOC_CONDENSATION = """\
### Condensation (`periodic`, `sweep`, `wear`)

The structure is condensed on its contact DOFs (paper eq. 19) by the method of the key
`condensation` (Python: `fretwear.condenser`, docs/api.md):

- `"exact"`: one complex LU and one solve per contact DOF at every harmonic and frequency.
- `"modal"`: one Craig-Bampton basis for every frequency up to the analysis' highest (the
  sweep's `f_max`, the solve's `frequency`, the wear run's frequency or its FRFs' `f_max`)
  and every kept harmonic: the fixed-interface modes below `condensation_cutoff` times the
  highest harmonic frequency (or `condensation_modes` of them), the static responses of the
  loads and, up to 1024 contact DOFs, the residual vectors (the static correction of the
  omitted modes; docs/theory.md, "Large interfaces"). A sweep or a wear run then condenses
  nothing again at each frequency or step.
- `"auto"` (default): the modal condensation for a large model (at least 2000 interior DOFs,
  and 8 per contact DOF or 3 harmonics or more) with a frequency, else the exact one
  (quasi-static runs are exact).

**Error check** of the modal condensation: at the highest harmonic of the highest frequency,
`Z_r` applied to four random vectors, the condensed loads and the recovery of the observed
points inside the structure are compared with the exact condensation (one complex LU); the
largest relative error must be at most `condensation_tol` (default 1e-3). Without
`condensation_modes` the number of modes is raised (doubled, at least 8, at most 512) until
the check passes; `"auto"` falls back to the exact condensation where 512 modes do not pass,
`"modal"` stops with an error. The method used, why, the modes kept and the check's error are
printed in the run summary (`condensation: ...`) and stored as results attributes
(`condensation`, `condensation_asked`, `condensation_reason`, `condensation_modes`,
`condensation_residual_vectors`, `condensation_error`, `condensation_tol`,
`condensation_f_max`, `condensation_max_order`).
"""


_DOC_FE = """\
## Exporting matrices from an FE code

With `format` (or `dofmap`) in `[model]`, the rows of the matrices are named by node id and
component, and a Craig-Bampton superelement is read like any matrices: its contact and observed
nodes must be boundary (retained) nodes, its modal coordinates are scalar points that nothing
names. Give the code's input file as `nodes` for coordinates and node sets.

- **Nastran**: a superelement with `EXTSEOUT(ASMBULK, EXTID=1, DMIGPCH)` (boundary grids on
  `ASET`/`BSET`, modes on `QSET` scalar points, `SPOINT`s) punches `KAAX`, `MAAX` (`BAAX`,
  `K4AX` with damping) as DMIG cards (so does the older `PARAM,EXTOUT,DMIGPCH`):
  `format = "dmig"`, `K = "model.pch"`. Full matrices: a DMAP `OUTPUT4` of `KGG`/`MGG`
  (`format = "op4"`, ASCII `FORMATTED` or binary, with a `dofmap` file; `names = {K = "KGG", M =
  "MGG"}`).
- **Abaqus**: `*SUBSTRUCTURE GENERATE` with `*RETAINED NODAL DOFS` (contact and observed
  nodes) and `*SUBSTRUCTURE MATRIX OUTPUT, STIFFNESS=YES, MASS=YES` writes one `.mtx` file:
  `format = "abaqus"`. Full matrices: `*MATRIX GENERATE, STIFFNESS, MASS` then `*MATRIX OUTPUT,
  STIFFNESS=YES, MASS=YES, FORMAT=MATRIX INPUT`: `format = "abaqus-matrix-input"`, `K` and `M`
  the `_STIF1.mtx` and `_MASS1.mtx` files.
- **ANSYS**: a substructure (`ANTYPE,SUBSTR` with `SEOPT` and master DOFs `M` on the contact
  and observed nodes, `CMSOPT` for component modes) or a full model leaves `file.full`
  (`WRFULL,1` stops after writing it): `format = "ansys-full"` (needs `pip install
  'fretwear[ansys]'`). Without that package: `HBMAT,K,txt,,ASCII,STIFF,NO,YES` and
  `HBMAT,M,txt,,ASCII,MASS,NO,YES` write Harwell-Boeing files and `K.mapping`:
  `format = "harwell-boeing"`, `dofmap = "K.mapping"`.
"""


def case_docs(analyses: Mapping[str, Table]) -> str:
    """The Markdown of ``docs/case-files.md``, generated from the schemas (``analyses``: the
    schema of each analysis type, as for :func:`validate`)."""
    parts = [_DOC_HEAD]
    parts.append("## [model]\n\n`type` selects one of the tables below.\n")
    for kind, table in MODEL_TYPES.items():
        parts.append(render_table(table, f'### type = "{kind}"'))
    parts.append(render_table(MATERIAL, "## [material] (meshes)"))
    parts.append(render_table(DAMPING, "## [damping]"))
    parts.append(render_table(SPRING, "## [[springs]] (meshes)"))
    parts.append(render_table(FIXED, "## [[fixed]] (meshes)"))
    parts.append(render_table(LOAD_MESH, "## [[loads]] (meshes)"))
    parts.append(render_table(LOAD_MATRICES, "## [[loads]] (matrices)"))
    parts.append(render_table(CONTACT_MESH, "## [contact] (meshes)"))
    parts.append(render_table(CONTACT_MATRICES, "## [contact] (matrices)"))
    parts.append(render_table(CONTACT_FE, "## [[contact]] (FE matrices)"))
    parts.append(render_table(LOAD_FE, "## [[loads]] (FE matrices)"))
    parts.append(render_table(FIXED_FE, "## [[fixed]] (FE matrices)"))
    parts.append(_DOC_FE)
    parts.append(
        "## [observed]\n\nOne key per point. Meshes: `name = [x, y(, z)]`, the node nearest "
        "to these coordinates [m] (its exact position is in the results), or `name = "
        '"set"`, a node set of one node. Matrices: `name = dof` or `name = [dofs]`; FE '
        "matrices: `name = node id` or a one-node set. Results and figures use these names.\n"
    )
    parts.append(render_table(CYCLIC, "## [cyclic] (meshes)"))
    parts.append(render_table(MISTUNING, "## [cyclic.mistuning] (meshes)"))
    parts.append(render_table(CENTRIFUGAL, "## [centrifugal] (meshes)"))
    parts.append("## [analysis]\n\n`type` selects one of the analyses below (those registered "
                 "in this version).\n")
    for kind, table in analyses.items():
        parts.append(render_table(table, f'### type = "{kind}"'))
    parts.append(_DOC_CONDENSATION)
    parts.append(render_table(OUTPUT, "## [output]"))
    return "\n".join(parts)


def docs_path() -> Path:
    """``docs/case-files.md`` of the source tree (the package is installed editable)."""
    return Path(__file__).resolve().parents[3] / "docs" / "case-files.md"


def write_case_docs(analyses: Mapping[str, Table], path: Path | str | None = None) -> Path:
    """Write :func:`case_docs` to ``path`` (default: :func:`docs_path`)."""
    path = Path(path) if path is not None else docs_path()
    path.write_text(case_docs(analyses), encoding="utf-8")
    return path
