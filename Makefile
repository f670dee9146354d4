# Two entry points: `make demo` (set up, run the main job) and `make test` (set up, run the suite).
VENV   ?= .venv
PYTHON ?= python3
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check -q

.PHONY: demo test lint bench clean

$(VENV)/.base: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PIP) install -e .
	touch $@

$(VENV)/.test: pyproject.toml $(VENV)/.base
	$(PIP) install -e '.[test]'
	touch $@

demo: $(VENV)/.base
	$(VENV)/bin/chargedesign design --out out

test: $(VENV)/.test
	$(PY) -m pytest -q

lint: $(VENV)/.test
	$(VENV)/bin/ruff check chargedesign tests examples
	$(VENV)/bin/mypy

bench: $(VENV)/.base
	$(VENV)/bin/chargedesign bench

clean:
	rm -rf $(VENV) out .pytest_cache .mypy_cache .ruff_cache
