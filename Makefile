# mitsuba-birefringent — build, render and test entry points.
#
#   make render   the main job: builds everything (make setup), then renders the default scene
#                 (a photoelastic disk under diametral compression between crossed circular
#                 polarisers: its isochromatic fringes) by colour channels (render_analytic,
#                 the multijitter sampler) to out/photoelastic_disk.exr and .png, and Figure 1
#                 of the paper's supplemental to out/fig1.png and out/fig1.json
#   make gallery  make setup, then renders every scene of scenes/ at gallery size (by colour
#                 channels where one plate is on every path; each scene's GALLERY options) into
#                 out/gallery/ and the contact sheet scenes/gallery.png (24 min on 2 cores at load
#                 average 10; docs/scenes.md lists each panel's samples and time)
#   make test     builds everything (make setup), then runs every test: cargo fmt --check, cargo
#                 clippy (warnings are errors), cargo's tests, then pytest's, then make fuzz-ci
#   make setup    cargo build --release, the virtualenv .venv/ from requirements.txt, Debian's
#                 libllvm19 if missing (for Mitsuba's llvm_ad_* variants), the Mitsuba plugin
#                 library (cpp/) and the mitsuba_birefringent package in .venv/; idempotent,
#                 and quick when nothing changed
#   make plugin   (part of setup) the plugin library plugin/mitsuba_birefringent/*.so and the
#                 package in .venv/ (an editable install: `pip install -e .`, the same build as
#                 `pip install .` and `pip wheel .`, see pyproject.toml), with its command
#                 mitsuba-birefringent
#   make fmt      cargo fmt --check
#   make lint     cargo clippy on all targets, warnings are errors
#   make clean    removes build outputs (target/, out/, Python caches, the scenes' generated
#                 textures scenes/data/*.exr); keeps .venv/
#   make distclean  clean, and removes .venv/ too
#   make fuzz     make setup, then a long fuzz campaign: every libFuzzer target of tests/fuzz/
#                 (the C ABI, the JSON calculator) for FUZZ_SECONDS each (default 600), then the
#                 plugin-parameter fuzzer for FUZZ_SECONDS; FUZZ_STRICT=1 also fails on soft
#                 findings (the core's internal error, a power fraction > 1; see
#                 tests/fuzz/run.sh), FUZZ_EXHAUSTIVE=1 on slow inputs too (one process)
#   make fuzz-ci  (part of test) the same, strict (FUZZ_STRICT=1: soft findings fail), for
#                 FUZZ_CI_SECONDS per libFuzzer target (10) and PLUGIN_FUZZ_CI_SECONDS (20)
#                 for the plugin fuzzer
#   make mutants  (not part of test) mutation testing: each mutation of tests/mutants/mutants.toml
#                 applied alone to a scratch copy in target/mutants/, rebuilt, and the tests that
#                 claim to cover it run; prints which are killed and which survive, fails if one
#                 survives or no longer applies (tools/mutants.py; MUTANTS=id,id runs only those)
#   make bench    make setup, then the core benchmark on one core (taskset -c 0) and its plot:
#                 bench/out/core.json, bench/out/core_error_vs_time.png (several minutes), then
#                 make bench-scenes, make bench-stack, make bench-jit, make bench-kernels and
#                 make bench-gradients
#   make bench-stack  layered stacks (examples/bench_stack.rs, one core): a 4-layer stack against
#                 one plate at one wavelength and over XYZ (issue goals: at most 4x each), and the
#                 channel integration's colour error on BENCH_STACKS random stacks against dense
#                 quadrature; bench/out/stack.json
#   make bench-jit  the plugins in the llvm variants (evaluated mode): render time against
#                 Mitsuba's dielectric/thindielectric and against the scalar variants, peak
#                 memory; bench/out/jit.json and bench/out/jit.png
#   make bench-kernels  the plugins in Mitsuba's default mode (their programs replayed in the
#                 kernel) against Mitsuba's own plugins: six quartz plates, a bouncing calcite and
#                 glass sphere; render time ratios, first render with an empty and a warm kernel
#                 cache, peak memory; bench/out/kernels.json and bench/out/kernels.png
#   make bench-cuda  the same in the cuda_ad variants (a machine with an NVIDIA GPU)
#   make bench-gradients  gradient renders of the photoelastic disk (llvm_ad_spectral_polarized):
#                 time and peak memory of a primal, a forward- and a reverse-mode gradient
#                 render; bench/out/gradients.json
#   make bench-scenes  the scene benchmarks alone: the core's shortcuts (examples/bench_shortcuts.rs,
#                 one core), error vs time per scene, overhead against Mitsuba's own plugins;
#                 writes bench/results.json, bench/out/ (JSON, PNG plots), docs/benchmarks.md
#                 and the summary of it in README.md (~4 min)
#   make bench-overhead  the overhead table alone (ours against Mitsuba's own plugins, isotropic
#                 and anisotropic scenes), merged into bench/results.json, docs/benchmarks.md
#                 and README.md's summary; the other figures are kept
#   make bench-variants  what each variant costs with the plugins (render time against
#                 scalar_spectral_polarized in alternating pairs, peak memory of a process per
#                 variant: bench/variants.py) and the default render's noise per sampler and
#                 time (bench/default_render.py); printed, and written to bench/out/variants.json
#                 and default_render.json (25 and 75 min on 2 cores at load average 6-12)

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

