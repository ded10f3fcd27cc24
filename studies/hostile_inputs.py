"""Survey: how fretwear answers case files, study files and checkpoints a hostile user writes.

Generates N case files from the schema (tests/helpers/hostile.py: one to three keys of a
small valid case of one of every analysis type replaced by valid or invalid values for their
specification) and runs each with ``fretwear run`` in this process; then S study files of
every kind (tests/helpers/hostile_studies.py) with ``fretwear study --collect``; then edits
every kind of checkpoint (tests/helpers/hostile_checkpoints.py: wear, sweep, worn-state,
study member) and resumes. Prints the count of each outcome: ran (exit 0/1 with a results
file), clean message (exit 2, one line), traceback (an exception escaped), hang (longer than
the time limit), files written outside the output folder, the count of each analysis type
and study kind drawn, and the first examples of each failure kind; for checkpoints, every
edit and whether it was refused.

    python studies/hostile_inputs.py --n 500 --studies 100 --seed 1
    python studies/hostile_inputs.py --api   # the API calls of tests/helpers/hostile_api.py
"""

from __future__ import annotations

import argparse
import contextlib
import random
import sys
import tempfile
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from helpers import hostile, hostile_checkpoints, hostile_sizes, hostile_studies  # noqa: E402
from hypothesis import HealthCheck, given, settings  # noqa: E402

#: files a generated run writes beside its case file (inputs, not outputs)
INPUTS = ("case.toml", "base.toml", "study.toml", *hostile.SECTOR_FILES)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=500, help="generated case files")
    ap.add_argument("--studies", type=int, default=100, help="generated study files")
    ap.add_argument("--no-checkpoints", action="store_true", help="skip the checkpoint edits")
    ap.add_argument("--no-sizes", action="store_true", help="skip the sizes that cannot fit")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--api", action="store_true", help="survey the Python API calls instead")
    a = ap.parse_args()
    if a.api:
        api_survey()
        return
    random.seed(a.seed)
    if a.n:
        survey_files("case files", a.n, hostile.hostile_cases(),
                     lambda g, folder: hostile.run_generated(g[0], folder),
                     lambda g: g[0]["analysis"]["type"], lambda g: g[1], "results.nc")
    if a.studies:
        survey_files("study files", a.studies, hostile_studies.hostile_studies(),
                     lambda g, folder: hostile_studies.run_study_file(g[0], g[1], folder),
                     lambda g: g[0], lambda g: g[2], "study.nc")
    if not a.no_checkpoints:
        checkpoint_survey()
    if not a.no_sizes:
        size_survey()


