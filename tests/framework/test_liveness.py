"""A run recorded as running whose process is gone reads as 'died' (issue 15, defect 5)."""
import os
import subprocess
import sys
from datetime import datetime, timedelta, timezone

from pointatlas.catalog import Catalog
from pointatlas.liveness import STALE_S, hostname, identity, pid_alive, process_start, run_alive


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_this_process_is_alive_and_a_finished_one_is_not():
    me = identity()
    assert pid_alive(me["pid"], me["pid_start"])
    assert not pid_alive(_dead_pid())


def test_a_reused_pid_is_not_taken_for_the_run():
    me = identity()
    assert me["pid_start"] == process_start(os.getpid()) != ""
    assert not pid_alive(me["pid"], str(int(me["pid_start"]) + 1))


def test_other_hosts_are_judged_by_their_heartbeat():
    fresh = datetime.now(timezone.utc).isoformat()
    stale = (datetime.now(timezone.utc) - timedelta(seconds=2 * STALE_S)).isoformat()
    assert run_alive(123, "some-other-node", "", fresh)
    assert not run_alive(123, "some-other-node", "", stale)


def test_catalog_lists_a_killed_run_as_died(tmp_path):
    cat = Catalog(tmp_path / "catalog.sqlite")
    start = datetime.now(timezone.utc).isoformat()
    cat.start(run_id="alive", experiment="e", overrides=[], path=None, git_commit="",
              start_time=start, process=identity())
    cat.start(run_id="killed", experiment="e", overrides=[], path=None, git_commit="",
              start_time=start, process={"pid": _dead_pid(), "host": hostname(), "pid_start": ""})
    status = {r.id: r.status for r in cat.runs()}
    assert status == {"alive": "running", "killed": "died"}
    assert [r.id for r in cat.runs(status="died")] == ["killed"]
