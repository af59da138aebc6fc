# The same commands for people and CI (.ci/run calls `make test`).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test lint bench docs test-docs clean

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e '.[dev]'
	@touch $(STAMP)

## set up and run the default scenario (headless)
run: $(STAMP)
	$(PY) -m otonav

## set up and run the whole gate: static, unit, smoke, SIL (stops at the first red layer)
## (the GUI smoke test needs Debian's xvfb and x11-apps: installed here when missing)
test: $(STAMP)
	@sh scripts/ensure_xvfb.sh
	$(PY) scripts/gate.py

## layer 0 only
lint: $(STAMP)
	$(PY) scripts/gate.py static

## the stack against bare physics (README "Performance"); the other benchmarks/ scripts
## print the runtime, recording and acceptance figures
bench: $(STAMP)
	$(PY) -m otonav bench

## build the docs site into site/ (--strict: a broken link or reference fails; the
## reference pages and sample outputs are generated from the code and a real run)
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --site-dir site

## the built site renders in headless Chromium (Debian's chromium: installed here when
## missing); screenshots in out/docs-screenshots/. CI runs it after `make test`.
test-docs: docs
	@sh scripts/ensure_chromium.sh
	$(PY) scripts/docs_screenshots.py site out/docs-screenshots

clean:
	rm -rf $(VENV) site .mypy_cache .ruff_cache .pytest_cache .hypothesis
