# The same commands for people and CI (.ci/run calls `make test`).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test lint bench clean

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

clean:
	rm -rf $(VENV) .mypy_cache .ruff_cache .pytest_cache .hypothesis
