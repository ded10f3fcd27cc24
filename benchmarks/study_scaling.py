"""How a study scales on Dask: a fixed 8-member study with 1 and 2 local workers.

The study: the paper's beam (Salles et al. 2011, section 4.2) on its 30 x 4 mesh, a sweep of
``--points`` frequencies (7 harmonics, 128 samples, the paper's settings) around its first
frictional resonance, over a grid of 8 friction coefficients (0.1 ... 0.45): members of 3-6 s
each, so that the figures are about the solves rather than Dask's per-task costs. Prints, on
this machine and in this run:

- ``in-process``: the 8 members run one after another in this process with the same task
  function the workers run (:func:`fretwear.study.runner.run_member`), after one warm-up run
  (imports, numba cache): the reference;
- ``1 worker`` and ``2 workers``: the wall time of the members on a LocalCluster of that
  many processes (one thread each), after the cluster has started and every worker has run a
  warm-up member (the start-up is printed apart: it is paid once per study);
- the overhead per member of 1 worker against in-process: (T_1 - T_in) / 8;
- ``speedup_2_workers = T_1 / T_2`` on the last line. The target is >= 1.6 on a 2-core
  machine; it needs both cores free (the load average is printed: on a shared machine the
  other processes take their share of the cores and the ratio says as much about them).

Run: ``python benchmarks/study_scaling.py [--points 64]``.
"""

from __future__ import annotations

import argparse
import os
import shutil
import tempfile
import time
from pathlib import Path

from fretwear.examples import __file__ as _examples
from fretwear.study.members import expand
from fretwear.study.runner import local_cluster, run_member, run_members
from fretwear.study.spec import read_study

MU = [0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45]


def _write_study(folder: Path, points: int) -> Path:
    text = (Path(_examples).parent / "beam-linear-frf.toml").read_text()
    text = text[: text.index("[analysis]")] + (
        f'[analysis]\ntype = "sweep"\nf_min = 6e3\nf_max = 8e3\nn_points = {points}\n'
        'spacing = "linear"\nharmonics = 7\nn_samples = 128\nlinear_references = []\n'
        "[output]\nvtu = false\nfigures = false\n")
    (folder / "beam.toml").write_text(text)
    study = folder / "study.toml"
    study.write_text('title = "scaling"\nbase = "beam.toml"\n[grid]\ncontact.mu = '
                     f"[{', '.join(map(str, MU))}]\n")
    return study


def _cluster(n: int):
    from distributed import Client

    t0 = time.perf_counter()
    cluster = local_cluster(n)  # the cluster `fretwear study` starts
    return cluster, Client(cluster), time.perf_counter() - t0


def _warm_up(client, member, folder: Path) -> float:
    """Every worker runs one member once (imports, numba cache) before the timing."""
    t0 = time.perf_counter()
    workers = list(client.scheduler_info()["workers"])
    futures = [client.submit(run_member, member.index, member.text, str(folder / f"w{i}"),
                             workers=[w], pure=False) for i, w in enumerate(workers)]
    client.gather(futures)
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--points", type=int, default=64, help="frequencies per member sweep")
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()}  cores: {os.cpu_count()}")
    tmp = Path(tempfile.mkdtemp(prefix="study-scaling-"))
    try:
        members = expand(read_study(_write_study(tmp, args.points)))
        t0 = time.perf_counter()
        run_member(0, members[0].text, str(tmp / "warm"))
        print(f"in-process warm-up (imports, numba cache, one member): "
              f"{time.perf_counter() - t0:.1f} s")
        t0 = time.perf_counter()
        for m in members:
            rec = run_member(m.index, m.text, str(tmp / "inproc" / m.folder_name)).record
            assert rec.status == "ok", rec.message
        t_in = time.perf_counter() - t0
        print(f"in-process : {t_in:7.1f} s for {len(members)} members "
              f"({t_in / len(members):.2f} s each)")
        times = {}
        for n in (1, 2):
            cluster, client, t_start = _cluster(n)
            try:
                t_warm = _warm_up(client, members[0], tmp / f"warm{n}")
                report = run_members(members, tmp / f"workers{n}", client, progress=False)
                assert all(r.status == "ok" for r in report.records)
                times[n] = report.seconds
                busy = {}
                for r in report.records:
                    busy[r.worker] = busy.get(r.worker, 0.0) + r.seconds
                members_s = " ".join(f"{r.seconds:.1f}" for r in report.records)
            finally:
                client.close()
                cluster.close()
            print(f"{n} worker{'s' if n > 1 else ' '} : {times[n]:7.1f} s  (cluster start "
                  f"{t_start:.1f} s, worker warm-up {t_warm:.1f} s, paid once per study)")
            print(f"    members [s]: {members_s}; busy per worker [s]: "
                  f"{' '.join(f'{b:.1f}' for b in busy.values())}")
        print(f"overhead per member, 1 worker vs in-process: "
              f"{(times[1] - t_in) / len(members):+.3f} s")
        print(f"load average after: {os.getloadavg()}")
        print(f"speedup_2_workers={times[1] / times[2]:.2f}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
