"""Which members a rerun skips: finished (ok or not converged) with a results file and a
status recorded for exactly the same case text; anything else runs again."""

from __future__ import annotations

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
