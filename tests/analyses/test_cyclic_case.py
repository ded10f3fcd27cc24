"""A sector described by a case file ([cyclic]): the run equals the whole disk, and the bad
inputs of the new keys are one-line messages naming the key.

Reference: the disk of N turned copies of the Python sector of tests/helpers/cyclic.py
(fretwear.model.cyclic.whole_disk), which the case file reproduces node by node."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from fretwear.analyses.run import load_case, run_case
from fretwear.errors import InputError
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions
from fretwear.hb.periodic import solve_periodic
from fretwear.io.case import build_model
from fretwear.io.results import read_results
from fretwear.model.cyclic import whole_disk
from tests.helpers.cyclic import sector_model, write_sector_case

N, EO = 8, 3
PERIODIC = ('[analysis]\ntype = "periodic"\nfrequency = 9000.0\nharmonics = 3\n'
            'n_samples = 32\neps = 3e9\ntol = 1e-13\nmax_iter = 200\n')


def test_case_file_sector_equals_the_disk(tmp_path):
    """The periodic analysis of the case-file sector (tip friction and an inter-blade
    contact between neighbours, EO 3 of N = 8: harmonics 1-3 in indices 3, 6, 1) equals one
    DLFT solve of the whole disk assembled from the Python sector at the same eps: sector
    0's contact harmonics to 1e-8 relative (the agreement of the exact reduction, tests/hb/
    test_cyclic.py; the results file adds only its write). The results record N, EO and
    the harmonic index of every harmonic."""
    path, _ = write_sector_case(tmp_path, N, EO, slit=True, analysis=PERIODIC)
    out = run_case(path, progress=False, echo=False)
    assert out.success
    ds = read_results(out.results)
    sector, model = sector_model(N, slit=True)
    sol_d = solve_periodic(whole_disk(sector, EO), FourierBasis((1, 2, 3), 32),
                           frequency=9000.0, eps=3e9,
                           options=SolveOptions(tol=1e-13, max_iter=200))
    assert sol_d.success
    nc = model.contact.n_nodes
    U = ds["contact_displacement_coefficients"].values
    U_d = sol_d.U[:nc]
    assert U.shape == U_d.shape
    assert np.max(np.abs(U - U_d)) < 1e-8 * np.abs(U_d).max()
    assert int(ds.attrs["cyclic_sectors"]) == N and int(ds.attrs["engine_order"]) == EO
    np.testing.assert_array_equal(np.atleast_1d(ds.attrs["harmonic_index"]), [0, 3, 6, 1])
    assert ds.attrs["condensation"] == "exact"


BAD = [
    ("match", "point = [0.001, 0.0, 0.0]", "cyclic: cyclic boundaries: left node 0 at "),
    ("engine order", "engine_order = 8", "cyclic.engine_order = 8: expected an integer with "
     "|engine_order| < sectors = 8"),
    ("axis", "axis = [0.0, 0.0, 2.0]", "cyclic.axis = [0.0, 0.0, 2.0]: expected a unit vector"),
    ("self-pairing", "", 'cyclic.neighbour = "neighbours": expected a [[contact]] block with a '
     "partner boundary other than its boundary"),
]


@pytest.mark.parametrize("what, lines, message", BAD, ids=[b[0] for b in BAD])
def test_bad_cyclic_keys(tmp_path, what, lines, message):
    """Boundaries that do not match under the rotation, an engine order out of range, an
    axis that is not a unit vector, a damper pairing a boundary with itself: one line
    naming the key (the case file is otherwise valid: the good one builds)."""
    path, _ = write_sector_case(tmp_path, N, EO, slit=True, analysis=PERIODIC)
    build_model(load_case(path))  # the unchanged case is good
    text = path.read_text()
    if what == "self-pairing":
        text = text.replace('partner = "slit_b"', 'partner = "slit_a"')
    else:
        table = text[text.index("[cyclic]"):]
        keys = {line.split("=")[0].strip() for line in lines.splitlines()}
        kept = "\n".join(line for line in table.splitlines()
                         if line.split("=")[0].strip() not in keys)
        text = text[:text.index("[cyclic]")] + kept.replace("[cyclic]", "[cyclic]\n" + lines,
                                                            1)
    path.write_text(text)
    with pytest.raises(InputError) as err:
        build_model(load_case(path))
    assert str(err.value).startswith(message), str(err.value)
    assert len(str(err.value).splitlines()) == 1


def test_centrifugal_table(tmp_path):
    """``[centrifugal]`` adds the load of fretwear.model.rotation.centrifugal_load (tested
    against closed forms in tests/model/test_rotation.py) about the ``[cyclic]`` axis by
    default, bit for bit; a bad axis names its key."""
    from fretwear.model.rotation import centrifugal_load

    path, _ = write_sector_case(tmp_path, N, EO, analysis=PERIODIC)
    text = path.read_text()
    path.write_text(text + "[centrifugal]\nspeed = 1500.0\n")
    model = build_model(load_case(path))
    _, ref = sector_model(N)
    want = centrifugal_load(ref, 1500.0).vector
    assert model.loads[-1].name == "centrifugal" and model.loads[-1].waveform == "constant"
    np.testing.assert_array_equal(model.loads[-1].vector, want)
    assert len(model.loads) == len(ref.loads) + 1
    path.write_text(text + "[centrifugal]\nspeed = 1500.0\naxis = [0.0, 1.0, 0.0]\n")
    with pytest.raises(InputError) as err:
        build_model(load_case(path))
    assert str(err.value).startswith("centrifugal: axis = [0.0, 1.0, 0.0]: a 2D sector turns")


@pytest.mark.parametrize("analysis, message", [
    ('[analysis]\ntype = "modes"\n', 'analysis.type = "modes": not available on a sector'),
    ('[analysis]\ntype = "sweep"\nf_min = 1e4\nf_max = 1.2e4\nlinear_references = ["free"]\n',
     'analysis.linear_references = ["free"]: expected none on a sector'),
])
def test_analyses_that_would_free_the_boundaries_are_refused(tmp_path, analysis, message):
    """Analyses that would treat the sector as a structure with free cyclic boundaries (the
    modes of the sector alone, a sweep's linear FRFs of the sector alone) are refused in one
    line before anything runs."""
    path, _ = write_sector_case(tmp_path, N, EO, analysis=analysis)
    with pytest.raises(InputError) as err:
        run_case(path, progress=False, echo=False)
    assert str(err.value).startswith(message), str(err.value)
    assert len(str(err.value).splitlines()) == 1


def test_sweep_checkpoint_is_not_reused_for_another_engine_order(tmp_path):
    """A sector sweep resumed with another engine order is refused as a checkpoint of another
    sweep (its key holds N and EO: the model alone is the same sector, and without them the
    stale points of EO 3 were taken for EO 2); with the same one it resumes (the sweep's own
    report ``resumed_from``)."""
    from fretwear.hb.cyclic import cyclic_condenser
    from fretwear.hb.options import SweepOptions
    from fretwear.hb.sweep import sweep

    sector, model = sector_model(N)
    basis = FourierBasis((1,), 16)
    ck = tmp_path / "sweep.ckpt.npz"
    opts = SweepOptions(eps=3e9, checkpoint=ck)
    first = sweep(model, basis, 9000.0, 9500.0, 2, options=opts,
                  condenser=cyclic_condenser(sector, 3))
    assert first.success and ck.is_file()
    resume = dataclasses.replace(opts, resume=True)
    again = sweep(model, basis, 9000.0, 9500.0, 2, options=resume,
                  condenser=cyclic_condenser(sector, 3))
    assert again.resumed_from == 2
    with pytest.raises(InputError, match="was written for a different model or different"):
        sweep(model, basis, 9000.0, 9500.0, 2, options=resume,
              condenser=cyclic_condenser(sector, 2))


MISTUNED = PERIODIC.replace("[analysis]\n", '[analysis]\ncondensation = "exact"\n')


def test_mistuned_case_equals_the_python_mistuned_disk(tmp_path):
    """``[cyclic.mistuning]`` runs the whole disk: with factors all 1 its periodic solve is
    the whole disk of the Python sector (fretwear.model.cyclic.whole_disk), with 5 %
    scattered Young's moduli and friction the Python mistuned disk
    (fretwear.model.mistuning.mistuned_disk); every sector's contact harmonics to 1e-8
    relative (both converged to 1e-13). The attributes record N, EO and the factors; every
    sector has its observed point ``tip@j``."""
    from fretwear.model.mistuning import mistuned_disk, mistuning

    young = [1.0, 1.05, 0.95, 1.02, 0.98, 1.0, 1.04, 0.97]
    mu = [1.0] * 4 + [1.1] * 4
    sector, _ = sector_model(N, slit=True)
    for factors, disk in (({"young": [1.0] * N}, whole_disk(sector, EO)),
                          ({"young": young, "mu": mu},
                           mistuned_disk(sector, EO, mistuning(N, young=young, mu=mu)))):
        path, _ = write_sector_case(tmp_path, N, EO, slit=True, analysis=MISTUNED)
        lines = "".join(f"{k} = {v}\n" for k, v in factors.items())
        path.write_text(path.read_text() + "\n[cyclic.mistuning]\n" + lines)
        out = run_case(path, tmp_path / "out", progress=False, echo=False)
        assert out.success
        ds = read_results(out.results)
        sol_d = solve_periodic(disk, FourierBasis((1, 2, 3), 32), frequency=9000.0, eps=3e9,
                               options=SolveOptions(tol=1e-13, max_iter=200))
        U = ds["contact_displacement_coefficients"].values
        assert U.shape == sol_d.U.shape
        assert np.max(np.abs(U - sol_d.U)) < 1e-8 * np.abs(sol_d.U).max()
        assert int(ds.attrs["mistuned_sectors"]) == N and int(ds.attrs["engine_order"]) == EO
        np.testing.assert_array_equal(ds.attrs["mistuning_young"], factors["young"])
        assert list(ds["point"].values[:2]) == ["tip@0", "tip@1"]


@pytest.mark.parametrize("lines, message", [
    ("young = [1.0, 1.0]\n", "cyclic.mistuning.young = [1.0, 1.0]: expected 8 factors"),
    ("std = 0.02\n", "[cyclic.mistuning]: std without seed"),
    ("std = 0.02\nseed = 1\nyoung = [1.0]\n", "cyclic.mistuning.young = [1.0]: expected no "
     "list"),
    ("mu = [1.0, 0.0]\n", "cyclic.mistuning.mu"),
])
def test_bad_mistuning_keys(tmp_path, lines, message):
    """Bad ``[cyclic.mistuning]`` keys: one line naming the key."""
    path, _ = write_sector_case(tmp_path, N, EO, analysis=PERIODIC)
    path.write_text(path.read_text() + "\n[cyclic.mistuning]\n" + lines)
    with pytest.raises(InputError) as err:
        build_model(load_case(path))
    assert str(err.value).startswith(message), str(err.value)
    assert len(str(err.value).splitlines()) == 1


def test_drawn_mistuning_is_the_seeded_draw(tmp_path):
    """``std`` and ``seed``: the factors of fretwear.model.mistuning.random_mistuning."""
    from fretwear.model.mistuning import random_mistuning

    path, _ = write_sector_case(tmp_path, N, EO, analysis=PERIODIC)
    path.write_text(path.read_text() + "\n[cyclic.mistuning]\nstd = 0.03\nseed = 4\n"
                    'draw = ["young", "wear"]\n')
    mt = build_model(load_case(path)).meta["mistuning"]
    want = random_mistuning(N, 0.03, 4, ("young", "wear"))
    np.testing.assert_array_equal(mt.young, want.young)
    np.testing.assert_array_equal(mt.wear, want.wear)
    assert np.all(mt.mu == 1.0)


def test_whole_disk_paraview_equals_the_disk_solution(tmp_path):
    """``[output] whole_disk = true``: the disk rebuilt from the sector's periodic solution
    (every sector turned, harmonic n phased by e^{i n EO j 2 pi / N}) equals, node by node
    and instant by instant, the DLFT solution of the whole disk assembled from N copies
    (fretwear.model.cyclic.whole_disk, solved to 1e-13, recovered exactly) to 1e-8 of the
    largest displacement; n_samples x EO = 32 x 3 is not a multiple of 8, so the sampled
    instants are the same on both sides but the disk is no exact travelling wave of them
    (docs/theory.md): the agreement is that of the two exact balances (measured 1.1e-15)."""
    import meshio

    from fretwear.hb.reduce import recover
    from fretwear.model.cyclic import _disk_numbering

    path, _ = write_sector_case(tmp_path, N, EO, slit=True, analysis=PERIODIC)
    path.write_text(path.read_text().replace("[output]\n", "[output]\nwhole_disk = true\n"))
    out = run_case(path, tmp_path / "out", progress=False, echo=False)
    pvd = [p for p in out.files if p.name == "periodic-disk.pvd"]
    assert out.success and pvd
    sector, model = sector_model(N, slit=True)
    disk = whole_disk(sector, EO)
    b = FourierBasis((1, 2, 3), 32)
    sol = solve_periodic(disk, b, frequency=9000.0, eps=3e9,
                         options=SolveOptions(tol=1e-13, max_iter=200))
    nc, d, H = sol.U.shape
    full = recover(disk, 9000.0, b.orders, b.to_complex(sol.U.reshape(nc * d, H)))
    samples = b.to_time(b.from_complex(full))  # (disk DOFs, instants)
    maps, _ = _disk_numbering(sector)
    nn = model.mesh.points.shape[0]
    files = sorted((tmp_path / "out" / "periodic-disk").glob("disk-*.vtu"))
    assert len(files) == 32
    for j in (0, 5, 17):
        got = meshio.read(files[j]).point_data["displacement"][:, :2]
        want = np.concatenate([samples[maps[s], j] for s in range(N)]).reshape(N * nn, 2)
        assert np.max(np.abs(got - want)) < 1e-8 * np.abs(samples).max()


def test_whole_disk_wear_paraview_equals_the_disk_wear(tmp_path):
    """``[output] whole_disk = true`` in a wear run: the worn surfaces of the disk rebuilt from
    the sector (every sector with the sector's wear, the tuned assumption) equal, node by
    node and step by step, the wear of the whole disk assembled from N copies
    (fretwear.model.cyclic.whole_disk) run through the same two explicit steps of 1e6
    cycles (one harmonic, 16 samples: a few seconds), both surfaces of the tip contact and
    of the pair between neighbours (whose partner is the next sector's node) wearing; to
    1e-12 of the deepest wear: the two exact balances are solved to 1e-13 (the sector and
    the disk agree to rounding, tests/hb/test_cyclic.py::test_wear_steps_equal_the_disk)."""
    import meshio

    from fretwear.wear.laws import side_depths
    from fretwear.wear.options import WearOptions
    from fretwear.wear.simulate import BalanceSetup, simulate_wear

    wear = ('[analysis]\ntype = "wear"\nfrequency = 9000.0\nharmonics = 1\nn_samples = 16\n'
            'eps = 3e9\ntol = 1e-13\nscheme = "explicit"\nadaptive = false\n'
            'initial_jump = 1e6\nmax_steps = 2\nmax_cycles = 1e9\n')
    path, _ = write_sector_case(tmp_path, N, EO, slit=True, analysis=wear)
    text = path.read_text().replace("[output]\n", "[output]\nwhole_disk = true\n")
    text = text.replace('name = "casing"\n', 'name = "casing"\nwear_coefficient = 1e-14\n')
    text = text.replace('name = "neighbours"\n', 'name = "neighbours"\nwear_coefficient = '
                        '1e-14\npartner_wear_coefficient = 2e-14\n')
    path.write_text(text)
    out = run_case(path, tmp_path / "out", progress=False, echo=False)
    assert out.success and any(p.name == "wear-disk.pvd" for p in out.files)
    sector, model = sector_model(N, slit=True, wear=1e-14)
    sector = dataclasses.replace(sector, model=dataclasses.replace(model, contact=dataclasses
                                 .replace(model.contact, partner_wear_coefficient=np.where(
                                     sector.neighbour_nodes(), 2e-14, 0.0))))
    opts = WearOptions(scheme="explicit", adaptive=False, initial_jump=1e6, max_steps=2,
                       max_cycles=1e9, solve=SolveOptions(tol=1e-13, max_iter=100,
                                                          strategy=("start",)))
    disk = whole_disk(sector, EO)
    r_d = simulate_wear(disk, FourierBasis((1,), 16), frequency=9000.0, options=opts,
                        balance=BalanceSetup(eps=3e9))
    assert r_d.success and r_d.history.cycles[-1] == 2e6
    c, nn = disk.contact, model.mesh.points.shape[0]
    nc = model.contact.n_nodes
    j = np.repeat(np.arange(N), nc)  # the sector of every disk contact node
    nb = np.tile(sector.neighbour_nodes(), N)
    files = sorted((tmp_path / "out" / "wear-disk").glob("disk-*.vtu"))
    assert len(files) == 3  # the start and two steps
    deepest = r_d.history.wear_depth.max()
    assert deepest > 1e-7  # it wears
    for k, f in enumerate(files):
        got = meshio.read(f).point_data["worn_depth"]
        wa, wb = side_depths(disk, r_d.history.wear_depth[k])
        want = np.full(N * nn, np.nan)
        want[j * nn + np.asarray(c.node_ids)] = wa
        pair = np.asarray(c.partner_ids) >= 0
        want[(np.where(nb, j + 1, j) % N * nn + np.asarray(c.partner_ids))[pair]] = wb[pair]
        assert np.array_equal(np.isnan(got), np.isnan(want))
        ok = ~np.isnan(want)
        assert np.max(np.abs(got[ok] - want[ok])) <= 1e-12 * deepest
