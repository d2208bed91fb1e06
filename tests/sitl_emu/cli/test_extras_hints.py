"""Installing an optional extra is said one way (README, -h, errors): `pip install -e '.[EXTRA]'` from the clone, and
in an error the command to paste (this Python, this clone's path). Before, `sitl-emu log` said pip install
'joyfly[plot]', campaign -h `pip install ray`, the view `pip install -e '.[view]'`, README 'joyfly[ray]'."""

from __future__ import annotations

import re
import sys

from click.testing import CliRunner
from support import REPO_ROOT

from sitl_emu.cli.extras import in_clone, install_command
from sitl_emu.cli.main import main
from sitl_emu.log.plot import INSTALL_HINT

README = (REPO_ROOT / "README.md").read_text(encoding="utf-8")


def _help(*args: str) -> str:
    return " ".join(CliRunner().invoke(main, [*args, "--help"], terminal_width=400).output.split())


def test_help_texts_say_the_clone_form() -> None:
    assert in_clone("plot") == "pip install -e '.[plot]' in the joyfly clone"
    assert f"the plot extra: {in_clone('plot')}" in _help("log")  # pyulog, for the summary itself
    assert f"the ray extra: {in_clone('ray')}" in _help("campaign")
    assert in_clone("view") in _help("serve")  # flightview's --view help says it the same way


def test_errors_give_a_command_that_works_from_any_folder() -> None:
    assert install_command("plot", "pyulog") == f"{sys.executable} -m pip install -e '{REPO_ROOT}[plot]'"
    assert INSTALL_HINT.endswith(install_command("plot", "x"))


def test_readme_says_the_same_and_names_the_extra_sitl_emu_log_needs() -> None:
    assert not re.search(r"pip install '?joyfly\[", README)  # the package is installed from the clone
    for extra in ("view", "plot", "ray"):
        assert f"`.venv/bin/pip install -e '.[{extra}]'` in the clone" in README, extra
    log_paragraph = README[README.index("`sitl-emu log FILE.ulg` summarises"):][:400]
    assert "pyulog" in log_paragraph and ".[plot]" in log_paragraph
