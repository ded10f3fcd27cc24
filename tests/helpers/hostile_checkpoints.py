"""Checkpoints a hostile user (or a disk) edits: every kind of state file a run resumes from
(wear, sweep and worn-state checkpoints, a study member's status and results), written by a
real run of a small case, then edited and resumed.

Shared by the survey (studies/hostile_inputs.py --checkpoints) and tests/test_hostile_cases.py.
The edits of an archive rewrite it whole (every zip CRC right again, so only fretwear's own
checks can tell): a NaN, a negative value, one value changed by one part in 1e15, an integer
changed, a text edited, an array removed, the content checksum removed, and the NaN and
negative edits with the checksum computed again (as someone who read the source would), which
only the checks of each array's finiteness and range can refuse; then the file truncated and
replaced by other bytes. Every edited checkpoint must be refused by ``fretwear run --resume``
(``fretwear study`` for a member) with one line naming the file, never resumed.
"""

from __future__ import annotations

import contextlib
import io
import json
import shutil
from pathlib import Path

import numpy as np

from fretwear.files import SEAL, seal
from helpers import hostile

#: checkpoint kind -> (analysis of the generated base case, checkpoint file name)
KINDS = {
    "wear": ("wear", "wear-checkpoint.npz"),
    "sweep": ("sweep", "sweep-checkpoint.npz"),
    "worn-state": ("worn-state", "worn-state-checkpoint.npz"),
}


