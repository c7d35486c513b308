"""synth check --cluster (issue 39, build 4): the same jobs on a Dask LocalCluster of two
worker processes on 127.0.0.1 give byte-identical files to the local run, and a worker
killed during the run is survived."""

from __future__ import annotations

import os
import shutil
import signal
from pathlib import Path

import pytest

from synth.line.project import load_line
from synth.line.report import write_line_reports
from synth.line.run import check_line

from test_line_check import EXAMPLE, GATE

distributed = pytest.importorskip("distributed")
TOML = """[[station]]
name = "press"
plant = "m/clamp.rules"
grafcets = ["m/clamp.g7"]
filter = "m/clamp.filter"
checks = ["validate", "filter-check"]
""" + GATE


@pytest.fixture(scope="module")
def cluster():  # type: ignore[no-untyped-def]
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as c:
        yield c


def files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


@pytest.fixture
def line(tmp_path: Path):  # type: ignore[no-untyped-def]
    (tmp_path / "m").mkdir()
    for src in ("plants/clamp.rules", "grafcets/clamp.g7", "plants/clamp.filter", "plants/gate.rules", "grafcets/gate.g7"):
        shutil.copy(EXAMPLE / src, tmp_path / "m")
    (tmp_path / "synth.toml").write_text(TOML, encoding="utf-8")
    return load_line(tmp_path / "synth.toml")


@pytest.mark.slow
def test_the_cluster_gives_the_local_run_byte_for_byte_and_survives_a_killed_worker(cluster, line, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    local = check_line(line, None, mutate=True, workers=2)
    assert (len(local.results), local.computed, local.exit_code) == (22, 22, 1)  # 3 checks, 19 mutants, 4 survivors
    # the checks then the mutants on the same two processes, each compiling a plant at most once
    assert len(local.stats.compiled) == 2 and max(local.stats.compiled.values()) <= 2
    write_line_reports(local, tmp_path / "local")

    remote = check_line(line, None, mutate=True, cluster=cluster.scheduler_address)
    assert remote.results == local.results
    write_line_reports(remote, tmp_path / "remote")
    assert files(tmp_path / "remote") == files(tmp_path / "local")
    assert len(remote.stats.compiled) == 2 and max(remote.stats.compiled.values()) <= 2  # each plant once per worker

    with distributed.Client(cluster.scheduler_address) as client:
        pids = sorted(client.run(os.getpid).values())
    killed: list[int] = []

    def kill_one(job, result, cached: bool) -> None:  # type: ignore[no-untyped-def]
        if not killed:
            killed.append(pids[0])
            os.kill(pids[0], signal.SIGKILL)

    survived = check_line(line, None, mutate=True, cluster=cluster.scheduler_address, progress=kill_one)
    assert killed and survived.results == local.results
    write_line_reports(survived, tmp_path / "survived")
    assert files(tmp_path / "survived") == files(tmp_path / "local")
