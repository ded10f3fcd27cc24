"""The mistuned disk (fretwear.model.mistuning) against the tuned sector, against a lumped chain
written here, and against Whitehead's bound.

References: the tuned sector's engine-order FRF (fretwear.hb.cyclic.cyclic_frf, the exact
cyclic reduction) spread over the disk with the wave's phases; a scalar chain of N disk and N
blade masses assembled here by hand (the lumped blisk's springs act alike in x and y, so the
disk's x and y motions are two such chains); Whitehead's bound (1 + sqrt(N)) / 2. The linear
responses are direct dense solves of 36 DOFs: they agree to rounding (1e-10 relative).
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers.cyclic import sector_model

from fretwear.errors import InputError
from fretwear.examples.blisk import lumped_blisk
from fretwear.hb.cyclic import cyclic_frf, cyclic_modes
from fretwear.model.cyclic import whole_disk
from fretwear.model.mistuning import (
    amplification_factor,
    blade_amplitudes,
    mistuned_disk,
    mistuning,
    random_mistuning,
    sector_responses,
    whitehead_bound,
)

N, EO = 12, 3


def frf(disk, freqs):
    """Dense direct solve of the disk's first harmonic, (nf, ndof) [m]."""
    free = disk.free_dofs()
    F = disk.load_harmonics(1)[1][free]
    K, M = disk.K.toarray()[np.ix_(free, free)], disk.M.toarray()[np.ix_(free, free)]
    D = disk.D.toarray()[np.ix_(free, free)]
    out = np.zeros((len(freqs), disk.ndof), dtype=complex)
    for i, f in enumerate(freqs):
        w = 2 * np.pi * f
        out[i, free] = np.linalg.solve(K + 1j * D - w * w * M, F)
    return out


def blades(disk, U):
    """(nf, N) the blade responses at the observed points ``blade@j``."""
    return blade_amplitudes(np.stack([U[:, p.dofs] for p in disk.observed], axis=1))


def test_zero_mistuning_is_the_tuned_sector():
    """Every factor 1: each sector's response (its own axes) is the tuned sector's
    engine-order FRF times e^{i EO j 2 pi / N} (1e-10 relative), and the amplification
    factor is 1 to rounding (1e-12)."""
    s = lumped_blisk(N, coupling=1e6)
    freqs = [440.0, 466.0, 480.0]
    disk = mistuned_disk(s, EO, mistuning(N))
    U = frf(disk, freqs)
    per = sector_responses(s, U)
    ref = cyclic_frf(s, EO, freqs)
    phase = np.exp(1j * EO * np.arange(N) * s.angle)
    want = ref[:, None, :] * phase[None, :, None]
    assert np.max(np.abs(per - want)) < 1e-10 * np.abs(want).max()
    tuned_blade = blade_amplitudes(ref[:, s.model.observed[0].dofs])
    assert abs(amplification_factor(blades(disk, U), tuned_blade) - 1) < 1e-12
    assert mistuning(N).tuned and not random_mistuning(N, 0.01, 1).tuned


def test_zero_mistuning_is_whole_disk_with_contact():
    """On a mesh sector with tip friction and an inter-blade contact, factors 1 give
    whole_disk's matrices, contact record and loads exactly (the same assembly)."""
    sector, _ = sector_model(6, slit=True, wear=1e-12)
    a, b = whole_disk(sector, 2), mistuned_disk(sector, 2, mistuning(6))
    for name in ("K", "M", "C", "D"):
        assert abs(getattr(a, name) - getattr(b, name)).max() == 0.0
    for name in ("dofs", "frame", "partner_dofs", "coords"):
        assert np.array_equal(getattr(a.contact, name), getattr(b.contact, name))
    nc = a.contact.n_nodes
    for name in ("mu", "wear_coefficient", "partner_wear_coefficient"):
        assert np.array_equal(np.broadcast_to(getattr(a.contact, name), (nc,)),
                              getattr(b.contact, name))
    assert np.array_equal(a.load_harmonics(2), b.load_harmonics(2))


def chain_frf(young, kc, f, eo):
    """The lumped blisk as two scalar chains (x, y) written out: disk mass j grounded
    (k_g f_j), tied to disk mass j+1 (k_c f_j) and to its blade (k_b f_j); loads: the
    tangential force of blade j turned by j alpha, phased e^{i EO j alpha}. (N, 2) blade
    displacement amplitudes in the disk's axes."""
    kg, kb, md, mb, eta, force = 1e7, 1e6, 0.5, 0.1, 0.005, 20.0
    n = young.size
    a = 2 * np.pi / n
    K = np.zeros((2 * n, 2 * n))  # disk masses 0..n-1, blades n..2n-1

    def spring(p, q, k):
        K[p, p] += k
        K[q, q] += k
        K[p, q] -= k
        K[q, p] -= k

    for j in range(n):
        K[j, j] += kg * young[j]
        spring(j, (j + 1) % n, kc * young[j])
        spring(j, n + j, kb * young[j])
    M = np.diag([md] * n + [mb] * n)
    w = 2 * np.pi * f
    Z = K * (1 + 1j * eta) - w * w * M
    theta = np.arange(n) * a + a / 2  # the blades' angles: the force is along e_t
    F = np.zeros((2 * n, 2), dtype=complex)
    F[n:, 0] = -force * np.sin(theta) * np.exp(1j * eo * np.arange(n) * a)
    F[n:, 1] = force * np.cos(theta) * np.exp(1j * eo * np.arange(n) * a)
    return np.linalg.solve(Z, F)[n:]


