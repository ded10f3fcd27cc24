"""The ``worn-state`` analysis of case files (fretwear.analyses.worn_state) end to end, on the
quasi-static wear block of the wear tests.

References: the documented schema of docs/results.md (``worn-state``), and the Python
function :func:`fretwear.worn_state` on the same model (the case file must give its state).
"""

from __future__ import annotations

import numpy as np
from helpers.cases import WEAR_BLOCK, check_documented

import fretwear as fw
from fretwear.analyses.run import load_case, run_case
from fretwear.io.case import build_model
from fretwear.io.results import read_results

CASE = f"""
title = "worn-state test block"
{WEAR_BLOCK}[analysis]
type = "worn-state"
quasi_static = true
harmonics = 3
n_samples = 32
checkpoint_every_s = 0.0
residual_tolerance = 1e-3
"""


def test_case_file_gives_the_python_state_and_the_documented_results(tmp_path):
    """`analysis = "worn-state"`: results.nc follows the schema (every variable documented,
    with its units and dimensions), its last step is the state of fw.worn_state on the same
    model (the same numbers: same steps), the figures and the checkpoint exist, and the
    summary says the state was reached with an estimate of the cycles."""
    case = tmp_path / "w.toml"
    case.write_text(CASE)
    out = run_case(case, progress=False, echo=False)
    ds = read_results(out.results)
    check_documented(ds, "worn-state")
    assert ds.attrs["analysis_type"] == "worn-state" and ds.attrs["converged"] == 1
    assert ds.attrs["worn_state_kind"] == "null_wear_rate"
    assert float(ds["null_wear_rate_residual"]) <= 1e-3
    assert float(ds["cycles_to_state_estimate"]) > 0
    c = load_case(case)
    model = build_model(c)
    ref = fw.worn_state(model, fw.FourierBasis.up_to(3, 32), quasi_static=True,
                        options=fw.WornStateOptions(tolerance=1e-3))
    np.testing.assert_allclose(ds["wear_depth"].values[-1], ref.wear, rtol=1e-9, atol=0)
    np.testing.assert_allclose(ds["worn_depth_surface"].values[-1, :, 0], ref.wear, rtol=1e-9)
    res = tmp_path / "w-results"
    for name in ("worn-state.png", "worn-state-residual.png",
                 "worn-state-checkpoint.npz"):
        assert (res / name).exists(), name
    assert "(an estimate)" in out.message
