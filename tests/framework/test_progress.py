"""Progress lines (tqdm) leave the first, JIT-compiling item out of the rate; long steps beat."""
import logging
import re
import time

from pointatlas.progress import Heartbeat, Progress


def test_progress_lines_rate_excludes_the_first_item(caplog):
    logger = logging.getLogger("test.progress")
    with caplog.at_level(logging.INFO, logger="test.progress"):
        for i in Progress(range(6), desc="charts", interval=0.0, logger=logger):
            time.sleep(0.4 if i == 0 else 0.02)  # the first item "compiles"
    lines = [r.getMessage() for r in caplog.records]
    assert lines[-1].startswith("charts: 6/6 (100%)")
    rate = float(re.search(r"([\d.]+)it/s", lines[-1]).group(1))
    assert rate > 15  # 5 items in ~0.1 s; with the first item it would be < 12/s
    assert len(lines) == len(set(lines))  # no repeated line


def test_open_ended_progress_and_manual_updates(caplog):
    logger = logging.getLogger("test.progress2")
    with caplog.at_level(logging.INFO, logger="test.progress2"):
        p = Progress(desc="steps", interval=0.0, logger=logger)
        for _ in range(3):
            p.update()
        p.close()
    assert p.count == 3 and caplog.records[-1].getMessage().startswith("steps: 3 ")


def test_heartbeat_logs_long_steps_only(caplog):
    logger = logging.getLogger("test.beat")
    with caplog.at_level(logging.INFO, logger="test.beat"):
        with Heartbeat("assembly", logger, every=0.05):
            time.sleep(0.18)
        n = len(caplog.records)
        with Heartbeat("short", logger, every=1.0):
            time.sleep(0.01)
    assert n >= 2 and all("assembly: still running" in r.getMessage() for r in caplog.records)
    assert len(caplog.records) == n
