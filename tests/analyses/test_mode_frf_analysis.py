"""The nonlinear-modes analysis with a synthesised forced response (``synthesis_f_min``,
``synthesis_f_max``): the shipped Jenkins oscillator (m = 0.5 kg, k = kt = 2e5 N/m,
mu N = 3 N, no viscous damping) with a cosine load of 2 N, one harmonic, 256 samples.

Checks against independent values: the modal force of a one-mass structure is ``F /
sqrt(m)`` (its mass-normalised shape is ``1 / sqrt(m)``: rounding); single-mode theory in
its hysteretic reading is exact for this oscillator (docs/theory.md section 11), so the
direct sweep's amplitudes stay below the backbone amplitude just past the synthesised peak
(the peak lies between two backbone points; 1e-3 for the sampling error at 256 samples,
measured 5.8e-5 on tests/hb/test_mode_synthesis.py) and reach at least 0.9 of the one just
below it (the sweep's 16 frequencies sample the peak: measured 1.05), and the sweep's
largest amplitude is at a frequency between the two synthesised for that amplitude."""

import shutil
from pathlib import Path

import numpy as np
from helpers.cases import check_documented

from fretwear.analyses.run import run_case
from fretwear.io.results import read_results

EXAMPLES = Path(__file__).resolve().parents[2] / "src" / "fretwear" / "examples"
FORCE, MASS = 2.0, 0.5


def test_synthesised_forced_response_beside_the_direct_sweep(tmp_path):
    for name in ("jenkins-K.mtx", "jenkins-M.mtx"):
        shutil.copy(EXAMPLES / name, tmp_path)
    (tmp_path / "jenkins-F.txt").write_text(f"{FORCE}\n")
    text = (EXAMPLES / "jenkins-nonlinear-modes.toml").read_text()
    text = text.replace("amplitude_min = 1e-6", "amplitude_min = 5e-6")
    text = text.replace("amplitude_max = 1e-2", "amplitude_max = 1e-4")
    text = text.replace("n_samples = 1024", "n_samples = 256")
    text = text.replace("[analysis]", '[[loads]]\nfile = "jenkins-F.txt"\nwaveform = "cos"\n\n'
                        "[analysis]")
    text += ('synthesis_f_min = 105.0\nsynthesis_f_max = 135.0\nsynthesis_points = 16\n'
             'synthesis_damping = "hysteretic"\n\n[output]\nfigures = true\nvtu = false\n')
    path = tmp_path / "case.toml"
    path.write_text(text)
    out = run_case(path, tmp_path / "results", progress=False, echo=False)
    assert out.success, out.summary
    assert (tmp_path / "results" / "mode-frf.png").is_file()
    ds = read_results(out.results)
    check_documented(ds, "nonlinear-modes")
    assert ds["converged"].values.all()
    np.testing.assert_allclose(ds["modal_force"].values, FORCE / np.sqrt(MASS), rtol=1e-12)
    hi = ds["synthesis_frequency_high"].values
    reached = np.flatnonzero(np.isfinite(hi))
    peak = reached[-1]
    assert 0 < peak < hi.size - 1  # the band of amplitudes goes past the peak
    a_mass = ds["response_amplitude"].sel(point="mass", axis="x", harmonic=1).values
    sweep = ds["sweep_response_amplitude"].sel(point="mass", axis="x").values
    assert np.all(np.isfinite(sweep))
    assert sweep.max() <= a_mass[peak + 1] * (1 + 1e-3)
    assert sweep.max() >= 0.9 * a_mass[peak]  # the sweep goes through the resonance
    # the sweep's peak frequency between the two synthesised frequencies of the last
    # amplitude below the peak (measured: 122.1 Hz between 119.2 and 127.2 Hz)
    f_peak = ds["sweep_frequency"].values[int(np.argmax(sweep))]
    lo = ds["synthesis_frequency_low"].values
    assert lo[peak] <= f_peak <= hi[peak]
