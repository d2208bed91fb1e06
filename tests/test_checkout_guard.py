"""The snapshot behind tests/conftest.py's check that no test leaves files in the checkout."""

from __future__ import annotations

from pathlib import Path

from support.checkout_guard import checkout_files, left_behind


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
