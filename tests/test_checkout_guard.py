"""The snapshot behind tests/conftest.py's check that no test leaves files in the checkout."""

from __future__ import annotations

from pathlib import Path

from support.checkout_guard import checkout_files, left_behind, top_level_files


def test_a_new_folder_is_named_once_and_caches_are_ignored(tmp_path: Path) -> None:
    (tmp_path / "sitl_emu").mkdir()
    (tmp_path / "sitl_emu" / "geo.py").write_text("")
    before = checkout_files(tmp_path)
    (tmp_path / "log" / "2026-11-28").mkdir(parents=True)  # what `sitl-emu serve` writes in its working directory
    (tmp_path / "log" / "2026-11-28" / "10_00_00.ulg").write_bytes(b"ULog")
    (tmp_path / "parameters.params").write_text("MIS_TAKEOFF_ALT 5\n")
    for cache in ("sitl_emu/__pycache__", ".pytest_cache", "build/compiled-check", ".venv/lib", "x.egg-info"):
        (tmp_path / cache).mkdir(parents=True)
        (tmp_path / cache / "junk").write_text("")
    assert left_behind(before, checkout_files(tmp_path)) == ["log", "parameters.params"]


def test_nothing_new_is_nothing_left(tmp_path: Path) -> None:
    (tmp_path / "README.md").write_text("")
    before = checkout_files(tmp_path)
    (tmp_path / "README.md").write_text("edited")
    assert left_behind(before, checkout_files(tmp_path)) == []


def test_the_top_level_listing_sees_what_a_server_leaves_in_its_working_directory(tmp_path: Path) -> None:
    (tmp_path / "tests").mkdir()
    before = top_level_files(tmp_path)
    (tmp_path / "tests" / "deep.txt").write_text("")  # the module's walk finds this one
    (tmp_path / "log").mkdir()
    (tmp_path / "parameters.params").write_text("")
    (tmp_path / ".pytest_cache").mkdir()
    assert left_behind(before, top_level_files(tmp_path)) == ["log", "parameters.params"]
