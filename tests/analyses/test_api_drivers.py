"""The analyses call the drivers of the public API (fretwear.api), so that one place decides
the time-domain fallback: the case-file key (``time_domain`` of a periodic or sweep analysis,
and of a wear analysis's ``frf_before_after``) is the api's ``time_domain=`` argument, and the
numerical core receives the api's fallback object.

Reference: the keywords the core function receives, caught by replacing it (the core is not
run: the replacement records its arguments and stops the run), against the api's fallback
object, itself replaced by a sentinel so that only a value passed through ``fretwear.api`` can
match; and the source of the analysis modules, which no longer name the fallback.
"""

import importlib
import pkgutil

import pytest
from helpers.cases import WEAR_BLOCK, small_case

import fretwear.analyses
from fretwear import api
from fretwear.analyses.run import run_case
from fretwear.hb.fallback import TimeDomainFallback

# stands for fretwear.timedomain.fallback.FALLBACK inside fretwear.api (a fallback of its own
# kind: the option records check what they are given)
SENTINEL = TimeDomainFallback(start=None, averaged_rate=None)

PERIODIC = '[analysis]\ntype = "periodic"\nfrequency = 1e4\nharmonics = 1\nn_samples = 16\n'
SWEEP = ('[analysis]\ntype = "sweep"\nf_min = 1e3\nf_max = 2e3\nn_points = 2\nharmonics = 1\n'
         'n_samples = 16\n')
WEAR = f"""
title = "wear block"
{WEAR_BLOCK}[analysis]
type = "wear"
quasi_static = true
harmonics = 1
n_samples = 16
max_steps = 1
[analysis.frf_before_after]
f_min = 2e3
f_max = 3e3
n_points = 2
"""
NO_FILES = "[output]\nfigures = false\nvtu = false\n"


class Stop(Exception):
    """Raised by the replaced core function once it has recorded its arguments."""


@pytest.fixture
def core(monkeypatch):
    """``replace(module, name)``: the core function ``name`` of the module the api calls
    records its keywords in ``calls[name]`` and stops the run (``run=True``: runs it)."""
    monkeypatch.setattr(api, "FALLBACK", SENTINEL)
    calls = {}

    def replace(module, name, run=False):
        real = getattr(module, name)

        def recorder(*args, **kwargs):
            calls.setdefault(name, []).append(kwargs)
            if run:
                return real(*args, **kwargs)
            raise Stop

        monkeypatch.setattr(module, name, recorder)

    return replace, calls


@pytest.mark.parametrize("key,expected", [("", SENTINEL), ("time_domain = true\n", SENTINEL),
                                          ("time_domain = false\n", None)])
def test_periodic_takes_the_fallback_of_the_api(tmp_path, core, key, expected):
    replace, calls = core
    replace(api._periodic, "solve_periodic")
    with pytest.raises(Stop):
        run_case(small_case(tmp_path, PERIODIC + key + NO_FILES), progress=False, echo=False)
    ((kw,),) = calls.values()
    assert kw["time_domain"] is expected and kw["frequency"] == 1e4


@pytest.mark.parametrize("key,expected", [("", SENTINEL), ("time_domain = false\n", None)])
def test_sweep_takes_the_fallback_of_the_api(tmp_path, core, key, expected):
    replace, calls = core
    replace(api._sweep, "sweep")
    with pytest.raises(Stop):
        run_case(small_case(tmp_path, SWEEP + key + NO_FILES), progress=False, echo=False,
                 resume=True)
    ((kw,),) = calls.values()
    assert kw["options"].time_domain is expected
    assert kw["options"].resume is True  # from the run context


@pytest.mark.parametrize("key,expected", [("", SENTINEL), ("time_domain = false\n", None)])
def test_wear_and_its_frfs_take_the_fallback_of_the_api(tmp_path, core, key, expected):
    """The wear run always gets the api's fallback (WearOptions.time_domain_rescue says
    whether it is used); its FRFs before and after wear get it as their key says."""
    replace, calls = core
    replace(api._wear, "simulate_wear", run=True)
    replace(api._wear, "frf_worn")
    path = tmp_path / "w.toml"
    path.write_text(WEAR + key + NO_FILES)
    with pytest.raises(Stop):
        run_case(path, progress=False, echo=False)
    (wear,) = calls["simulate_wear"]
    (frf,) = calls["frf_worn"]  # the unworn interface first; the run stops there
    assert wear["time_domain"] is SENTINEL and wear["quasi_static"] is True
    assert frf["options"].time_domain is expected


def test_no_analysis_names_the_fallback_itself():
    """The analyses leave the fallback to fretwear.api: none imports FALLBACK."""
    for info in pkgutil.iter_modules(fretwear.analyses.__path__):
        module = importlib.import_module(f"fretwear.analyses.{info.name}")
        assert not hasattr(module, "FALLBACK"), module.__name__
