# bulge: two commands do everything on a fresh Debian/Ubuntu (or macOS) machine.
#   make demo   install what is missing, build, run the pipeline on data/demo, write out/
#   make test   install what is missing, run the whole test suite (default
#               features), check that the library builds without OpenCV,
#               plotters and clap, then build the Python package and run
#               its tests against the command line
SHELL := /bin/bash
CARGO ?= cargo
OUT ?= out
TARGET := $(or $(CARGO_TARGET_DIR),target)
# A build from scratch (CI, a new clone) is faster without incremental
# compilation's bookkeeping; set CARGO_INCREMENTAL=1 to keep it.
export CARGO_INCREMENTAL ?= 0
# The demo uses the test build (dependencies optimised, bulge at opt-level 1):
# `cargo test --no-run` builds target/debug/bulge with the same dependency
# features as the tests (a plain `cargo build` would not unify them with the
# dev-dependencies and would rebuild half the dependencies), so `make demo`
# and `make test` share one build. Benchmarks use release.
BULGE := $(TARGET)/debug/bulge
BULGE_RELEASE := $(TARGET)/release/bulge

.PHONY: all deps build build-release demo test lint bench bench-peers clean python python-test

all: demo

deps:
	@bash scripts/install-deps.sh

build: deps
	$(CARGO) test --locked --no-run --lib --bins --tests

build-release: deps
	$(CARGO) build --release --locked

demo: build
	@bash scripts/demo.sh $(BULGE) $(OUT)

test: deps
	$(CARGO) test --locked --lib --bins --tests
	$(CARGO) test --locked --doc
	@echo "== the library alone: stress, fit, simulate, axisym (no OpenCV, plotters or clap)"
	@# No code is compiled only without the features, so the tests above
	@# already ran every line this build has; checking the library (not its
	@# test targets, which would check the dev-dependencies too) keeps
	@# make test short: about 1 min 50 s on two cores from a fresh clone,
	@# most of it checking the dependencies without the features (the test
	@# profile shares what it can with the test build).
	$(CARGO) check --locked --profile test --no-default-features --lib
	@echo "== the Python package (python/) against the command line"
	@# It reuses the library and the dependencies built above (same
	@# workspace, profile and features): about a minute and a half from a
	@# fresh clone, most of it pip fetching maturin, pandas and pytest.
	$(MAKE) --no-print-directory python-test

lint: deps
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --locked --workspace --all-targets --features bulge/harness -- -D warnings

bench: build-release
	$(BULGE_RELEASE) bench --out $(OUT)/bench

# bulge beside FElupe (a finite-element code, from PyPI) on the same bubble:
# wall times and errors against the exact heights, in one table.
PEERS_VENV := $(TARGET)/peers-venv
bench-peers: build-release
	@test -x $(PEERS_VENV)/bin/python || python3 -m venv $(PEERS_VENV) || \
	  { echo "bench-peers: python3 -m venv failed (Debian/Ubuntu: apt-get install python3-venv)" >&2; exit 1; }
	$(PEERS_VENV)/bin/pip install --quiet felupe==11.3.0 tensortrax==0.29.0
	$(PEERS_VENV)/bin/python benches/peers/compare.py $(BULGE_RELEASE) benches/peers/mooney-rivlin-disc.toml

# The Python package (python/, PyO3 + maturin) in a virtual environment
# under the target folder, built into the same target folder with the dev
# profile, so that the library and the dependencies built by cargo test
# are reused (python/Cargo.toml says how).
PY_VENV := $(TARGET)/py-venv
python: deps
	@test -x $(PY_VENV)/bin/python || python3 -m venv $(PY_VENV) || \
	  { echo "python: python3 -m venv failed (Debian/Ubuntu: apt-get install python3-venv)" >&2; exit 1; }
	CARGO_TARGET_DIR=$(abspath $(TARGET)) $(PY_VENV)/bin/pip install --quiet ./python pytest

# The bindings checked against the command line's output (needs the bulge
# binary that cargo test builds).
python-test: python
	CARGO_TARGET_DIR=$(abspath $(TARGET)) BULGE_BIN=$(abspath $(BULGE)) $(PY_VENV)/bin/python -m pytest -q python/tests

clean:
	rm -rf $(OUT)