def _arrays(path: Path) -> dict:
    with np.load(path, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def _first(arrays: dict, kinds: str, min_size: int = 1):
    for k in sorted(arrays):
        a = arrays[k]
        if k != SEAL and a.dtype.kind in kinds and a.size >= min_size:
            return k
    return None


def archive_edits(arrays: dict) -> list[tuple[str, dict | bytes]]:
    """``(label, edited arrays or raw bytes)`` of every edit of a checkpoint's ``arrays``."""
    out = []
    f = _first(arrays, "f")
    i = _first(arrays, "iu")
    t = _first(arrays, "U")

    def edited(key, change, reseal=False):
        a = {k: v.copy() for k, v in arrays.items()}
        a[key] = change(a[key].copy())
        if reseal:
            a = seal({k: v for k, v in a.items() if k != SEAL})
        return a

    def at0(value):
        def change(a):
            a.flat[0] = value if not callable(value) else value(a.flat[0])
            return a
        return change

    if f is not None:
        out += [(f"{f}: NaN", edited(f, at0(np.nan))),
                (f"{f}: negative", edited(f, at0(lambda x: -abs(x) - 1.0))),
                (f"{f}: one part in 1e15", edited(f, at0(lambda x: x * (1 + 1e-15) + 1e-300))),
                (f"{f}: NaN, checksum recomputed", edited(f, at0(np.nan), reseal=True)),
                (f"{f}: inf, checksum recomputed", edited(f, at0(np.inf), reseal=True))]
        neg = [k for k in sorted(arrays) if k != SEAL and arrays[k].dtype.kind == "f"
               and arrays[k].size and np.all(arrays[k] >= 0) and np.any(arrays[k] > 0)]
        if neg:
            out.append((f"{neg[0]}: negative, checksum recomputed",
                        edited(neg[0], at0(lambda x: -abs(x) - 1.0), reseal=True)))
    if i is not None:
        out.append((f"{i}: integer + 1", edited(i, at0(lambda x: x + 1))))
        out.append((f"{i}: -1, checksum recomputed", edited(i, at0(-1), reseal=True)))
    if t is not None:
        out.append((f"{t}: text edited", edited(t, lambda a: np.asarray(str(a) + " "))))
    k = _first(arrays, "fiub")
    if k is not None:
        out.append((f"{k}: removed", {kk: v for kk, v in arrays.items() if kk != k}))
    out.append(("checksum removed", {kk: v for kk, v in arrays.items() if kk != SEAL}))
    return out


def _save(path: Path, content) -> None:
    if isinstance(content, bytes):
        path.write_bytes(content)
        return
    with open(path, "wb") as fh:
        np.savez(fh, **content)


def _cli(args: list[str]) -> tuple[int | None, str, str]:
    from fretwear import cli

    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = cli.main(args)
    except BaseException as exc:  # what would be a traceback on the command line
        return None, err.getvalue(), f"traceback: {type(exc).__name__}: {exc}"[:300]
    return rc, err.getvalue(), "message" if rc == 2 else "ran"


def _verdict(rc, err: str, outcome: str, path: Path) -> str:
    """``"refused"`` (exit 2, one line naming ``path``), else what happened."""
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    if outcome.startswith("traceback"):
        return outcome
    if rc == 2 and len(lines) == 1 and str(path) in lines[0]:
        return "refused"
    if rc == 2:
        return f"message not naming the file: {' | '.join(lines)[:200]}"
    return "resumed (accepted)"


def survey_archives(folder: Path, kinds=tuple(KINDS)) -> list[tuple[str, str, str]]:
    """``(kind, edit, verdict)`` of every edit of every archive checkpoint kind."""
    rows = []
    for kind in kinds:
        analysis, name = KINDS[kind]
        work = folder / kind
        work.mkdir()
        case = hostile.base_case(analysis)
        case.setdefault("output", {}).update({"figures": False, "vtu": False})
        path = work / "case.toml"
        path.write_text(hostile.toml_text(case))
        out = work / "out"
        rc, err, outcome = _cli(["run", str(path), "-o", str(out), "--no-progress"])
        ckpt = out / name
        if not ckpt.is_file():
            rows.append((kind, "(the run)", f"no checkpoint written: {outcome} {err[-200:]}"))
            continue
        good = ckpt.read_bytes()
        arrays = _arrays(ckpt)
        edits = archive_edits(arrays) + [("truncated", good[: len(good) // 2]),
                                          ("other bytes", b"PK\x03\x04 not an archive" * 20)]
        for label, content in edits:
            _save(ckpt, content)
            (out / "results.nc").unlink(missing_ok=True)
            rc, err, outcome = _cli(["run", str(path), "-o", str(out), "--resume",
                                     "--no-progress"])
            rows.append((kind, label, _verdict(rc, err, outcome, ckpt)))
        ckpt.write_bytes(good)
    return rows


def survey_members(folder: Path) -> list[tuple[str, str, str]]:
    """``(kind, edit, verdict)`` of every edit of a finished study member (its status file
    and its results file), the study run once on a LocalCluster of one worker."""
    from fretwear.study.runner import SEAL_KEY

    work = folder / "study"
    work.mkdir()
    case = hostile.base_case("modes")
    case.setdefault("output", {}).update({"figures": False, "vtu": False})
    (work / "base.toml").write_text(hostile.toml_text(case))
    study = work / "study.toml"
    study.write_text('base = "base.toml"\n[grid]\n"contact.mu" = [0.3]\n'
                     '[output]\nfigures = false\n')
    out = work / "out"
    rc, err, outcome = _cli(["study", str(study), "-o", str(out), "--workers", "1",
                             "--no-progress"])
    member = out / "member-0000"
    status, results = member / "status.json", member / "results.nc"
    if not (status.is_file() and results.is_file()):
        return [("study member", "(the run)", f"no finished member: {outcome} {err[-300:]}")]
    good_status, good_results = status.read_text(), results.read_bytes()

    def status_edit(change):
        d = json.loads(good_status)
        change(d)
        return json.dumps(d)

    edits = [
        ("status: ok -> failed", "status", status_edit(lambda d: d.update(status="failed"))),
        ("status: message edited", "status", status_edit(lambda d: d.update(message="x"))),
        ("status: case hash edited", "status",
         status_edit(lambda d: d.update(case_sha256="0" * 64))),
        ("status: results hash edited", "status",
         status_edit(lambda d: d.update(results_sha256="0" * 64))),
        ("status: checksum removed", "status", status_edit(lambda d: d.pop(SEAL_KEY))),
        ("status: checksum forged", "status", status_edit(lambda d: d.update(
            {SEAL_KEY: "0" * 64}))),
        ("results: one byte changed", "results",
         good_results[:-1] + bytes([good_results[-1] ^ 1])),
        ("results: replaced by another run's", "results", good_results + b"\0"),
    ]
    rows = []
    for label, which, content in edits:
        status.write_text(good_status)
        results.write_bytes(good_results)
        target = status if which == "status" else results
        if isinstance(content, bytes):
            target.write_bytes(content)
        else:
            target.write_text(content)
        rc, err, outcome = _cli(["study", str(study), "-o", str(out), "--collect",
                                 "--no-progress"])
        rows.append(("study member", label, _verdict(rc, err, outcome, target)))
    shutil.rmtree(work, ignore_errors=True)
    return rows
