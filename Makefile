# Two entry points, each sets itself up from scratch: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
# Two stamps: the demo needs the package only (a venv of about 255 MB, installed in about 10 s), the tests
# the whole [test] extra (MAVSDK, MAVProxy, Ray, Rerun, Selenium...: about 1.7 GB). `make test` after `make demo` adds
# the test extra to the same venv.
DEMO_STAMP := $(VENV)/.installed-demo
STAMP := $(VENV)/.installed-test

.PHONY: demo test test-fast test-compiled compiled-check lint bench clean speedups clean-speedups

# Two pytest workers (pytest-xdist): every test picks free ports and writes only under tmp_path, so they run side by
# side. A module's tests stay on one worker (--dist loadfile), so a module's fixture runs once.
# `make test TEST_WORKERS=0`: one process.
TEST_WORKERS ?= 2
PARALLEL = -n $(TEST_WORKERS) --dist loadfile

$(DEMO_STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet --no-compile -e .
	touch $(DEMO_STAMP)

$(STAMP): $(DEMO_STAMP)
	$(BIN)/python -m pip install --quiet "setuptools>=77" -e '.[test]'
	touch $(STAMP)

demo: $(DEMO_STAMP)
	$(BIN)/joyfly demo

test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy sitl_emu joyfly flightview px4common
	$(BIN)/python -m pytest -q $(PARALLEL)
	$(MAKE) test-compiled

# The edit-test loop: every test but the `slow` ones (subprocesses, MAVSDK, MAVProxy, the browser, SDL and long
# end-to-end flights; tests/conftest.py), in one process: about a minute of CPU time.
test-fast: $(STAMP)
	$(BIN)/python -m pytest -q -m "not slow"

# The opt-in compiled build, checked in a scratch copy (your tree is left as it is): build it, then the tests of the
# vehicle core, Sim and the link (the `compiled` marker, given in tests/conftest.py), including
# tests/sitl_emu/vehicle/test_speedups_exact.py (compiled and pure Python fly bit-identically).
CHECK_DIR := build/compiled-check
test-compiled: $(STAMP)
	@if ! command -v "$$($(BIN)/python -c 'import sysconfig; print((sysconfig.get_config_var("CC") or "cc").split()[0])')" \
	    >/dev/null; then echo "No C compiler here: the compiled-build check is skipped."; exit 0; fi; \
	$(MAKE) --no-print-directory compiled-check

compiled-check:
	rm -rf $(CHECK_DIR) && mkdir -p $(CHECK_DIR)
	cp -r sitl_emu joyfly flightview px4common tests tools examples pyproject.toml README.md $(CHECK_DIR)/
	cp setup.py MANIFEST.in $(CHECK_DIR)/  # the wheel build test (tests/sitl_emu/test_speedups_build.py)
	cd $(CHECK_DIR) && $(abspath $(BIN))/python tools/build_speedups.py
	cd $(CHECK_DIR) && $(abspath $(BIN))/python -m pytest -q -p no:cacheprovider $(PARALLEL) -m compiled

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy sitl_emu joyfly flightview px4common

bench: $(STAMP)
	$(BIN)/python -m bench

# Opt-in: compile the vehicle core's hot modules in place with mypyc (tools/build_speedups.py). Nothing else
# compiles anything; a stale build is bypassed at import with a warning (sitl_emu/_speedups.py).
speedups: $(STAMP)
	$(BIN)/python tools/build_speedups.py

clean-speedups:
	find sitl_emu -name '*.so' -delete
	rm -rf sitl_emu/_speedups_manifest.json build/mypyc

clean: clean-speedups
	rm -rf $(VENV) build *.egg-info
