# `make test` and `make demo` work from a fresh clone with only Python 3.11 and pip.
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: test demo lint bench docs clean

# Once: the environment, then the kernels compiled in a step of their own (pip would compile
# them inside its quiet build, without a word). The times: measured on two-core machines,
# some busy with other work (README)
$(STAMP): pyproject.toml
	@echo "== installing bistair and its dependencies into $(VENV) (2-5 minutes, once)"
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	BISTAIR_NO_PREBUILD=1 $(BIN)/python -m pip install --quiet -e '.[dev]'
	@echo "== compiling the decode kernels for this machine into src/bistair/_kernels (about 2 minutes on two cores, up to 16 on a busy machine; once)"
	$(BIN)/python -m bistair.app.kernels src/bistair/_kernels \
		|| echo "warning: some kernels were not compiled: they compile on their first call"
	touch $(STAMP)

# the tests on up to four processes (pytest-xdist), each test file in one of them
test: $(STAMP)
	@echo "== lint (ruff), then the tests on up to 4 processes (half an hour to an hour on two cores)"
	$(BIN)/ruff check src tests benchmarks examples docs/conf.py docs/spec_fields.py docs/site_settings.py
	$(BIN)/python -m pytest -q -n auto --maxprocesses 4 --dist loadfile

demo: $(STAMP)
	@echo "== bistair demo: the paper's simulation at 1280 x 1024, every method (2-3 minutes)"
	$(BIN)/bistair demo --out demo-out

lint: $(STAMP)
	$(BIN)/ruff check src tests benchmarks examples docs/conf.py docs/spec_fields.py docs/site_settings.py

bench: $(STAMP)
	$(BIN)/python benchmarks/decode_speed.py

DOCS_STAMP := $(VENV)/.docs-installed

$(DOCS_STAMP): $(STAMP) pyproject.toml
	# (the kernels were compiled by the first install: not again)
	BISTAIR_NO_PREBUILD=1 $(BIN)/python -m pip install --quiet -e '.[dev,docs]'
	touch $(DOCS_STAMP)

# the documentation site into docs/_build/html (warnings are errors; the gallery runs)
docs: $(DOCS_STAMP)
	$(BIN)/python -m sphinx -W --keep-going -b html docs docs/_build/html

clean:
	rm -rf $(VENV) demo-out .pytest_cache build src/*.egg-info src/bistair/_kernels docs/_build docs/auto_examples \
		docs/api/*.rst docs/sg_execution_times.rst
	# numba's cache files are keyed by file and line: they pile up after code moves
	find src tests -path '*/__pycache__/*' \( -name '*.nbi' -o -name '*.nbc' \) -delete
