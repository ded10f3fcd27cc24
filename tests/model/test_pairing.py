"""Partners of a two-body interface (fretwear.model.pairing): node-to-node, mortar and
node-to-segment, through every analysis.

References independent of the code under test:

* a block on a base 1e6 times stiffer and held is the block on a rigid flat, up to the
  base's compliance (relative size ~ the stiffness ratio), whatever the base's mesh: on a
  non-matching base (mortar pairs) the periodic solution, a wear run and a time
  integration match the node-to-rigid runs;
* Archard's law on both surfaces: worn volume per cycle = sum over the sides of k_w / mu x
  the friction energy per cycle, on a non-matching interface as on a matching one;
* a non-matching joint tends to the matching-mesh answer as both meshes are refined
  (benchmarks/nonmatching.py prints the rate; here one refinement pair);
* ``pairing = "auto"`` keeps node-to-node pairs on matching meshes (the model of today).
"""

import numpy as np
import pytest

from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.hb.problem import DLFTProblem
from fretwear.hb.reduce import condense
from fretwear.model import (
    ContactSpec,
    Damping,
    Material,
    Spring,
    Traction,
    from_mesh,
    join,
    rectangle,
)
from fretwear.wear.laws import side_depths, wear_coefficients, worn_volume

STEEL = Material(210e9, 0.3, 7800.0)
MU = 0.3
F_HZ = 2000.0
BASIS = FourierBasis.up_to(3, 32)
RATIO = 1e-6
SCALE = 1e7 / STEEL.E
SOFT = Material(1e7, 0.3, 7800.0 * SCALE)


def block_on_base(nb=5, E_base=210e9, block=STEEL, scale=1.0, kw=(0.0, 0.0), **kw_contact):
    """A 20 x 10 mm block (4 x 2 Q4) on a 20 x 5 mm base of ``nb`` x 1 Q4 held at its
    bottom: non-matching for ``nb != 4``."""
    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, nb, 1)))
    return from_mesh(
        mesh, {"block": block, "base": Material(E_base, 0.3, 7800.0)},
        damping=Damping(loss_factor=0.02),
        supports=[Spring("block.top_left", "x", scale * 1e7), ("base.bottom", "all")],
        loads=[Traction("block.top", pressure=scale * 20e6, waveform="constant"),
               Traction("block.right", traction=(-scale * 1e7, 0.0), waveform="cos")],
        contact=ContactSpec("block.bottom", mu=MU, partner="base.top", wear_coefficient=kw[0],
                            partner_wear_coefficient=kw[1], **kw_contact),
        observed={"tip": (0.02, 0.015)})


def block_on_rigid(block=STEEL, scale=1.0, kw=0.0):
    return from_mesh(
        rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005)), block,
        damping=Damping(loss_factor=0.02), supports=[Spring("top_left", "x", scale * 1e7)],
        loads=[Traction("top", pressure=scale * 20e6, waveform="constant"),
               Traction("right", traction=(-scale * 1e7, 0.0), waveform="cos")],
        contact=ContactSpec("bottom", mu=MU, wear_coefficient=kw),
        observed={"tip": (0.02, 0.015)})


def solve(model):
    return solve_periodic(model, BASIS, frequency=F_HZ, options=SolveOptions(tol=1e-12),
                          raise_on_failure=True)


