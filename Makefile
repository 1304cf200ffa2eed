# brakesqueal — developer entry points. Every target creates .venv on first use.
PY ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: demo test test-slow test-all bench docs install clean lint

$(BIN)/python:
	$(PY) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

$(STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $(STAMP)

install: $(STAMP)

demo: $(STAMP)
	$(BIN)/python -m brakesqueal.demo

# the quick suite (tests marked slow excluded); CI runs both.  pytest-xdist runs the files on PYTEST_WORKERS
# processes (each file's tests on one of them, so module fixtures are built once); PYTEST_WORKERS=0 runs in one.
PYTEST_WORKERS ?= 2
XDIST = -n $(PYTEST_WORKERS) --dist loadfile
# one BLAS thread per worker: two workers each running OpenBLAS's two threads on two cores made a dense 200-wide
# eigenvalue scan (critical-speed of the 100-DOF brake) take over 10 minutes instead of 40 s
BLAS1 = OPENBLAS_NUM_THREADS=$${OPENBLAS_NUM_THREADS:-1}
test: $(STAMP)
	$(BLAS1) $(BIN)/python -m pytest -q -m "not slow" $(XDIST)

# the explorer's browser tests time a served page in chromium: they run alone, after the others
BROWSER_TESTS = tests/explorer/test_browser.py tests/explorer/test_browser_layout.py tests/explorer/test_browser_security.py
test-slow: $(STAMP)
	$(BLAS1) $(BIN)/python -m pytest -q -m slow $(XDIST) $(addprefix --ignore=,$(BROWSER_TESTS))
	$(BIN)/python -m pytest -q -m slow $(BROWSER_TESTS)

test-all: $(STAMP)
	$(BLAS1) $(BIN)/python -m pytest -q $(XDIST)

lint: $(STAMP)
	$(BIN)/ruff check src benchmarks
	$(BIN)/mypy

bench: $(STAMP)
	$(BIN)/python -m benchmarks

DOCS_STAMP := $(VENV)/.installed-docs
$(DOCS_STAMP): pyproject.toml | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test,docs]"
	touch $(DOCS_STAMP)

docs: $(DOCS_STAMP)
	MPLBACKEND=Agg $(BLAS1) $(BIN)/python -m sphinx -W --keep-going -E -q -b html docs docs/_build/html
	$(BIN)/python docs/_ext/check_offline.py docs/_build/html
	$(BIN)/python docs/_ext/check_layout.py docs/_build/html
	@echo "documentation: docs/_build/html/index.html"

clean:
	rm -rf $(VENV) build src/*.egg-info .pytest_cache

# The explorer measured in a real browser (needs chromium: apt-get install chromium); not part of `make bench`.
.PHONY: bench-explorer explorer-screenshots
bench-explorer: $(STAMP)
	$(BIN)/python benchmarks/browser_explorer.py

# Screenshots of the explorer's browser tests into the docs' gallery (docs/figures/explorer-*.png).
explorer-screenshots: $(STAMP)
	BRAKESQUEAL_EXPLORER_SCREENSHOTS=docs/figures $(BIN)/python -m pytest -q tests/explorer/test_browser.py
