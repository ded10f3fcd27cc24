"""Which members a rerun skips: finished (ok or not converged) with a results file and a
status recorded for exactly the same case text; anything else runs again."""

from __future__ import annotations

import json

import pytest

from fretwear.errors import InputError
from fretwear.study.runner import MemberRecord, case_hash, finished, read_status


def _member(folder, status, text="a = 1\n", results=True):
    folder.mkdir()
    (folder / "case.toml").write_text(text)
    (folder / "status.json").write_text(MemberRecord(0, status, case_sha256=case_hash(text))
                                        .to_json())
    if results:
        (folder / "results.nc").write_bytes(b"x")
    return folder


def test_finished_members_only_for_the_same_case_text(tmp_path):
    ok = _member(tmp_path / "ok", "ok")
    assert finished(ok, "a = 1\n").skipped
    assert finished(ok, "a = 2\n") is None  # the study changed the member: run it again
    assert finished(_member(tmp_path / "nc", "not converged"), "a = 1\n") is not None
    assert finished(_member(tmp_path / "f", "failed"), "a = 1\n") is None
    assert finished(_member(tmp_path / "nr", "ok", results=False), "a = 1\n") is None
    bad = _member(tmp_path / "bad", "ok")
    (bad / "status.json").write_text("{truncated")
    assert read_status(bad) is None and finished(bad, "a = 1\n") is None


def test_a_status_without_hash_is_checked_against_the_case_file(tmp_path):
    ok = _member(tmp_path / "ok", "ok")
    (ok / "status.json").write_text('{"index": 0, "status": "ok"}')
    assert finished(ok, "a = 1\n") is not None
    assert finished(ok, "a = 2\n") is None


def test_default_workers_start_without_dask_memory_trimming(client):
    """The workers of the default LocalCluster run without Dask's MALLOC_TRIM_THRESHOLD_
    (it made fretwear's members 30-50 % slower, docs/study.md) and with one BLAS thread."""
    import os

    envs = client.run(lambda: {k: os.environ.get(k) for k in
                               ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")})
    assert len(envs) == 2
    for env in envs.values():
        assert env["MALLOC_TRIM_THRESHOLD_"] is None and env["OMP_NUM_THREADS"] == "1"


def _sealed_member(folder, results=b"results of the run"):
    import hashlib

    folder.mkdir()
    text = "a = 1\n"
    (folder / "case.toml").write_text(text)
    (folder / "results.nc").write_bytes(results)
    rec = MemberRecord(0, "ok", "periodic solution", case_sha256=case_hash(text),
                       results_sha256=hashlib.sha256(results).hexdigest())
    (folder / "status.json").write_text(rec.to_json())
    return folder


@pytest.mark.parametrize("edit", [
    lambda d: d.__setitem__("status", "ok" if d["status"] != "ok" else "not converged"),
    lambda d: d.__setitem__("case_sha256", case_hash("a = 2\n")),  # made to match another case
    lambda d: d.__setitem__("message", d["message"] + " "),
    lambda d: d.pop("content_sha256"),
    lambda d: d.__setitem__("content_sha256", "0" * 64),
], ids=["status", "case-hash", "message", "no-seal", "wrong-seal"])
def test_an_edited_status_is_refused_in_one_line_naming_it(tmp_path, edit):
    """A status file edited by hand (a field changed, its checksum removed or forged) is
    refused with one line naming the file, never trusted: the SHA-256 of its fields, computed
    again here, no longer matches the one it holds. The unedited status is still read (the
    check does not refuse good files)."""
    folder = _sealed_member(tmp_path / "m")
    assert finished(folder, "a = 1\n").skipped
    path = folder / "status.json"
    d = json.loads(path.read_text())
    edit(d)
    path.write_text(json.dumps(d))
    with pytest.raises(InputError) as err:
        finished(folder, "a = 1\n")
    msg = str(err.value)
    assert str(path) in msg and "damaged" in msg and "\n" not in msg


def test_a_replaced_results_file_is_refused(tmp_path):
    """A member's results.nc replaced after its status was sealed (the status records the
    SHA-256 of the results bytes) is refused in one line naming the results file."""
    folder = _sealed_member(tmp_path / "m")
    (folder / "results.nc").write_bytes(b"other results")
    with pytest.raises(InputError) as err:
        finished(folder, "a = 1\n")
    assert str(folder / "results.nc") in str(err.value) and "\n" not in str(err.value)
