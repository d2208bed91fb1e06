"""Benchmarks for sitl_emu and joyfly: `python -m bench` (or `python bench/run.py`, `make bench`).

Every figure is measured on the machine that runs it and printed on one line with its unit; see bench/run.py.
"""
