# The CAM toolkit: build, test, demo parts, benchmarks.
#   make demo    every demo part into out/<part>/ (one rule per pipeline stage)
#   make test    all unit, property and end-to-end tests, then every demo part, each of its NC
#                programs read by LinuxCNC's rs274 (where installed) and its collision report checked
#   make check   formatting, clippy -D warnings, then the tests
# Demo parameters are variables: `make demo-sine SINE_TOL=0.001`.

SHELL := bash
.SHELLFLAGS := -eu -o pipefail -c
.DELETE_ON_ERROR:
.SUFFIXES:
MAKEFLAGS += --no-builtin-rules --warn-undefined-variables

CARGO ?= cargo
# Where cargo puts release binaries: its default, or the user's CARGO_TARGET_DIR.
CARGO_TARGET_DIR ?= target
RELEASE := $(CARGO_TARGET_DIR)/release
OUT := out

# Each demo part's pipeline is a fragment mk/<part>.mk that adds itself to DEMOS and the filters
# it runs to FILTERS; stage rules depend on $(RELEASE)/<filter>, which cargo keeps up to date.
FILTERS :=
DEMOS :=
include $(sort $(wildcard mk/*.mk))
BINS := $(addprefix $(RELEASE)/,$(sort $(FILTERS)))

.PHONY: all build test lint check fmt docs demo bench clean FORCE
all: build

build: $(BINS)

$(BINS): FORCE
	$(CARGO) build --release --bins

# Property tests run from a fixed seed, so CI reruns exactly the cases checked before landing;
# `make test PROPTEST_SEED=$$RANDOM` explores new ones.
PROPTEST_SEED ?= 20261122
# The tests run on release builds, the binaries `make demo` runs, so the workspace and its
# dependencies are compiled once (a debug build beside the release one doubled CI's compile time;
# four internal debug assertions are then left to `cargo test`), by nextest where it is installed
# (tests of different files side by side on every core), else by cargo test.
TEST_RUN := $(shell $(CARGO) nextest --version >/dev/null 2>&1 && echo 'nextest run --no-fail-fast' || echo test)
test:
	$(CARGO) build --release --bins
	PROPTEST_RNG_SEED=$(PROPTEST_SEED) $(CARGO) $(TEST_RUN) --release --workspace
	$(MAKE) demo
	scripts/check-demos.sh $(OUT)

lint:
	$(CARGO) fmt --all -- --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings

check: lint test

fmt:
	$(CARGO) fmt --all

# Regenerates the parts of docs/formats.md made from the code (the toolpath columns).
docs:
	UPDATE_DOCS=1 $(CARGO) test -p camkit --lib docs_in_sync

demo: $(addprefix demo-,$(DEMOS))

bench:
	$(CARGO) bench --workspace
	scripts/bench-arcwelder.sh

clean:
	rm -rf $(OUT)
	$(CARGO) clean

%/:
	mkdir -p $@
