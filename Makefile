# mitsuba-birefringent — build, render and test entry points.
#
#   make render   the main job: builds everything (make setup), then makes out/fig1.png
#                 and out/fig1.json (Figure 1 of the paper's supplemental)
#   make test     builds everything (make setup), then runs every test: cargo's, then pytest's
#   make setup    cargo build --release + the virtualenv .venv/ from requirements.txt;
#                 idempotent, and quick when nothing changed
#   make fmt      cargo fmt --check
#   make lint     cargo clippy on all targets, warnings are errors
#   make clean    removes build outputs (target/, out/, Python caches); keeps .venv/
#   make distclean  clean, and removes .venv/ too
#
# There is no `bench` target yet: it will be added together with the first benchmarks.

SHELL := bash
.SHELLFLAGS := -euo pipefail -c
.DEFAULT_GOAL := help
.DELETE_ON_ERROR:

# cargo from PATH, else rustup's default location (for shells that did not source ~/.cargo/env).
CARGO ?= $(shell command -v cargo 2>/dev/null || echo $(HOME)/.cargo/bin/cargo)
PYTHON ?= python3

VENV := .venv
VPY := $(VENV)/bin/python
VENV_STAMP := $(VENV)/.stamp
BIN := target/release/birefringence
OUT := out
PYTESTS := tests/python

PIP_FLAGS := --disable-pip-version-check --no-input --progress-bar off

.PHONY: help setup build venv render test test-rust test-python fmt lint clean distclean

help:
	@sed -n '3,13s/^# \{0,1\}//p' $(firstword $(MAKEFILE_LIST))

## ---- set-up -------------------------------------------------------------------------------

setup: build venv

# Always asks cargo: it tracks the Rust sources itself and returns in well under a second when
# target/ is up to date. Builds the library and the `birefringence` calculator binary.
build:
	$(CARGO) build --release

venv: $(VENV_STAMP)

# Re-run only when requirements.txt changes (or the venv is missing). The stamp is written last,
# so an interrupted or failed install is retried by the next make.
$(VENV_STAMP): requirements.txt
	@if [ ! -x $(VPY) ]; then \
	  echo "creating virtualenv $(VENV)/ with $$($(PYTHON) --version 2>&1)"; \
	  $(PYTHON) -m venv $(VENV) || { \
	    echo "error: '$(PYTHON) -m venv' failed; on Debian install python3-venv (apt-get install python3-venv)" >&2; \
	    rm -rf $(VENV); exit 1; }; \
	fi
	$(VPY) -m pip install $(PIP_FLAGS) -r requirements.txt
	@touch $@

## ---- main job ---------------------------------------------------------------------------

# Figure 1 of the supplemental: Fresnel power ratios of an isotropic/uniaxial interface,
# computed by the calculator binary. Always regenerated (a few seconds).
render: setup
	@mkdir -p $(OUT)
	$(VPY) tools/plot_fig1.py $(BIN) $(OUT)

## ---- tests ------------------------------------------------------------------------------

test: setup
	$(MAKE) --no-print-directory test-rust
	$(MAKE) --no-print-directory test-python

test-rust:
	$(CARGO) test --release

# pytest exits 5 when it collects no test: that is accepted only if tests/python really holds
# no test file; any other non-zero exit (or 5 with test files present) is a failure.
test-python: venv
	@rc=0; $(VPY) -m pytest -q $(PYTESTS) || rc=$$?; \
	if [ $$rc -eq 5 ] && [ -z "$$(find $(PYTESTS) -name 'test_*.py' -o -name '*_test.py' 2>/dev/null)" ]; then \
	  echo "$(PYTESTS): no Python test files; nothing to run"; rc=0; \
	fi; \
	exit $$rc

## ---- code quality ----------------------------------------------------------------------

fmt:
	$(CARGO) fmt --all -- --check

lint:
	$(CARGO) clippy --all-targets -- -D warnings

## ---- cleaning ---------------------------------------------------------------------------

clean:
	$(CARGO) clean
	rm -rf $(OUT) .pytest_cache
	find . -path ./$(VENV) -prune -o -type d -name __pycache__ -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)