# The Mitsuba plugin library: the crate cpp/ (the C++ shim, compiled by cpp/build.rs against the
# headers of the mitsuba/drjit/nanobind wheels in SITE with the wheel-matching flags, linked with
# the core), copied into the Python package plugin/mitsuba_birefringent/. The Python build backend
# (build_backend/birefringent_backend.py, BUILD_COMMAND) builds it with `make plugin-lib`, passing
# the site-packages of its build environment as SITE (.venv/'s for make setup).
PLUGIN_SO := plugin/mitsuba_birefringent/libmitsuba_birefringent.so
PLUGIN_BUILT := target/release/libmitsuba_birefringent.so
# site-packages of .venv/ (evaluated when used: the venv may not exist yet when make starts)
SITE = $(shell $(VPY) -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')

.PHONY: help setup build venv llvm plugin plugin-lib render gallery test test-rust test-python mutants fuzz fuzz-ci bench bench-scenes bench-overhead bench-jit bench-variants bench-kernels bench-cuda bench-gradients bench-stack fmt lint clean distclean

help:
	@sed -n '3,/^$$/s/^# \{0,1\}//p' $(firstword $(MAKEFILE_LIST))

## ---- set-up -------------------------------------------------------------------------------

setup: build venv llvm plugin

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

# Dr.Jit's LLVM backend (the llvm_ad_* variants) needs libLLVM >= 16 at run time; Debian 12's
# default libLLVM 14/15 fail while compiling kernels. Debian's libllvm19 works, and Dr.Jit finds
# it without DRJIT_LIBLLVM_PATH. Installed with apt-get (through sudo unless root) when missing;
# elsewhere install libLLVM >= 16 and point DRJIT_LIBLLVM_PATH at it.
llvm:
	@if command -v dpkg >/dev/null 2>&1; then \
	  if ! dpkg -s libllvm19 >/dev/null 2>&1; then \
	    echo "installing Debian's libllvm19 (run time of Dr.Jit's LLVM backend: the llvm_ad_* variants)"; \
	    sudo=$$([ "$$(id -u)" = 0 ] || echo sudo); \
	    $$sudo apt-get update -qq && \
	    $$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19 >/dev/null; \
	  fi; \
	else \
	  echo "note: not a Debian system; the llvm_ad_* variants need libLLVM >= 16 (DRJIT_LIBLLVM_PATH)"; \
	fi

# The plugin library and the package: `import mitsuba; import mitsuba_birefringent` in .venv/
# registers the BSDFs `thinbirefringent` and `birefringent`. Every run builds the library through
# the build backend, i.e. with the same command as `pip install .`; the package is installed
# editable (a .pth file pointing at plugin/, the metadata and the command mitsuba-birefringent)
# when the packaging changes, which runs the same build again (up to date by then). No network.
EDITABLE_STAMP := $(VENV)/.editable-stamp
plugin: build venv
	@$(VPY) build_backend/birefringent_backend.py
	@$(MAKE) --no-print-directory $(EDITABLE_STAMP)

$(EDITABLE_STAMP): pyproject.toml Cargo.toml build_backend/birefringent_backend.py $(VENV_STAMP)
	$(VPY) -m pip install $(PIP_FLAGS) --no-build-isolation --no-deps --no-index -e .
	@touch $@

# The library alone, against the packages in SITE (the build backend's command; see above).
# cargo rebuilds it only when its sources or the wheels' versions (WHEELS, their dist-info names)
# change, not when another environment with the same wheels is named. It replaces the package's
# copy only when it differs, by a rename (a process that loaded the old one keeps it intact).
WHEELS = $(shell cd $(SITE) && ls -d mitsuba-*.dist-info drjit-*.dist-info nanobind-*.dist-info | sed 's/\.dist-info$$//')
plugin-lib:
	MITSUBA_SITE_PACKAGES=$(SITE) MITSUBA_WHEELS="$(WHEELS)" $(CARGO) build --release -p mitsuba-birefringent-plugin
	@cmp -s $(PLUGIN_BUILT) $(PLUGIN_SO) || { cp $(PLUGIN_BUILT) $(PLUGIN_SO).new && \
	  mv -f $(PLUGIN_SO).new $(PLUGIN_SO) && echo "updated $(PLUGIN_SO)"; }

## ---- main job ---------------------------------------------------------------------------

# The default scene (scenes/photoelastic_disk.py) rendered by colour channels
# (mitsuba_birefringent.render_analytic: one llvm_ad_mono_polarized pass per sRGB channel, the
# plate integrated over each in closed form, no colour noise; the multijitter sampler of
# scenes/render.py, which stratifies each path's choice between the plate's reflection and
# transmission: the brightness noise that remains), and Figure 1 of the supplemental
# (Fresnel power ratios of an isotropic/uniaxial interface, computed by the calculator binary, a
# few seconds). Always regenerated. RENDER_MODE=spectral renders the scene by spectral sampling
# in scalar_spectral_polarized instead.
RENDER_SCENE ?= photoelastic_disk
RENDER_SPP ?= 16
RENDER_SIZE ?= 320
RENDER_MODE ?= analytic
render: setup
	@mkdir -p $(OUT)
	$(VPY) scenes/render.py $(RENDER_SCENE) --out $(OUT) --spp $(RENDER_SPP) --width $(RENDER_SIZE) --height $(RENDER_SIZE) $(if $(filter spectral,$(RENDER_MODE)),,--analytic)
	$(VPY) tools/plot_fig1.py $(BIN) $(OUT)

# Every scene module of scenes/ (a `scene` function and `VARIANTS`) at gallery size, then the
# contact sheet scenes/gallery.png (committed: the README shows it).
GALLERY_WIDTH ?= 320
GALLERY_SPP ?= 16
gallery: setup
	$(VPY) scenes/gallery.py --out $(OUT)/gallery --sheet scenes/gallery.png --width $(GALLERY_WIDTH) --spp $(GALLERY_SPP)

## ---- tests ------------------------------------------------------------------------------

test: setup
	$(MAKE) --no-print-directory fmt
	$(MAKE) --no-print-directory lint
	$(MAKE) --no-print-directory test-rust
	$(MAKE) --no-print-directory test-python
	$(MAKE) --no-print-directory fuzz-ci

test-rust:
	$(CARGO) test --release

# pytest exits 5 when it collects no test: that is accepted only if tests/python really holds
# no test file; any other non-zero exit (or 5 with test files present) is a failure.
test-python: plugin
	@rc=0; $(VPY) -m pytest -q $(PYTESTS) || rc=$$?; \
	if [ $$rc -eq 5 ] && [ -z "$$(find $(PYTESTS) -name 'test_*.py' -o -name '*_test.py' 2>/dev/null)" ]; then \
	  echo "$(PYTESTS): no Python test files; nothing to run"; rc=0; \
	fi; \
	exit $$rc

## ---- mutation testing ------------------------------------------------------------------

# tools/mutants.py: the copy in target/mutants/ builds with its own target dir (incremental
# between mutations and runs) and the wheels of .venv/ (SITE); its tests run with .venv/'s
# interpreter and the copy's package and plugin library (not the editable install's).
MUTANTS ?=
mutants: venv llvm
	$(VPY) tools/mutants.py $(if $(MUTANTS),--only $(MUTANTS))

## ---- fuzzing --------------------------------------------------------------------------

# tests/fuzz/run.sh builds the libFuzzer targets with the stable toolchain (libfuzzer-sys pinned
# in tests/fuzz/Cargo.toml/Cargo.lock, coverage by rustc's stable sancov flags) into
# target/fuzz/ and runs each for the given seconds with a fixed seed; crashing inputs are kept
# in target/fuzz/artifacts/. tests/fuzz/plugin_fuzz.py fuzzes the plugin parameters through
# mi.load_dict in every supported variant, one worker subprocess at a time (a segfault is a
# finding, its input kept in target/fuzz/plugin/). Both print executions and exit 1 on a crash;
# fuzz-ci (make test) also on a soft finding: the core's internal error (a panic it caught, a
# non-finite result it refused), which reaches the renderer only as a warning and no light, or a
# power fraction above 1.
FUZZ_SECONDS ?= 600
FUZZ_CI_SECONDS ?= 10
PLUGIN_FUZZ_CI_SECONDS ?= 20

fuzz: setup
	CARGO=$(CARGO) tests/fuzz/run.sh $(FUZZ_SECONDS)
	$(VPY) tests/fuzz/plugin_fuzz.py --seconds $(FUZZ_SECONDS) $(if $(filter 1,$(FUZZ_STRICT)),--strict)

fuzz-ci: plugin
	FUZZ_STRICT=1 CARGO=$(CARGO) tests/fuzz/run.sh $(FUZZ_CI_SECONDS)
	$(VPY) tests/fuzz/plugin_fuzz.py --seconds $(PLUGIN_FUZZ_CI_SECONDS) --strict

## ---- benchmark ------------------------------------------------------------------------

# examples/bench_core.rs: timings of the exact optics and of the closed-form spectral integration,
# the validation run of tests/spectral_rgb.rs on BENCH_PLATES random plates, and error vs time
# against stochastic wavelength sampling; then bench/plot_core.py. Built by cargo (unpinned),
# run pinned to one core when taskset exists. Results: bench/out/core.json and the plot.
BENCH_OUT := bench/out
BENCH_PLATES ?= 500
BENCH_BIN := target/release/examples/bench_core
TASKSET := $(shell command -v taskset >/dev/null 2>&1 && echo taskset -c 0)

bench: setup
	$(CARGO) build --release --example bench_core
	@mkdir -p $(BENCH_OUT)
	$(TASKSET) $(BENCH_BIN) --validate $(BENCH_PLATES) --out $(BENCH_OUT)/core.json
	$(VPY) bench/plot_core.py $(BENCH_OUT)/core.json $(BENCH_OUT)/core_error_vs_time.png
	$(MAKE) --no-print-directory bench-scenes
	$(MAKE) --no-print-directory bench-stack
	$(MAKE) --no-print-directory bench-jit
	$(MAKE) --no-print-directory bench-kernels
	$(MAKE) --no-print-directory bench-gradients

# examples/bench_stack.rs: interleaved timings of stacks against plates, and the validation of
# tests/stack_spectral.rs on BENCH_STACKS random stacks. Pinned to one core like bench.
BENCH_STACKS ?= 200

bench-stack: setup
	$(CARGO) build --release --example bench_stack
	@mkdir -p $(BENCH_OUT)
	$(TASKSET) target/release/examples/bench_stack --validate $(BENCH_STACKS) --out $(BENCH_OUT)/stack.json

# bench/jit.py: the overhead scenes of bench/scenes.py in every llvm variant in evaluated mode
# (ours against Mitsuba's own plugins, and against ours in the scalar variants), interleaved
# rounds in one process per variant, peak memory in one process per configuration.
bench-jit: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/jit.py --out $(BENCH_OUT)

# bench/kernels.py: ours and Mitsuba's plugins both in Mitsuba's default (symbolic) mode; each
# configuration in processes of its own (kernel cache cold, then warm), the time ratios from
# interleaved rounds in one process. bench-cuda: the same rows in the cuda_ad variants.
bench-kernels: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/kernels.py --out $(BENCH_OUT)

bench-cuda: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/kernels.py --backend cuda --out $(BENCH_OUT)

# bench/gradients.py: a primal, forward- and reverse-mode gradient renders of the photoelastic
# disk in llvm_ad_spectral_polarized (the plate's birefringence texture, its thickness, and a
# parameter of Mitsuba's own retarder for comparison), interleaved in one process (CPU and wall
# time), peak memory in one process per configuration.
bench-gradients: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/gradients.py --out $(BENCH_OUT)

# examples/bench_shortcuts.rs (speed ratios of the core's shortcuts, one core), then
# bench/scenes.py (every scene module of scenes/: error vs time against an exact
# per-wavelength reference, cached in bench/out/ by scene + parameters, the channel render
# render_analytic among the methods; render-time overhead against Mitsuba's
# thindielectric/dielectric, isotropic and anisotropic scenes), which writes bench/results.json;
# bench/equal_time.py (the channel render and spectral sampling at equal time:
# bench/analytic_vs_spectral.png); then bench/readme.py regenerates docs/benchmarks.md between
# <!-- bench:begin --> and <!-- bench:end --> and README.md's summary of it.
bench-scenes: setup
	$(CARGO) build --release --example bench_shortcuts
	@mkdir -p $(BENCH_OUT)
	$(TASKSET) target/release/examples/bench_shortcuts --out $(BENCH_OUT)/shortcuts.json
	$(VPY) bench/scenes.py --out $(BENCH_OUT) --results bench/results.json
	$(VPY) bench/equal_time.py --out $(BENCH_OUT) --results bench/results.json
	$(VPY) bench/readme.py bench/results.json docs/benchmarks.md README.md

# Part 2 of bench/scenes.py alone (render-time overhead against thindielectric/dielectric, the
# isotropic and the anisotropic rows), merged into bench/results.json; then the README section.
bench-overhead: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/scenes.py --only overhead --out $(BENCH_OUT) --results bench/results.json
	$(VPY) bench/readme.py bench/results.json docs/benchmarks.md README.md

# bench/variants.py (each variant's time and memory with the plugins, one process per
# measurement, rounds interleaved) and bench/default_render.py (make render's remaining noise
# per sampler and its time against spectral sampling): the figures README.md states.
bench-variants: setup
	@mkdir -p $(BENCH_OUT)
	$(VPY) bench/variants.py --out $(BENCH_OUT)/variants.json
	$(VPY) bench/default_render.py --out $(BENCH_OUT)/default_render.json

## ---- code quality ----------------------------------------------------------------------

fmt:
	$(CARGO) fmt --all -- --check

lint:
	$(CARGO) clippy --all-targets -- -D warnings

## ---- cleaning ---------------------------------------------------------------------------

clean:
	$(CARGO) clean
	rm -f $(PLUGIN_SO)
	rm -rf $(OUT) $(BENCH_OUT) .pytest_cache
	rm -f scenes/data/*.exr
	find . -path ./$(VENV) -prune -o -type d -name __pycache__ -prune -exec rm -rf {} +

distclean: clean
	rm -rf $(VENV)
