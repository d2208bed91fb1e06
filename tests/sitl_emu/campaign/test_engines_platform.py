"""Both sides of the campaign engines' platform seams: the worker count (os.sched_getaffinity is Linux-only) and
the serial engine's wall-time limit (SIGALRM and setitimer are POSIX-only)."""

from __future__ import annotations

import os
import signal

import pytest
from support import campaign_scenarios

from sitl_emu.campaign.cases import make_cases
from sitl_emu.campaign.engines import default_workers
from sitl_emu.campaign.engines.serial import SerialEngine, alarm_available
from sitl_emu.campaign.scenario import Limits, scenario_ref


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


def _serial_rows(behave: str) -> list[tuple[str, str]]:
    cases = make_cases({"options.bad_seeds": [0], "options.behave": behave}, {"seed": [0, 1]})
    rows = SerialEngine().run(scenario_ref(campaign_scenarios.misbehave), cases, Limits(sim_s=None, wall_s=0.5))
    return [(row["status"], row["error"]) for _, row in rows]


TIMED_OUT = ("timeout", "the case passed its limit of 0.5 wall seconds.")


@pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="POSIX side (CI is Linux)")
def test_on_posix_sigalrm_ends_a_case_wherever_it_is() -> None:
    assert alarm_available()
    before = signal.getsignal(signal.SIGALRM)
    assert _serial_rows("hang") == [TIMED_OUT, ("passed", "")]  # asleep outside the Sim
    assert signal.getsignal(signal.SIGALRM) == before


def test_without_sigalrm_the_sims_next_step_ends_the_case(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delattr(signal, "setitimer", raising=False)  # Windows
    monkeypatch.delattr(signal, "SIGALRM", raising=False)
    assert not alarm_available()
    assert _serial_rows("slow_steps") == [TIMED_OUT, ("passed", "")]