def survey_files(what: str, n: int, strategy, run, kind_of, changes_of, result: str) -> None:
    """Run ``n`` files drawn from ``strategy`` and print the counts of each outcome."""
    counts: Counter = Counter()
    kinds: Counter = Counter()
    examples: dict[str, list[str]] = {}

    @settings(max_examples=n, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(strategy)
    def survey(generated):
        kinds[kind_of(generated)] += 1
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp) / "work"
            folder.mkdir()
            before = set(Path(tmp).rglob("*"))
            rc, err, outcome = run(generated, folder)
            lines = [ln for ln in err.strip().splitlines() if ln.strip()]
            if outcome == "message" and (len(lines) != 1 or not lines[0].startswith("error:")):
                outcome = "message not one line"
            if outcome == "ran" and not (folder / "out" / result).is_file():
                outcome = f"ran without {result}"
            stray = [p for p in set(Path(tmp).rglob("*")) - before
                     if folder / "out" not in p.parents and p != folder / "out"
                     and p.name not in INPUTS]
            if stray:
                outcome = "wrote outside the output folder"
        kind = outcome.split(":")[0]
        counts[kind] += 1
        if kind not in ("ran", "message"):
            examples.setdefault(kind, []).append(
                f"{kind_of(generated)}: {'; '.join(changes_of(generated))} -> {outcome}")
            print(f"  [{what}] {examples[kind][-1]}"[:400], flush=True)
        if sum(counts.values()) % 10 == 0:  # a running tally (a long survey on a busy machine)
            print(f"  [{what}] so far {sum(counts.values())}: " + ", ".join(
                f"{k} {v}" for k, v in counts.most_common()), flush=True)

    survey()
    total = sum(counts.values())
    print(f"generated {what}: {total}")
    for kind, k in counts.most_common():
        print(f"  {kind}: {k}")
    print("  by kind: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items())))
    for kind, ex in examples.items():
        print(f"\nfirst {min(5, len(ex))} of {kind}:")
        for e in ex[:5]:
            print("  " + e)
    sys.stdout.flush()


def checkpoint_survey() -> None:
    """Every edit of every checkpoint kind, resumed: refused or not."""
    with tempfile.TemporaryDirectory() as tmp:
        rows = hostile_checkpoints.survey_archives(Path(tmp))
        rows += hostile_checkpoints.survey_members(Path(tmp))
    verdicts = Counter(v.split(":")[0] for _, _, v in rows)
    names = list(dict.fromkeys(k for k, _, _ in rows))
    print(f"edited checkpoints: {len(rows)} over {len(names)} kinds ({', '.join(names)})")
    for v, k in verdicts.most_common():
        print(f"  {v}: {k}")
    for kind, label, verdict in rows:
        if verdict != "refused":
            print(f"  {kind}: {label} -> {verdict}")
    sys.stdout.flush()


def size_survey() -> None:
    """One call per family of arrays that grow with an input, sized not to fit: refused by
    its own check (one line, estimate and machine's memory) or not."""
    calls = hostile_sizes.size_calls()
    verdicts = Counter()
    for c in calls:
        v = hostile_sizes.verdict(c)
        verdicts[v.split(":")[0]] += 1
        if v != "refused":
            print(f"  size: {c.family} -> {v}"[:400])
    print(f"sizes that cannot fit: {len(calls)} calls over "
          f"{len({c.family for c in calls})} families")
    for v, k in verdicts.most_common():
        print(f"  {v}: {k}")
    sys.stdout.flush()


def api_survey() -> None:
    """Each hostile call of tests/helpers/hostile_api.py over every public name: counts of
    each outcome, the accepted calls classified (legal, with why, or a silent accept of a
    wrong input), every deep error, and the public names not covered."""
    from helpers import hostile_api, hostile_api_more

    import fretwear as fw

    counts: Counter = Counter()
    reasons: Counter = Counter()
    others = []
    with tempfile.TemporaryDirectory() as tmp, contextlib.chdir(tmp):  # a relative path given
        calls = hostile_api.all_calls(Path(tmp))  # to a call (a checkpoint '1') lands there
        for label, name, key, value, thunk in calls:
            out = hostile_api.outcome(thunk)
            kind = out.split(":")[0]
            if kind == "accepted":
                why = hostile_api.legal(name, key, value)
                kind = "accepted (legal)" if why else "silent accept"
                if why:
                    reasons[why] += 1
                else:
                    others.append(f"{label} -> silent accept")
            elif kind not in ("message", "accepted with a warning"):
                others.append(f"{label} -> {out}")
            counts[kind] += 1
    names = {name for _, name, _, _, _ in calls} | set(hostile_api_more.NOT_CALLED)
    names |= {n for v in hostile_api.COVERS.values() for n in v}
    missing = sorted(set(fw.__all__) - names)
    bad = hostile_api_more.check_not_called()
    failed = "; FAILED: " + ", ".join(bad) if bad else ""
    print(f"API calls: {sum(counts.values())} over {len(set(fw.__all__) - set(missing))} of "
          f"the {len(fw.__all__)} public names (fretwear.__all__; "
          f"{len(hostile_api_more.NOT_CALLED)} checked without calls: "
          f"{', '.join(hostile_api_more.NOT_CALLED)}{failed})")
    print(f"  names not covered: {', '.join(missing) if missing else 'none'}")
    for kind, n in counts.most_common():
        print(f"  {kind}: {n}")
    print("  why the accepted calls are legal:")
    for why, n in reasons.most_common():
        print(f"    {n} x {why}")
    for line in others:
        print("  " + line)


if __name__ == "__main__":
    main()
