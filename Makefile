# whirl: `make run` and `make test` each install what is missing, then do their job.
SHELL := /bin/bash
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)
STUDY ?= studies/thesis_ch3/hardening_case2.yaml
OUT ?= out

.PHONY: setup system-deps test test-fast lint run generate clean

setup: system-deps $(VENV)/.installed
	@$(BIN)/python -m compileall -q whirl_cli >/dev/null

# Debian packages AUTO-07p needs at run time: the AUTO runtime and gfortran to compile equations.
system-deps:
	@if ! command -v gfortran >/dev/null || [ ! -d /usr/lib/auto-07p/lib ]; then \
	  echo "installing auto-07p and gfortran (Debian packages)"; \
	  $(SUDO) apt-get install -y -q auto-07p gfortran || \
	  { $(SUDO) apt-get update -q && $(SUDO) apt-get install -y -q auto-07p gfortran; }; \
	fi

# bifpy (the second AUTO engine, WHIRL_AUTO_ENGINE=bifpy) compiles AUTO-07p when it is installed;
# its Makefile passes no optimisation flag, so -O2 goes in through MAKEFLAGS (the optimised
# engine runs about twice as fast), and --no-cache-dir keeps pip from reusing a wheel built
# without it. Installed first, so that '.[dev]' finds it satisfied.
BIFPY := bifpy>=0.3,<0.4
BIFPY_MAKEFLAGS := F90=gfortran\ -O2 F77=gfortran\ -O2

$(VENV)/.installed: pyproject.toml
	@[ -x $(BIN)/python ] || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install -q --upgrade pip
	MAKEFLAGS='$(BIFPY_MAKEFLAGS)' $(BIN)/python -m pip install -q --no-cache-dir '$(BIFPY)'
	$(BIN)/python -m pip install -q -e '.[dev]'
	@touch $@

test: setup
	$(BIN)/python -m pytest -q

test-fast: setup
	$(BIN)/python -m pytest -q -m "not auto"

lint: setup
	$(BIN)/ruff check whirl_cli tests benchmarks

run: setup
	@mkdir -p $(OUT)
	$(BIN)/whirl run $(STUDY) -o $(OUT)/$(basename $(notdir $(STUDY))).h5 --overwrite

generate: setup
	$(BIN)/whirl generate

# Every study under studies/ (resumable: up-to-date outputs are skipped) -> results/<name>.h5
SWEEP_JOBS ?= $(shell nproc 2>/dev/null || echo 2)
.PHONY: sweep references bench figures
sweep: setup
	$(BIN)/whirl sweep studies -o results --jobs $(SWEEP_JOBS)

# Every thesis chapter-3 figure (sheets/thesis_ch3) -> figures/fig3_<n>.png + figures/index.html,
# running the studies they need into results/ (up-to-date results are reused)
figures: setup
	$(BIN)/whirl figures sheets/thesis_ch3 -o figures --results results --jobs $(SWEEP_JOBS)

# Regenerate the committed HDF5 references of tests/regression (a deliberate act: review the
# `whirl compare` output against the old files before committing the new ones).
REFERENCES ?= hardening_case2 linear_datum_airspeed
references: setup
	@mkdir -p tests/regression/references
	@for name in $(REFERENCES); do \
	  $(BIN)/whirl run studies/thesis_ch3/$$name.yaml -o tests/regression/references/$$name.h5 \
	    --no-plots --overwrite || exit 1; \
	done
	@ls -l tests/regression/references

# Performance figures (ratios and timings, printed; never asserted in tests)
bench: setup
	$(BIN)/python benchmarks/bench.py

clean:
	rm -rf $(OUT) .pytest_cache build *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
