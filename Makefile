# sins-fw: `make demo` and `make test` do all the set-up on a fresh machine (Python 3.11, Rust,
# PyPI and crates.io reachable): a virtual environment, the pinned dependencies, the extension built
# in release mode. A second run with nothing changed rebuilds nothing.

PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
DEPS   := $(VENV)/.deps-installed
BUILT  := $(VENV)/.extension-built
# The C ABI library `sins-fw build-firmware` links against (below).
CABI   := $(or $(CARGO_TARGET_DIR),target)/release/libsins_cabi.so
RUST_SOURCES := Cargo.toml $(wildcard Cargo.lock) pyproject.toml $(shell find rust -name '*.rs' -o -name Cargo.toml)
# pytest runs on PYTEST_WORKERS pytest-xdist workers (CI has two cores; most tests use one), whole
# modules to a worker so that a module's shared set-up is made once; the modules marked `alone`
# (tests/conftest.py: pools, a cluster or a browser sized for the machine) run after, by themselves.
PYTEST_WORKERS ?= 2
export CARGO_TERM_COLOR ?= never

.PHONY: demo cabi test test-rust test-rust-built test-python lint fmt bench clean golden docs wheel firmware-toolchain

demo: $(BUILT) $(CABI)
	$(BIN)/sins-fw demo

# The C ABI library `sins-fw build-firmware` links a user's firmware against, where the source tree's
# sins_fw.firmware_build.cabi_dirs looks for it (`cargo test` leaves its copy in target/release/deps/
# only): built by `make demo` and `make test` too. `cargo build -p sins-cabi` resolves the features of
# the core's dependencies for sins-cabi alone (no num-traits `std` or `i128`, no libc `std`, a smaller
# syn for the derive macros), so after `cargo test --workspace --release` it compiled the core, and
# everything above serde, a second time (117.5 s of CPU, benchmarks/test-suite.md). With
# CABI_WITH_TESTS=1 (`make test`, and the tests' own `make cabi`: tests/conftest.py) the library is
# the one the Rust tests' build makes, copied out of deps/ (atomically: a running firmware may have it
# mapped): one core for both. `make demo` keeps the smaller build of the library alone.
CABI_WITH_TESTS ?=
ifneq ($(CABI_WITH_TESTS),)
$(CABI): $(RUST_SOURCES)
	+$(CARGO_TEST) --no-run
	cp -f $(dir $@)deps/$(notdir $@) $@.$$$$ && mv -f $@.$$$$ $@
else
$(CABI): $(RUST_SOURCES)
	+cargo build --release -p sins-cabi
	touch $@
endif

cabi: $(CABI)

# The two Rust builds `make test` needs, the Rust tests (`release`) and the extension (`dist`: fat LTO in
# one codegen unit, whose long single-threaded compile and link of the core leave a core idle), run at
# the same time, sharing make's two job slots with the cargo processes (`+`: cargo reads make's
# jobserver, so two compilers run at a time, not four); then the tests run. The C ABI library is the
# Rust tests' (CABI_WITH_TESTS=1, above), copied after their build, not beside it: in the parallel
# stage its cargo waited on the tests' cargo's lock for their whole build while holding one of the two
# slots, and the dependencies' install and the extension's build, the longest chain, started only
# after it (a fresh clone, load 12: `pip install` began 2 497 s in).
CARGO_TEST := cargo test --workspace --release

test:
	$(MAKE) --no-print-directory -j2 test-rust-built $(BUILT)
	$(MAKE) --no-print-directory $(CABI) test-rust test-python CABI_WITH_TESTS=1

test-rust-built:
	+$(CARGO_TEST) --no-run

test-rust:
	$(CARGO_TEST)

# Python keeps each module's compiled bytecode for the next start, unless told not to write it
# (PYTHONDONTWRITEBYTECODE, which some machines set to keep source trees free of __pycache__): then each
# of the ~290 `sins-fw` processes the tests start compiled the package's modules again, about 0.25 s
# of CPU a start (`sins-fw --version`: 0.65 s of CPU, 0.40 s from the cache; benchmarks/test_time.md).
# The tests' Python writes its cache under the build folder instead (PYTHONPYCACHEPREFIX): the source
# tree stays as it was.
PYTEST := env -u PYTHONDONTWRITEBYTECODE PYTHONPYCACHEPREFIX=$(abspath $(or $(CARGO_TARGET_DIR),target))/pycache $(BIN)/pytest

test-python: $(BUILT) firmware-toolchain
	$(PYTEST) -q -m "not alone" -n $(PYTEST_WORKERS) --dist loadscope
	$(PYTEST) -q -m alone

# `sins-fw build-firmware` compiles with Debian's clang 14 and an LLVM pass built against llvm-14-dev
# (sins_fw.firmware_build, docs/c-drivers.md): installed here when missing (as root, with apt-get).
firmware-toolchain:
	@command -v clang-14 >/dev/null && command -v llvm-config-14 >/dev/null \
		&& test -f "$$(llvm-config-14 --includedir)/llvm/Passes/PassPlugin.h" \
		|| { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq clang-14 llvm-14-dev; }

lint: $(DEPS)
	cargo fmt --all -- --check
	cargo clippy --workspace --all-targets -- -D warnings
	$(BIN)/ruff check python tests benchmarks
	$(BIN)/ruff format --check python tests benchmarks

fmt: $(DEPS)
	cargo fmt --all
	$(BIN)/ruff format python tests benchmarks
	$(BIN)/ruff check --fix python tests benchmarks

bench: $(BUILT)
	$(BIN)/sins-fw bench --out benchmarks/results.md

# The abi3 wheel (one file for every CPython >= 3.11 on this platform; the bundled profiles and
# traces inside, and the C ABI library with its header for `sins-fw build-firmware`, copied into
# python/sins_fw/cabi for the build and removed after it): `pip install dist/sins_fw-*.whl` needs no
# Rust toolchain.
WHEEL_DIR ?= dist
CABI_STAGE := python/sins_fw/cabi
wheel: $(DEPS) $(CABI)
	mkdir -p $(CABI_STAGE)
	cp $(CABI) rust/cabi/include/sins_fw.h $(CABI_STAGE)/
	$(BIN)/maturin build --profile dist --quiet --out $(WHEEL_DIR); rc=$$?; rm -rf $(CABI_STAGE); exit $$rc

# Regenerate tests/golden/hashes.toml (f64 output hashes on the bundled traces), printing old → new.
golden: $(BUILT)
	$(BIN)/python -m sins_fw.golden tests/golden/hashes.toml

# Regenerate docs/events.md from the core's event and output-column tables.
docs: $(BUILT)
	$(BIN)/python -m sins_fw.docs

clean:
	cargo clean
	rm -rf $(VENV) python/sins_fw/_core*.so .pytest_cache .ruff_cache .hypothesis

$(VENV)/bin/python:
	$(PYTHON) -m venv $(VENV)

$(DEPS): requirements.txt | $(VENV)/bin/python
	$(BIN)/pip install --disable-pip-version-check -q -r requirements.txt
	touch $@

$(BUILT): $(DEPS) $(RUST_SOURCES)
	+VIRTUAL_ENV=$(abspath $(VENV)) $(BIN)/maturin develop --profile dist --quiet
	touch $@