def test_auto_pairing_keeps_matching_nodes_and_takes_mortar_otherwise():
    assert block_on_base(nb=4).contact.segments is None
    c = block_on_base(nb=5).contact
    assert c.segments is not None and np.any((c.segments.weights != 0).sum(axis=1) > 2)
    np.testing.assert_allclose(c.segments.weights.sum(axis=1), 1.0, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(c.gap, 0.0)  # a flat face: no geometric gap


@pytest.mark.parametrize("pairing", ["mortar", "node-to-segment"])
def test_stiff_non_matching_base_is_a_rigid_flat(pairing):
    """Soft block on a 1e6 times stiffer base of 5 elements under its 4: contact forces and
    tip motion are those on a rigid flat to 2 x the ratio (measured 0.2 x for node-to-node
    pairs, tests/model/test_interfaces.py)."""
    stiff = block_on_base(E_base=1e7 / RATIO, block=SOFT, scale=SCALE, pairing=pairing)
    a, b = solve(stiff), solve(block_on_rigid(block=SOFT, scale=SCALE))
    assert np.any(b.state == 2) and np.any(b.state == 1)
    np.testing.assert_allclose(a.lam, b.lam, rtol=0, atol=2 * RATIO * np.abs(b.lam).max())
    np.testing.assert_allclose(a.observed["tip"], b.observed["tip"], rtol=0,
                               atol=2 * RATIO * np.abs(b.observed["tip"]).max())


def test_sweep_on_a_stiff_non_matching_base():
    """A sweep (3 points about 2 kHz) of the soft block on the stiff mortar-paired base gives
    the contact forces and tip motion of the sweep on a rigid flat at every point, to 2 x the
    stiffness ratio as the periodic solve above (the sweep goes through the same contact
    transform)."""
    from fretwear.api import sweep

    stiff = block_on_base(E_base=1e7 / RATIO, block=SOFT, scale=SCALE)
    assert stiff.contact.segments is not None
    opts = SolveOptions(tol=1e-12)
    a, b = (sweep(m, BASIS, 1900.0, 2100.0, 3, options=opts)
            for m in (stiff, block_on_rigid(block=SOFT, scale=SCALE)))
    assert a.success and b.success
    np.testing.assert_array_equal(a.frequency_hz, b.frequency_hz)
    for pa, pb in ((p.solution, q.solution) for p, q in zip(a.points, b.points, strict=True)):
        np.testing.assert_allclose(pa.lam, pb.lam, rtol=0, atol=2 * RATIO * np.abs(pb.lam).max())
        np.testing.assert_allclose(pa.observed["tip"], pb.observed["tip"], rtol=0,
                                   atol=2 * RATIO * np.abs(pb.observed["tip"]).max())


def test_wear_and_time_integration_on_a_stiff_non_matching_base():
    """A wear run (3 steps) and 6 periods of time integration of the soft block on the stiff
    mortar-paired base = the same on a rigid flat (the wear coefficients of both surfaces
    added on the rigid flat), to 10 x and 20 x the stiffness ratio (as for node-to-node pairs
    in tests/model/test_interfaces.py); the base's wear on its own nodes, by the mortar
    weights, keeps the total worn volume of its surface."""
    from fretwear.hb.solution import initial_state
    from fretwear.model.projection import partner_node_values
    from fretwear.timedomain.integrate import integrate
    from fretwear.timedomain.options import InitialState, IntegrationOptions
    from fretwear.wear import WearOptions, simulate_wear

    pair = block_on_base(E_base=1e7 / RATIO, block=SOFT, scale=SCALE, kw=(1e-9, 3e-9))
    rigid = block_on_rigid(block=SOFT, scale=SCALE, kw=4e-9)
    opts = WearOptions(max_steps=3, tolerance=0.1)
    wa, wb = (simulate_wear(m, BASIS, frequency=F_HZ, options=opts) for m in (pair, rigid))
    assert wa.success and wb.history.wear_depth[-1].max() > 0
    np.testing.assert_allclose(wa.history.cycles, wb.history.cycles, rtol=10 * RATIO)
    np.testing.assert_allclose(wa.history.wear_depth, wb.history.wear_depth, rtol=0,
                               atol=10 * RATIO * wb.history.wear_depth[-1].max())
    # the partner surface's share (3/4) on the base's nodes: same worn volume (the mortar
    # weights times areas add up to each base node's area)
    depth = 0.75 * wa.history.wear_depth[-1]
    ids, on_base = partner_node_values(pair.contact, depth)
    base_area = {int(n): a for n, a in zip(*_nodal_areas(pair, "base.top"), strict=True)}
    np.testing.assert_allclose(sum(base_area[n] * v for n, v in zip(ids, on_base,
                                                                   strict=True)),
                               depth @ pair.contact.area, rtol=1e-12)
    run = {}
    for key, model in (("pair", pair), ("rigid", rigid)):
        U0, V0 = initial_state(model, solve(model))
        run[key] = integrate(model, F_HZ, options=IntegrationOptions(steps_per_period=256),
                             start=InitialState(U0=U0, V0=V0), n_periods=6, record="last")
    a, b = run["pair"], run["rigid"]
    assert a.success and b.success and np.any(b.state == 2)
    np.testing.assert_allclose(a.lam, b.lam, rtol=0, atol=20 * RATIO * np.abs(b.lam).max())


def _nodal_areas(model, boundary):
    from fretwear.model.loads import nodal_areas

    return nodal_areas(model.mesh, boundary, model.thickness)


def test_two_sided_archard_identity_on_non_matching_meshes():
    """k_w = 1e-13 and 3e-13 1/Pa on a 4 | 5 mortar interface: the worn volume per cycle of
    both surfaces = (ka + kb) / mu x the friction energy per cycle, to 1e-9 (Coulomb's
    equality on the converged samples, as for node-to-node pairs)."""
    ka, kb = 1e-13, 3e-13
    model = block_on_base(kw=(ka, kb))
    sol = solve(model)
    from fretwear.wear.kernels import slip_work

    prob = DLFTProblem(condense(model, F_HZ, [0, *BASIS.harmonics]), model.contact, BASIS,
                       eps=sol.eps, anchor=sol.anchor)
    lu, lx, state, _ = prob.time_law(sol.U.reshape(prob.m, -1))
    Wa, Wb = side_depths(model, wear_coefficients(model) * slip_work(lu, lx, state, sol.eps))
    energy = sol.friction_energy().sum()
    assert energy > 0
    volume = worn_volume(Wa, sol.area) + worn_volume(Wb, sol.area)
    np.testing.assert_allclose(volume, (ka + kb) / MU * energy, rtol=1e-9)


def test_one_refinement_halves_the_distance_to_the_matching_answer():
    """benchmarks/nonmatching.py, levels 0 and 1 (4 | 5 then 8 | 10 elements): the relative
    difference of the tip amplitude from the matching meshes' falls from 8.2e-3 to 2.6e-3
    (measured); asserted: by at least a factor 2."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parents[2] / "benchmarks" / "nonmatching.py"
    spec = importlib.util.spec_from_file_location("nonmatching", path)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    d = []
    for level in (0, 1):
        ref = bench.amplitude(bench.joint_2d(level, 1.0, "node-to-node"))
        d.append(abs(bench.amplitude(bench.joint_2d(level, 1.25, "mortar")) - ref) / ref)
    assert d[1] < 0.5 * d[0] and d[0] < 0.02


# --- bad input: one clear message ---------------------------------------------------------
def lap(**kw):
    """A 2D lap joint: the upper plate [20, 60] mm overlaps the lower [0, 40] mm on
    [20, 40] mm; 2.5 mm elements below, 3.33 mm above."""
    mesh = join(("lower", rectangle(0.04, 0.004, 16, 2)),
                ("upper", rectangle(0.04, 0.004, 12, 2, origin=(0.02, 0.004))))
    return from_mesh(mesh, STEEL, thickness=0.01,
                     supports=[("lower.bottom", "all"), Spring("upper.right", "x", 1e7),
                               Spring("upper.right", "y", 1e8)],
                     loads=[Traction("upper.top", pressure=2e7, region={"x": (0.02, 0.04)})],
                     contact=ContactSpec("upper.bottom", mu=0.3, partner="lower.top", **kw))


def test_lap_joint_overlap_by_region():
    c = lap(region={"x": (0.02, 0.04)}).contact
    assert c.n_nodes == 7 and c.segments is not None
    np.testing.assert_allclose(c.area.sum(), 0.02 * 0.01, rtol=1e-14)


def test_whole_face_of_a_lap_joint_suggests_the_overlap():
    """The whole bottom of the upper plate against the lower plate's top: most nodes lie
    beyond the lower plate; the message lists them and gives the region of the overlap."""
    with pytest.raises(InputError) as info:
        lap()
    msg = str(info.value)
    assert msg.startswith("contact 'contact': 6 of 13 contact nodes have no partner on "
                          "boundary 'lower.top' within")
    assert "6 of them lie outside the partner face: restrict the contact boundary to the " \
           "part that touches it (region such as region = {x = [0.02, 0.04]})" in msg
    with pytest.raises(InputError, match=r"have no partner on boundary 'lower.top' within "
                                         r".* m: nodes \d+, \d+.*restrict"):
        lap(pairing="node-to-node")


def test_unmatched_node_to_node_names_the_nodes_and_the_other_pairings():
    with pytest.raises(InputError, match=r"3 of 5 contact nodes have no partner on boundary "
                                         r"'base.top' within 2.5e-08 m: nodes 1, 2, 3 "
                                         r"\(farthest: node 2 at \(0.01, 0.005\), 0.002 m "
                                         r"away\): the two "
                                         r"boundaries need matching nodes \(pairing = "
                                         r"\"node-to-segment\" pairs non-matching meshes\), or "
                                         r"a larger tolerance"):
        block_on_base(nb=5, pairing="node-to-node")


def test_bad_pairings():
    with pytest.raises(InputError, match=r"contact 'contact': pairing = 'mortar ' ; expected "
                                         r"one of \['auto', 'node-to-node', 'mortar', "
                                         r"'node-to-segment'\]".replace(" ;", ";")):
        ContactSpec("bottom", mu=0.3, partner="top", pairing="mortar ")
    with pytest.raises(InputError, match="pairing = 'mortar' without a partner boundary"):
        ContactSpec("bottom", mu=0.3, pairing="mortar")


def test_mortar_refuses_a_node_whose_area_is_not_covered():
    """The region ends in the middle of an element of the lower plate: fine (covered); one
    that reaches beyond the lower plate's end by a whole upper element is refused, naming the
    uncovered fraction."""
    with pytest.raises(InputError, match=r"lie outside the partner face|uncovered fraction"):
        lap(region={"x": (0.02, 0.0434)}, pairing="mortar", tolerance=0.01)


def test_mortar_and_rigid_interfaces_combine():
    """A mortar interface and a node-to-rigid one in one model: each interface's rows of the
    local transform are those of the model with that interface alone (the combined record
    pads the weights; the rigid nodes have none)."""
    mesh = join(("block", rectangle(0.02, 0.01, 4, 2, origin=(0.0, 0.005))),
                ("base", rectangle(0.02, 0.005, 5, 1)))
    held = [Spring("block.top_left", "x", 1e7), Spring("block.top", "y", 1e7),
            ("base.bottom", "all")]
    specs = [ContactSpec("block.bottom", mu=MU, partner="base.top", name="joint"),
             ContactSpec("block.right", mu=MU, name="wall", gap=1e-3,
                         region={"y": (0.0075, 0.015)})]  # not the corner of the joint
    both = from_mesh(mesh, STEEL, supports=held, contact=specs).contact
    assert both.names() == ["joint", "wall"] and both.segments is not None
    T = both.local_transform(2 * mesh.points.shape[0]).toarray()
    rows = 0
    for spec in specs:
        one = from_mesh(mesh, STEEL, supports=held, contact=spec).contact
        Ti = one.local_transform(2 * mesh.points.shape[0]).toarray()
        np.testing.assert_array_equal(T[rows:rows + Ti.shape[0]], Ti)
        rows += Ti.shape[0]
    assert rows == T.shape[0]
    np.testing.assert_array_equal(both.segments.weights[both.interface_index() == 1], 0.0)
