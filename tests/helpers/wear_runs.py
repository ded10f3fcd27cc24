"""A short quasi-static wear run shared by the tests of the state and the history of a wear
run (tests/wear/test_state.py, test_history.py)."""

from __future__ import annotations

from fretwear.examples.builders import stromberg_beam
from fretwear.hb.fourier import FourierBasis
from fretwear.wear import RunControl, WearOptions, simulate_wear


def short_run():
    """Six steps of a quasi-static wear run (12 x 2 Stromberg beam, 3 harmonics), with every
    accepted step's record as the callback got it."""
    model, basis = stromberg_beam(nx=12, ny=2), FourierBasis.up_to(3, 32)
    seen = []
    res = simulate_wear(model, basis, quasi_static=True, options=WearOptions(max_steps=6),
                        run=RunControl(callback=lambda step, record: seen.append(record)))
    nc, d = model.contact.dofs.shape
    dims = {"nc": nc, "d": d, "d-1": d - 1, "m": nc * d, "H": basis.size}
    return res, seen, dims


def reduced_example(name: str, nx: int, folder):
    """A reduced copy of a shipped quasi-static beam example (``nx`` x 2 Q4 elements instead
    of 30 x 4; the case file written to ``folder``): its model and a basis of 3 harmonics,
    32 samples (tests/wear/test_worn_state.py, test_stick_set.py)."""
    from fretwear.analyses.run import load_case
    from fretwear.examples import example_path
    from fretwear.io.case import build_model

    text = example_path(name).read_text()
    for old, new in (("nx = 30 ", f"nx = {nx} "), ("ny = 4 ", "ny = 2 ")):
        assert old in text
        text = text.replace(old, new)
    path = folder / "case.toml"
    path.write_text(text)
    return build_model(load_case(path)), FourierBasis.up_to(3, 32)
