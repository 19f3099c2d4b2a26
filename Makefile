# roverlab: the two set-up commands are `make run` and `make test` (see README.md).
VENV ?= .venv
PY := $(VENV)/bin/python
PYTHON ?= python3

.PHONY: run test install lint bench clean

$(VENV)/.installed: pyproject.toml scripts/install-system-deps.sh
	bash scripts/install-system-deps.sh
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e '.[test]'
	touch $@

install: $(VENV)/.installed

## Install, then run the main job on the built-in default world and robot.
run: install
	$(VENV)/bin/roverlab demo

# examples/ is left out: the user's seed scripts, kept as given (pyproject's extend-exclude)
lint: install
	$(VENV)/bin/ruff check src tests benchmarks
	$(VENV)/bin/ruff format --check src tests benchmarks
	$(VENV)/bin/mypy

## Install, then run the linters and the whole test suite.
# Two pytest workers (pytest-xdist), a test file per worker so module fixtures run once:
# many tests wait on the processes they start, and CI has 2 cores and 20 minutes.
test: lint
	$(VENV)/bin/pytest -q -n 2 --dist loadfile

bench: install
	$(PY) -m pip install -q -e '.[bench]'
	for b in benchmarks/*.py; do $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache
