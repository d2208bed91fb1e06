"""Fakes, in-memory link contexts, free ports, scripted flights and a pty job helper shared by the tests."""

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]  # the repository: README.md, examples/, pyproject.toml
