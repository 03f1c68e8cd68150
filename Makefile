# `make test` and `make demo` work from a fresh clone with only Python 3.11 and pip.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: test demo lint bench clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

test: $(STAMP)
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/python -m pytest -q

demo: $(STAMP)
	$(BIN)/bistair demo --out demo-out

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks

bench: $(STAMP)
	$(BIN)/python benchmarks/decode_speed.py

clean:
	rm -rf $(VENV) demo-out .pytest_cache build src/*.egg-info
	# numba's cache files are keyed by file and line: they pile up after code moves
	find src tests -path '*/__pycache__/*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