def test_mistuned_disk_equals_a_chain_written_out():
    """A random Young's modulus mistuning (2 %): every blade's displacement in the disk's
    axes equals the hand-written chain's, to 1e-10 relative, at three frequencies."""
    s = lumped_blisk(N, coupling=1e6)
    mt = random_mistuning(N, 0.02, 5)
    disk = mistuned_disk(s, EO, mt)
    freqs = [455.0, 466.0, 478.0]
    U = frf(disk, freqs)
    for i, f in enumerate(freqs):
        got = np.stack([U[i, p.dofs] for p in disk.observed])
        want = chain_frf(mt.young, 1e6, f, EO)
        assert np.max(np.abs(got - want)) < 1e-10 * np.abs(want).max()


def ensemble_amplification(coupling, members=6):
    """The largest amplification over a seeded ensemble (2 % Young's modulus scatter) of the
    lumped blisk (ground stiffness 1e6 N/m) around the tuned resonance of its engine order
    (the lowest mode of index EO, +-10 %, 101 frequencies)."""
    s = lumped_blisk(N, coupling=coupling, ground_stiffness=1e6)
    f0 = cyclic_modes(s, EO, 1)[0][0]
    freqs = np.linspace(0.9 * f0, 1.1 * f0, 101)
    tuned = mistuned_disk(s, EO, mistuning(N))
    ref = blades(tuned, frf(tuned, freqs))
    return max(amplification_factor(blades(d, frf(d, freqs)), ref) for d in
               (mistuned_disk(s, EO, random_mistuning(N, 0.02, seed))
                for seed in range(members)))


@pytest.fixture(scope="module")
def amplification():
    """Coupling k_c [N/m] -> the ensemble's amplification: the family's frequencies spread
    over the harmonic indices by 0.2 %, 2 % and 65 % at 1e3, 1e4, 1e6 N/m."""
    return {c: ensemble_amplification(c) for c in (1e3, 1e4, 1e6)}


def test_ensemble_amplification_within_whiteheads_bound(amplification):
    """Whitehead: no member amplifies beyond (1 + sqrt(12)) / 2 = 2.23, and the largest
    blade of some member is above the tuned response (> 1) at every coupling."""
    for amp in amplification.values():
        assert 1.0 < amp < whitehead_bound(N)


def test_amplification_peaks_at_weak_coupling(amplification):
    """Whitehead's argument: the amplification is largest where the coupling spreads the
    family's frequencies by about the mistuning's frequency scatter (1 % for 2 % on the
    stiffness): k_c = 1e4 (2 %); less where the blades are nearly independent (1e3: 0.2 %)
    or strongly coupled (1e6: 50 %). Measured 1.16, 1.52, 1.16 on the 6 members."""
    weak, mid, strong = amplification[1e3], amplification[1e4], amplification[1e6]
    assert mid > 1.2 * weak and mid > 1.2 * strong


def test_mistuning_factors_land_on_each_sector():
    """Sector j's contact nodes carry mu f_mu,j and k_w f_w,j; its stiffness f_E,j K (the
    disk's K is linear in the factors: K(f) - K(1) = sum (f_j - 1) A_j K A_j^T)."""
    sector, model = sector_model(6, wear=1e-12)
    f = np.array([1.0, 1.1, 0.9, 1.0, 1.05, 0.95])
    mt = mistuning(6, young=f, mu=f[::-1], wear=2 * f)
    disk = mistuned_disk(sector, 0, mt)
    nc = model.contact.n_nodes
    assert np.allclose(disk.contact.mu, 0.3 * np.repeat(f[::-1], nc), rtol=1e-15)
    assert np.allclose(disk.contact.wear_coefficient, 2e-12 * np.repeat(f, nc), rtol=1e-15)
    one = mistuned_disk(sector, 0, mistuning(6, young=[1, 2, 1, 1, 1, 1]))
    tuned = mistuned_disk(sector, 0, mistuning(6))
    from fretwear.model.cyclic import sector_maps

    A1 = sector_maps(sector)[0][1]
    assert abs((one.K - tuned.K) - A1 @ model.K @ A1.T).max() < 1e-6 * abs(model.K).max()
    assert [p.name for p in disk.observed][:2] == ["tip@0", "tip@1"]


@pytest.mark.parametrize("kwargs, match", [
    ({"young": [1.0, 1.0]}, "2 factors given; expected 4"),
    ({"mu": [1.0, -1.0, 1.0, 1.0]}, "expected positive factors"),
    ({"wear": "x"}, "expected 4 numbers"),
])
def test_bad_mistuning_is_one_line(kwargs, match):
    with pytest.raises(InputError, match=match):
        mistuning(4, **kwargs)


def test_bad_draws_and_disk_size_are_one_line():
    with pytest.raises(InputError, match="std = 0.7"):
        random_mistuning(4, 0.7, 1)
    with pytest.raises(InputError, match="kinds"):
        random_mistuning(4, 0.01, 1, kinds=("mass",))
    with pytest.raises(InputError, match="expected a Mistuning of the disk's 12 sectors"):
        mistuned_disk(lumped_blisk(N), EO, mistuning(4))
    assert random_mistuning(4, 0.01, 3).young.tolist() == random_mistuning(4, 0.01, 3) \
        .young.tolist()
