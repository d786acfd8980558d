# Everything a fresh machine needs: `make demo` and `make test` create .venv and install on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

.PHONY: demo test test-slow test-long bench lint format clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)  ## locate the fruit of the shipped RGB-D frame, write out/demo/
	$(BIN)/symfruit demo --output out/demo

test: $(STAMP)  ## lint, type check and the test suite (slow evaluation runs excluded)
	$(BIN)/ruff check src tests examples
	$(BIN)/ruff format --check src tests examples
	$(BIN)/mypy
	$(BIN)/python -m pytest -m "not slow"

test-slow: $(STAMP)  ## the whole suite, slow evaluation runs included
	$(BIN)/python -m pytest

test-long: $(STAMP)  ## property and fuzz tests with fresh random cases and many more of them
	SYMFRUIT_HYPOTHESIS=long $(BIN)/python -m pytest -m "not slow"

bench: $(STAMP)  ## the project's benchmark
	$(BIN)/symfruit bench

lint: $(STAMP)
	$(BIN)/ruff check src tests examples

format: $(STAMP)
	$(BIN)/ruff format src tests examples
	$(BIN)/ruff check --fix src tests examples

clean:
	rm -rf $(VENV) out .pytest_cache .ruff_cache
