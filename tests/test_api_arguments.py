"""The Python API refuses wrong shapes, types and values at its entry points with a
ValueError (InputError) or TypeError that names the argument, instead of a traceback from
deep inside (an AttributeError on None, an IndexError in the balance, a geomspace error) or
a silent answer (complex K cut to its real part, a zero response reported as converged).

Reference: the documented signatures (docstrings) of each entry point.
"""

import math

import numpy as np
import pytest
import scipy.sparse as sp

import fretwear as fw
from fretwear.errors import InputError
from fretwear.hb.options import SweepOptions
from fretwear.model import ContactSpec, Material, Spring, Traction, from_mesh, rectangle
from fretwear.model.core import Load


@pytest.fixture(scope="module")
def block():
    return from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                     springs=[Spring(at=(0.0, 0.005), direction="x", stiffness=1e7)],
                     loads=[Traction("top", pressure=1e6),
                            Traction("right", pressure=1e5, waveform="cos")],
                     contact=ContactSpec("bottom", mu=0.3), observed={"Pe": (0.02, 0.005)})


BASIS = fw.FourierBasis.up_to(3, 32)


@pytest.mark.parametrize("kw,match", [
    ({"frequency": -5.0}, "frequency"),
    ({"frequency": math.nan}, "frequency"),
    ({"frequency": 0.0}, "frequency = 0.0 Hz: expected > 0"),
    ({"frequency": 1e30}, "frequency"),
    ({"anchor": np.zeros((2, 2))}, "anchor has shape"),
    ({"U0": np.zeros(3)}, "U0 has shape"),
])
def test_solve_periodic_bad_values(block, kw, match):
    args = {"frequency": 1500.0, **kw}
    with pytest.raises(InputError, match=match):
        fw.solve_periodic(block, BASIS, **args)


def test_solve_periodic_bad_types(block):
    with pytest.raises(TypeError, match="model = None: expected a fretwear Model"):
        fw.solve_periodic(None, BASIS, frequency=1500.0)
    with pytest.raises(TypeError, match="basis = 3: expected a fretwear FourierBasis"):
        fw.solve_periodic(block, 3, frequency=1500.0)
    with pytest.raises(InputError, match="basis keeps no harmonic"):
        fw.solve_periodic(block, fw.FourierBasis((), 8), frequency=1500.0)


def test_load_on_a_harmonic_that_is_not_kept_is_refused():
    """A load on harmonic 5 with harmonics 1..3 kept would give a static response reported
    as converged: refused, naming both."""
    m = from_mesh(rectangle(0.02, 0.01, 4, 2), Material(210e9, 0.3, 7800.0), thickness=0.01,
                  springs=[Spring(at=(0.0, 0.005), direction="x", stiffness=1e7)],
                  loads=[Traction("top", pressure=1e6),
                         Traction("right", pressure=1e5, waveform="fourier",
                                  coefficients={5: (1.0, 0.0)})],
                  contact=ContactSpec("bottom", mu=0.3))
    with pytest.raises(InputError, match=r"act on harmonics \[5\] but the basis keeps "
                                         r"\[1, 2, 3\]"):
        fw.solve_periodic(m, BASIS, frequency=1500.0)


@pytest.mark.parametrize("args,match", [
    ((0.0, 2e3, 5), "0 < f_min < f_max"),
    ((2e3, 1e3, 5), "0 < f_min < f_max"),
    ((1e3, 1e3, 5), "0 < f_min < f_max"),
    ((1e3, 2e3, 1), "n_points = 1: expected an integer >= 2"),
    ((1e3, 2e3, 2.5), "n_points = 2.5"),
    ((1e3, 2e3, 10**12), "needs about .* GiB of memory"),
    ((-1e3, 2e3, 5), "f_min"),
])
def test_sweep_bad_bands(block, args, match):
    with pytest.raises(InputError, match=match):
        fw.sweep(block, BASIS, *args)


def test_sweep_bad_spacing(block):
    with pytest.raises(InputError, match='spacing = .lin.: expected "log" or "linear"'):
        fw.sweep(block, BASIS, 1e3, 2e3, 3, options=SweepOptions(spacing="lin"))


@pytest.mark.parametrize("harmonics,samples,match", [
    ((1, 2.5), 16, "expected integers"),
    ((1,), 2.5, "n_samples = 2.5"),
    ((1,), 10**9, "needs about .* GiB of memory"),
])
def test_fourier_basis_bad_arguments(harmonics, samples, match):
    with pytest.raises(InputError, match=match):
        fw.FourierBasis(harmonics, samples)


def test_complex_stiffness_is_refused_not_cut():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]) * (1 + 0.01j))
    with pytest.raises(InputError, match="K holds complex values"):
        fw.from_matrices(K, sp.identity(2), contact_normal_dofs=[0],
                         contact_tangential_dofs=[1], mu=0.3)


def test_nan_load_is_refused():
    K = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    with pytest.raises(InputError, match="finite nodal forces"):
        fw.from_matrices(K, sp.identity(2), contact_normal_dofs=[0],
                         contact_tangential_dofs=[1], mu=0.3,
                         loads=[Load(np.array([np.nan, 0.0]), "cos")])


def test_simulate_wear_checks_its_arguments(block):
    with pytest.raises(TypeError, match="options = .*expected a WearOptions"):
        fw.simulate_wear(block, BASIS, frequency=1500.0, options={"max_steps": 3})
    with pytest.raises(InputError, match="frequency"):
        fw.simulate_wear(block, BASIS, frequency=-1.0)
    with pytest.raises(InputError, match="max_steps"):
        fw.WearOptions(max_steps=2.5)


def test_time_integration_frequency(block):
    with pytest.raises(InputError, match="frequency"):
        fw.integrate(block, 1e30, n_periods=1)
    with pytest.raises(InputError, match="frequency"):
        fw.integrate(block, -1.0, n_periods=1)


def test_time_steps_that_cannot_be_recorded_are_refused(block):
    """1e9 steps per period recorded: refused with the memory estimate, before allocating."""
    with pytest.raises(InputError, match=r"recording 1 periods of 1000000000 time steps needs "
                                         r"about .* GiB"):
        fw.integrate(block, 1500.0, n_periods=1, steps_per_period=10**9)
