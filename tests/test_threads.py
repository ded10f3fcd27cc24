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
