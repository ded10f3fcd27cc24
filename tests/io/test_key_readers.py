"""Which analyses read which case-file keys (``Field.used_by``, fretwear.io.case._READERS):
every key of the schema x every analysis type is read, or named as ignored when given.

Three references: the registry (the analysis types the declarations list are all the
registered ones, and only those); the schema walked key by key (every key of every table,
model kind, model type, list of tables and table of tables, for every analysis type: given a
value, it is named by the pass of ignored keys exactly when a field on its path leaves the
analysis out, and as a warning in the tables of the run, a note in those of the model: so a
key declared later is covered without touching this file); and the computed results (the
modes and the FRF of the shipped beam, bit for bit the same whatever the keys declared
unread by them say: what the declarations claim, measured).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from helpers.cases import small_case

from fretwear import linear
from fretwear.analyses.registry import analysis_tables, available
from fretwear.analyses.run import load_case
from fretwear.io import case as case_files
from fretwear.io.case import build_model, ignored_notes
from fretwear.io.schema import MISSING, AnyOf, Dict, Table, TableList, Variant, unused_keys


class Given:
    """A value given to a key: equal to no default, not a switch turned off."""

    def __repr__(self) -> str:
        return "given"


def test_the_declared_analyses_are_the_registered_ones():
    """A new analysis type must be declared (else every key read by 'every analysis but
    ...' would look ignored by it)."""
    assert set(case_files.ANALYSES) == set(available())
    assert len(case_files.ANALYSES) == len(set(case_files.ANALYSES))


def _leaves(spec, path, readers, out):
    """(key path, nested value giving only that key, readers) of every key under ``spec``;
    ``readers``: the analyses that read every field on the path (None: every one)."""
    if isinstance(spec, AnyOf):
        for o in spec.options:
            if isinstance(o, Table | TableList | Dict | Variant):
                _leaves(o, path, readers, out)
        return
    if isinstance(spec, Variant):
        for kind, table in spec.tables().items():
            sub = []
            _leaves(table, path, readers, sub)
            out += [(p, {spec.key: kind, **v}, r) for p, v, r in sub]
        return
    if isinstance(spec, TableList):
        sub = []
        _leaves(spec.table, path, readers, sub)
        out += [(p, [v], r) for p, v, r in sub]
        return
    if isinstance(spec, Dict):
        sub = []
        _leaves(spec.value, path + ".x", readers, sub)
        out += [(p, {"x": v}, r) for p, v, r in sub]
        if not sub:
            out.append((path + ".x", {"x": Given()}, readers))
        return
    if isinstance(spec, Table):
        for key, f in spec.fields.items():
            r = readers if f.used_by is None else (
                f.used_by if readers is None else tuple(a for a in readers if a in f.used_by))
            sub = []
            _leaves(f.spec, f"{path}.{key}" if path else key, r, sub)
            if sub:
                # the whole table given and left unread is named once, as itself
                out += [(p, {key: v}, r) for p, v, r in sub]
            else:
                out.append((f"{path}.{key}" if path else key, {key: Given()}, r))


@pytest.mark.parametrize("kind", ["mesh", "matrices", "fe"])
def test_every_key_x_every_analysis_is_read_or_named(kind):
    """For every key of the model kind's case table (the [analysis] tables apart: each type
    reads its own) and every analysis type: given alone, the key is named as ignored iff
    the declarations leave the analysis out of its readers (``used_by`` of every field on its
    path), with the path of the outermost unread field."""
    tables = analysis_tables()
    top = case_files._case_table(kind, tables)
    leaves = []
    for key, f in top.fields.items():
        if key == "analysis":
            continue
        sub = []
        _leaves(f.spec, key, f.used_by, sub)
        leaves += ([(p, {key: v}, r) for p, v, r in sub] if sub
                   else [(key, {key: Given()}, f.used_by)])
    assert len(leaves) > 40  # every table walked (model types, contact, output...)
    for path, raw, readers in leaves:
        for a in available():
            named = unused_keys(top, {**raw, "analysis": {"type": a}}, a)
            if readers is None or a in readers:
                assert named == [], (path, a, named)
            else:
                assert len(named) == 1, (path, a, named)
                assert path.startswith(named[0][0].replace("[1]", "")), (path, named)
                assert a not in named[0][2]


def test_analysis_keys_are_read_by_their_own_type():
    """The keys of each [analysis] table belong to its type: none is declared for others."""
    for a, table in analysis_tables().items():
        for key, f in table.fields.items():
            assert f.used_by is None or a in f.used_by, (a, key)


def test_an_ignored_key_is_a_note_in_the_model_a_warning_in_the_run(tmp_path):
    """Each ignored key is one line naming it, its value and who reads it: a note for the
    model's tables (a property of the structure, kept in a file run for other analyses), a
    warning for the run's ([output], [analysis]); and the static load P, which an FRF (the
    response to the harmonic 1 of the loads) does not read."""
    text = ('[analysis]\ntype = "frf"\nf_min = 100.0\nf_max = 200.0\nn_points = 2\n'
            "[output]\nwhole_disk = true\n")
    lines = ignored_notes(load_case(small_case(tmp_path, text)), analysis_tables())
    assert lines == [
        "note: contact.mu = 0.3 is not used by a frf analysis (read by every analysis but "
        "modes, frf, cyclic-modes): it is ignored",
        "note: contact.wear_coefficient = 1e-11 is not used by a frf analysis (only by wear, "
        "incremental-wear, worn-state): it is ignored",
        "warning: output.whole_disk = true is not used by a frf analysis (only by periodic, "
        "wear): it is ignored",
        'note: load "P" (waveform "constant") is not used by a frf analysis (the response to '
        "the harmonic 1 of the loads): it is ignored"]


#: keys the linear analyses are declared not to read, and a second value for each
CHANGES = {
    "mu": "mu = 0.9", "gap": "gap = 1e-5", "normal_stiffness": "normal_stiffness = 1e9",
    "tangential_stiffness": "tangential_stiffness = 1e9",
    "normal_pressure": "normal_pressure = 2e5\nnormal_waveform = \"cos\"",
}


def _model(tmp_path: Path, contact_line: str | None = None, drop: str | None = None):
    text = ('[analysis]\ntype = "modes"\nn_modes = 4\n')
    path = small_case(tmp_path, text)
    src = path.read_text()
    if contact_line is not None:  # the key's line replaced, or added to [contact]
        key = contact_line.split(" =")[0]
        lines = [ln for ln in src.splitlines() if ln.split(" =")[0] != key]
        src = "\n".join(lines).replace("\n[contact]\n", f"\n[contact]\n{contact_line}\n")
    if drop == "damping":
        src = src.replace("[damping]", "[damping]\nrayleigh_mass = 3.0")
    if drop == "loads":
        src = src.replace("pressure = 1e4\nwaveform = \"sin\"", "pressure = 3e4\nwaveform = "
                          "\"cos\"")
    path.write_text(src)
    return build_model(load_case(path))


def test_keys_declared_unread_by_the_linear_analyses_change_nothing_there(tmp_path):
    """The modes and the FRF (both interfaces) of the shipped beam are bit for bit the same
    with each contact key declared unread by them changed (friction, gap, contact
    stiffness, a prescribed normal pressure), and the modes with another damping and other
    loads: the declarations are what the computation does."""
    ref = _model(tmp_path)
    f_ref = {i: linear.modes(ref, 4, interface=i) for i in ("sliding", "stuck")}
    r_ref = {i: linear.frf(ref, [500.0, 3000.0], interface=i) for i in ("sliding", "stuck")}
    changed = [_model(tmp_path, line) for line in CHANGES.values()]

    def contact_of(model):
        c = model.contact
        load = None if c.normal_load is None else c.normal_load.vector
        return [np.asarray(x if x is not None else np.nan, float).ravel()
                for x in (c.mu, c.gap, c.kn, c.kt, load)]

    for model in changed:  # each change reached the model (else the test proves nothing)
        assert any(a.shape != b.shape or not np.array_equal(a, b, equal_nan=True)
                   for a, b in zip(contact_of(model), contact_of(ref), strict=True))
    for model in changed:
        for i in ("sliding", "stuck"):
            m = linear.modes(model, 4, interface=i)
            assert np.array_equal(m.frequency_hz, f_ref[i].frequency_hz)
            assert np.array_equal(m.shapes, f_ref[i].shapes)
            r = linear.frf(model, [500.0, 3000.0], interface=i)
            assert np.array_equal(r.contact, r_ref[i].contact)
            assert all(np.array_equal(r.observed[k], r_ref[i].observed[k])
                       for k in r_ref[i].observed)
    for drop in ("damping", "loads"):
        model = _model(tmp_path, drop=drop)
        for i in ("sliding", "stuck"):
            m = linear.modes(model, 4, interface=i)
            assert np.array_equal(m.frequency_hz, f_ref[i].frequency_hz)
            assert np.array_equal(m.shapes, f_ref[i].shapes)


def test_defaults_and_missing_are_not_named():
    """A key left at its default (or absent) is not named: MISSING and defaults are the
    schema's own, so a case that writes out a default gets no line."""
    top = case_files._case_table("mesh", analysis_tables())
    contact = top.fields["contact"].spec.table
    assert contact.fields["gap"].default == 0.0 and contact.fields["mu"].default is MISSING
    raw = {"contact": [{"gap": 0.0}], "analysis": {"type": "modes"}}
    assert unused_keys(top, raw, "modes") == []


def test_keys_another_key_makes_unread_are_named(tmp_path):
    """n_modes with f_max (every mode up to f_max), the modal condensation's keys with
    condensation = "exact", and every condensation key on a sector (condensed exactly, one
    condensation per harmonic index): one warning each, naming the key and why; the same
    keys without the key that overrides them are not named. Reference: the documented
    behaviour (fretwear.analyses.common.condenser_of, the modes' f_max), by hand."""
    from helpers.cyclic import write_sector_case

    def notes(text, path=None):
        case = load_case(path or small_case(tmp_path, text))
        return [n for n in ignored_notes(case, analysis_tables()) if "analysis." in n]

    assert notes('[analysis]\ntype = "modes"\nn_modes = 3\nf_max = 1e4\n') == [
        "warning: analysis.n_modes = 3 is not used: f_max is given (every mode up to it): it "
        "is ignored"]
    assert notes('[analysis]\ntype = "modes"\nn_modes = 3\n') == []
    periodic = '[analysis]\ntype = "periodic"\nfrequency = 1e4\ncondensation_tol = 0.01\n'
    assert notes(periodic + 'condensation = "exact"\n') == [
        "warning: analysis.condensation_tol = 0.01 is not used: condensation = \"exact\" (the "
        "keys of the modal condensation): it is ignored"]
    assert notes(periodic + 'condensation = "modal"\n') == []
    path, _ = write_sector_case(tmp_path, analysis='[analysis]\ntype = "periodic"\n'
                                'frequency = 100.0\ncondensation = "modal"\n')
    assert notes(None, path) == [
        'warning: analysis.condensation = "modal" is not used: a sector ([cyclic]) is '
        "condensed exactly, one condensation per harmonic index: it is ignored"]


def test_the_periodic_part_of_a_load_is_named_in_a_nonlinear_mode(tmp_path):
    """A nonlinear mode is a free vibration preloaded by the static loads
    (fretwear.hb.nonlinear_modes.ModeSystem.loads: harmonic 0): the beam's load Q
    (waveform "sin") is named, its static load P is not."""
    text = ('[analysis]\ntype = "nonlinear-modes"\namplitude_min = 1e-9\n'
            "amplitude_max = 1e-8\nn_amplitudes = 2\n")
    lines = ignored_notes(load_case(small_case(tmp_path, text)), analysis_tables())
    assert [n for n in lines if "load " in n] == [
        'note: load "Q" (waveform "sin") is not used by a nonlinear-modes analysis beyond its '
        "static part (a free vibration, preloaded by the static loads): its periodic part is "
        "ignored"]
