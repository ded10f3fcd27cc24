"""The continuation state of a sweep (:mod:`fretwear.hb.branch`): the reduced models kept within
their memory budget, the secant predictor and the stick anchors of the loading history,
compared with hand-computed values."""

import time

import numpy as np
from helpers.blocks import closed_block

from fretwear.hb import branch
from fretwear.hb.branch import Branch, Problems
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.reduce import exact_condenser

BASIS = FourierBasis.up_to(3, 32)


def test_reduced_models_kept_within_the_memory_budget(monkeypatch):
    """The sweep's cache of reduced models keeps at most CACHE_SIZE of them and no more bytes
    than CACHE_BYTES, always the newest (counted against the models' own sizes)."""
    model = closed_block()
    probs = Problems(model, BASIS, None, 1e9, exact_condenser(model))
    one = probs.get(2 * np.pi * 1000.0, None).reduced.Z.nbytes
    monkeypatch.setattr(branch, "CACHE_BYTES", int(2.5 * one))
    for f in (1100.0, 1200.0, 1300.0):
        probs.get(2 * np.pi * f, None)
    assert list(probs.cache) == [2 * np.pi * 1200.0, 2 * np.pi * 1300.0]
    monkeypatch.setattr(branch, "CACHE_BYTES", one // 2)  # smaller than one: the newest only
    probs.get(2 * np.pi * 1400.0, None)
    assert list(probs.cache) == [2 * np.pi * 1400.0]


def test_predictor_and_anchors_follow_the_history():
    """No point: no prediction, the first anchors. One point: that point. Two: the secant
    ``U1 + (U1 - U0) (w - w1) / (w1 - w0)`` (exact for harmonics linear in w, checked at a
    third frequency), and the anchors are the last point's mean tangential positions
    ``U[:, 1:, 0]`` (contact-local: component 0 is the normal one)."""
    model = closed_block()
    nc, d = model.contact.n_nodes, model.contact.dim
    first = np.full((nc, d - 1), 7.0)
    b = Branch(model, first)
    assert b.predict(10.0) is None and b.anchor() is first
    rng = np.random.default_rng(1)
    A, B = rng.standard_normal((2, nc * d, BASIS.size))
    b.history.append((10.0, A + 10.0 * B))
    np.testing.assert_array_equal(b.predict(30.0), A + 10.0 * B)
    b.history.append((20.0, A + 20.0 * B))
    np.testing.assert_allclose(b.predict(35.0), A + 35.0 * B, rtol=0, atol=1e-12)
    U = (A + 20.0 * B).reshape(nc, d, -1)
    np.testing.assert_array_equal(b.anchor(), U[:, 1:, 0])


def test_lap_is_wall_and_cpu_since_the_last_lap():
    """``Branch.lap``: the wall and CPU seconds since the previous lap, the clock restarted.
    Against ``time.sleep`` (wall time that takes no CPU): the first lap holds at least the
    sleep's 20 ms of wall time and less than 10 ms of CPU; a lap right after is short."""
    b = Branch(closed_block(), None)
    b.lap()
    time.sleep(0.02)
    wall, cpu = b.lap()
    assert wall >= 0.02 and cpu < 0.01
    assert b.lap()[0] < 0.02
