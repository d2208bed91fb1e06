"""Both programs' -h say a default and a range one way, `[default: 1.0; 0.1 to 100]` (fly's own options did, click's
ranges said `0.1<=x<=100.0`), with one bracket (--view-port had `[default: a free one]. [1<=x<=65535]`); --fence-action
says the rule joyfly/session/fence_watch.py applies."""

from __future__ import annotations

import re
from typing import Any

from click.testing import CliRunner

from joyfly.cli import main as joyfly
from joyfly.session.fence_watch import FENCE_GRACE_S, FENCE_TOLERANCE_M, RETURN_M_S, RETURN_WINDOW_S
from sitl_emu.cli.main import main as sitl_emu


def _help(group: Any, *args: str) -> str:
    result = CliRunner().invoke(group, [*args, "--help"], prog_name="x", terminal_width=1000)
    assert result.exit_code == 0, result.output
    return " ".join(result.output.split())


def test_defaults_and_ranges_read_one_way_in_both_programs() -> None:
    serve, demo, fly = _help(sitl_emu, "serve"), _help(joyfly, "demo"), _help(joyfly, "fly")
    assert "[default: 1.0; 0.1 to 100]" in serve and "[default: 1.0; 0.1 to 100]" in demo
    assert "[default: 2.0; 0.1 to 50]" in fly
    for text in (serve, demo, fly):
        assert not re.search(r"<=?x|x<=?|x>=?", text), text  # click's own range style
        assert "]. [" not in text and "[default: (a free one); 1 to 65535]" in text  # --view-port, --view-grpc-port


def test_fence_action_help_says_the_rule_the_code_applies() -> None:
    fly = _help(joyfly, "fly")
    words = fly[fly.index("--fence-action"):][:600]
    assert f"more than {FENCE_TOLERANCE_M:g} m outside the fence" in words
    assert f"outside {FENCE_GRACE_S:g} s and is not coming back" in words
    assert f"closing in at under {RETURN_M_S:g} m/s over the last {RETURN_WINDOW_S:g} s" in words
    assert "warn does nothing more" in words
