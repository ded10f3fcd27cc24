"""Survey: how fretwear answers case files a hostile user writes.

Generates N case files from the schema (tests/helpers/hostile.py: one to three keys of a
small valid case replaced by valid or invalid values for their specification) and runs each with
``fretwear run`` in this process. Prints the count of each outcome: ran (exit 0/1 with a
results file), clean message (exit 2, one line), traceback (an exception escaped), hang
(longer than the time limit), files written outside the output folder, and the first
examples of each failure kind.

    python studies/hostile_inputs.py --n 500 --seed 1
    python studies/hostile_inputs.py --api   # the API calls of tests/helpers/hostile_api.py
"""

from __future__ import annotations

import argparse
import random
import sys
import tempfile
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from helpers import hostile  # noqa: E402
from hypothesis import HealthCheck, given, settings  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=500, help="generated cases")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--api", action="store_true", help="survey the Python API calls instead")
    a = ap.parse_args()
    if a.api:
        api_survey()
        return
    counts: Counter = Counter()
    examples: dict[str, list[str]] = {}

    @settings(max_examples=a.n, deadline=None, database=None, derandomize=False,
              suppress_health_check=list(HealthCheck))
    @given(hostile.hostile_cases())
    def survey(generated):
        case, changes = generated
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp) / "work"
            folder.mkdir()
            before = set(Path(tmp).rglob("*"))
            rc, err, outcome = hostile.run_generated(case, folder)
            lines = [ln for ln in err.strip().splitlines() if ln.strip()]
            if outcome == "message" and (len(lines) != 1 or not lines[0].startswith("error:")):
                outcome = "message not one line"
            if outcome == "ran" and not (folder / "out" / "results.nc").is_file():
                outcome = "ran without results"
            stray = [p for p in set(Path(tmp).rglob("*")) - before
                     if folder / "out" not in p.parents and p != folder / "out"
                     and p.name != "case.toml"]
            if stray:
                outcome = "wrote outside the output folder"
        kind = outcome.split(":")[0]
        counts[kind] += 1
        if kind not in ("ran", "message"):
            examples.setdefault(kind, []).append(f"{'; '.join(changes)} -> {outcome}")

    random.seed(a.seed)
    survey()
    total = sum(counts.values())
    print(f"generated cases: {total}")
    for kind, n in counts.most_common():
        print(f"  {kind}: {n}")
    for kind, ex in examples.items():
        print(f"\nfirst {min(5, len(ex))} of {kind}:")
        for e in ex[:5]:
            print("  " + e)


def api_survey() -> None:
    """Each hostile call of tests/helpers/hostile_api.py: counts of each outcome and every call
    that did not end in a message."""
    from helpers import hostile_api

    counts: Counter = Counter()
    others = []
    for label, thunk in hostile_api.calls():
        out = hostile_api.outcome(thunk)
        counts[out.split(":")[0]] += 1
        if out != "message":
            others.append(f"{label} -> {out}")
    print(f"API calls: {sum(counts.values())}")
    for kind, n in counts.most_common():
        print(f"  {kind}: {n}")
    for line in others:
        print("  " + line)


if __name__ == "__main__":
    main()
