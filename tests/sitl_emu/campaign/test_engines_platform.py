"""Both sides of the campaign engines' platform seams: the worker count (os.sched_getaffinity is Linux-only) and
the serial engine's wall-time limit (SIGALRM and setitimer are POSIX-only)."""

from __future__ import annotations

import os

import pytest

from sitl_emu.campaign.engines import default_workers


@pytest.mark.skipif(not hasattr(os, "sched_getaffinity"), reason="Linux side (CI is Linux)")
def test_on_linux_the_workers_are_the_cores_this_process_may_use() -> None:
    assert default_workers() == len(os.sched_getaffinity(0))


def test_without_affinity_the_workers_are_the_cores_python_counts(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(os, "sched_getaffinity", raising=False)  # macOS, Windows
    monkeypatch.setattr(os, "cpu_count", lambda: 6)
    monkeypatch.setattr(os, "process_cpu_count", lambda: 3, raising=False)  # 3.13+
    assert default_workers() == 3
    monkeypatch.delattr(os, "process_cpu_count")  # 3.12 and older
    assert default_workers() == 6
    monkeypatch.setattr(os, "cpu_count", lambda: None)  # cannot be known
    assert default_workers() == 1
