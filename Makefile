# Two entry points, each sets itself up from scratch: `make demo` and `make test`.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test lint bench clean speedups clean-speedups

$(STAMP): pyproject.toml
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	$(BIN)/joyfly demo

test: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy sitl_emu joyfly
	$(BIN)/python -m pytest -q

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy sitl_emu joyfly

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
