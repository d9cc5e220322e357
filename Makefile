# bulge: two commands do everything on a fresh Debian/Ubuntu (or macOS) machine.
#   make demo   install what is missing, build, run the pipeline on data/demo, write out/
#   make test   install what is missing, run the whole test suite
SHELL := /bin/bash
CARGO ?= cargo
OUT ?= out
BULGE := $(or $(CARGO_TARGET_DIR),target)/release/bulge

.PHONY: all deps build demo test lint bench clean

all: demo

deps:
	@bash scripts/install-deps.sh

build: deps
	$(CARGO) build --release --locked

demo: build
	@bash scripts/demo.sh $(BULGE) $(OUT)

test: deps
	$(CARGO) test --locked --all-targets
	$(CARGO) test --locked --doc

lint: deps
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --locked --all-targets -- -D warnings

bench: build
	$(BULGE) bench --out $(OUT)/bench

clean:
	rm -rf $(OUT)
