"""fretwear.threads: the BLAS thread count of the drivers. The count is read back through
threadpoolctl (independent of fretwear: it asks the loaded BLAS library itself); the drivers'
own use is tested in tests/test_api.py."""

import numpy as np
import pytest

from fretwear import threads
from fretwear.errors import InputError

threadpoolctl = pytest.importorskip("threadpoolctl")


def blas() -> set:
    return {i["num_threads"] for i in threadpoolctl.threadpool_info() if i["user_api"] == "blas"}


@pytest.fixture
def fresh(monkeypatch):
    """The count read anew from the environment, restored after the test."""
    monkeypatch.setattr(threads, "_state", {})
    yield monkeypatch


def test_limited_sets_and_restores_the_blas_threads(fresh):
    if not blas():
        pytest.skip("no BLAS library reported by threadpoolctl")
    fresh.setenv("FRETWEAR_THREADS", "1")
    seen = []

    @threads.limited
    def work():
        seen.append(blas())
        return np.ones((3, 3)) @ np.ones(3)

    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        outside = blas()
        np.testing.assert_array_equal(work(), [3.0, 3.0, 3.0])
        assert seen == [{1}] and blas() == outside
        threads.set_blas_threads(None)  # not limited: the caller's setting is seen inside
        work()
        assert seen[-1] == outside


@pytest.mark.parametrize("raw, expected", [("1", 1), (" 3 ", 3), ("none", None), ("all", None)])
def test_environment_variable(fresh, raw, expected):
    fresh.setenv("FRETWEAR_THREADS", raw)
    assert threads.blas_threads() == expected


@pytest.mark.parametrize("raw", ["0", "-2", "two", "1.5"])
def test_bad_environment_variable_is_one_line(fresh, raw):
    fresh.setenv("FRETWEAR_THREADS", raw)
    with pytest.raises(InputError, match=f"FRETWEAR_THREADS = '{raw}': expected a whole number "
                                         ">= 1 or 'none'"):
        threads.blas_threads()


@pytest.mark.parametrize("n", [0, -1, 1.5, True, "2"])
def test_bad_count_is_refused(fresh, n):
    with pytest.raises(InputError, match=r"set_blas_threads\("):
        threads.set_blas_threads(n)


class _Stop(Exception):
    """Raised by the recorder once it has seen the thread count inside a driver."""


def _block():
    from fretwear.model import ContactSpec, Material, Spring, Traction, from_mesh, rectangle

    return from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     supports=[Spring(at=(0.0, 0.005), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=1e5, waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.3))


def _sector():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from helpers.cyclic import sector_model

    return sector_model(4)[0]


#: public driver -> (module of the function it calls inside, that function, its arguments)
DRIVERS = {
    "run": ("fretwear.analyses.python_run", "run_built",
            lambda fw, tmp: (_block(), "modes", tmp)),
    "load_levels": ("fretwear.levels", "excitation_scaled",
                    lambda fw, tmp: (_block(), fw.FourierBasis.up_to(1, 8), 1e3, 2e3, 2, [1.0])),
    "modes": ("fretwear.linear", "_lowest_modes", lambda fw, tmp: (_block(),)),
    "frf": ("fretwear.linear", "_check_contact", lambda fw, tmp: (_block(), [1e3])),
    "cyclic_modes": ("fretwear.hb.cyclic", "harmonic_model", lambda fw, tmp: (_sector(), 1)),
    "cyclic_frf": ("fretwear.hb.cyclic", "harmonic_model",
                   lambda fw, tmp: (_sector(), 1, [1e3])),
    "sweep_stability": ("fretwear.hb.sweep_stability", "instance",
                        lambda fw, tmp: (_block(), None)),
}


@pytest.mark.parametrize("name", sorted(DRIVERS))
def test_every_public_driver_runs_with_the_drivers_blas_threads(name, monkeypatch, tmp_path):
    """Each public driver that computes (not only fw.sweep and the wear drivers: fw.run, the
    load levels, the linear modes and FRFs, the cyclic ones) runs its body with
    :func:`blas_threads` BLAS threads: the count read by threadpoolctl (independent of
    fretwear) inside the driver's first computation is 1 while the caller has set 2. The
    recorder stops the driver there (no solve is run). fw.run, fw.load_levels, fw.modes,
    fw.frf, the cyclic drivers and fw.sweep_stability saw the caller's 2 threads before they
    were limited."""
    import importlib

    import fretwear as fw

    if not blas():
        pytest.skip("no BLAS library reported by threadpoolctl")
    module_name, inner, arguments = DRIVERS[name]
    seen = []

    def recorder(*args, **kwargs):
        seen.append(blas())
        raise _Stop

    args = arguments(fw, tmp_path)
    monkeypatch.setattr(threads, "_state", {"n": 1})
    monkeypatch.setattr(importlib.import_module(module_name), inner, recorder)
    with threadpoolctl.threadpool_limits(limits=2, user_api="blas"):
        outside = blas()  # {2}, or {1, 2} with a single-threaded BLAS loaded beside
        if 2 not in outside:
            pytest.skip("no BLAS library here takes 2 threads")
        with pytest.raises(_Stop):
            getattr(fw, name)(*args)
        after = blas()
    assert seen == [{1}]
    assert after == outside
