# Two entry points: `make demo` (set up, run the main job) and `make test` (set up, run the suite).
VENV   ?= .venv
PYTHON ?= python3
PY     := $(VENV)/bin/python
PIP    := $(PY) -m pip --disable-pip-version-check -q

.PHONY: demo test test-slow lint bench clean docs schemas tables

$(VENV)/.base: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(PIP) install -e .
	# this machine sets PYTHONDONTWRITEBYTECODE, so without this every command compiles the
	# package anew (about 0.3 s of CPU per command, docs/benchmarks.md "Start-up")
	$(PY) -m compileall -q chargedesign
	touch $@

$(VENV)/.test: pyproject.toml $(VENV)/.base
	$(PIP) install -e '.[test]'
	touch $@

demo: $(VENV)/.base
	$(VENV)/bin/chargedesign design --out out

# the suite on every core (pytest-xdist): worksteal gives each worker a contiguous half and
# moves work when one runs dry, so a file's module fixtures are mostly built once; one BLAS
# thread per worker (the workers fill the cores); the tests marked slow: `make test-slow`
test: $(VENV)/.test
	OPENBLAS_NUM_THREADS=1 $(PY) -m pytest -q -n auto --dist worksteal

# the soak runs and benchmarks (marked slow); their properties are checked by `make test` too
test-slow: $(VENV)/.test
	$(PY) -m pytest -q -m slow

lint: $(VENV)/.test
	$(VENV)/bin/ruff check chargedesign tests examples tools
	$(VENV)/bin/mypy

bench: $(VENV)/.base
	$(VENV)/bin/chargedesign bench

# the documentation site (mkdocs-material + mkdocstrings); warnings are errors
docs: $(VENV)/.test
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site
	$(PY) tools/check_site.py site

# regenerate the shipped JSON Schemas from chargedesign/schemas.py
schemas: $(VENV)/.base
	$(PY) -c "from chargedesign.schemas import NAMES, schema_text; \
	[open(f'chargedesign/data/schemas/{n}.schema.json', 'w').write(schema_text(n)) for n in NAMES]"

# regenerate the shipped tables of the conditions engine (harmonics, V, mu), the
# realisability map's terms and the model's evaluators (lambdify's sources) with sympy
tables: $(VENV)/.base
	$(PY) -c "from chargedesign.moment_conditions.tables import write_tables; write_tables()"
	$(PY) -c "from chargedesign.model.evaluators import write_evaluators; write_evaluators()"
	$(PY) -c "from chargedesign.physical.map_data import MAP_FILE; \
	from chargedesign.physical.realism import derived_map_terms; MAP_FILE.write(derived_map_terms())"

CLEAN := $(VENV) out site .pytest_cache .mypy_cache .ruff_cache .hypothesis

clean:
	@echo "make clean: removes $(CLEAN) (those present are named below)"
	@for d in $(CLEAN); do if [ -e "$$d" ]; then echo "  removing $$d"; rm -rf "$$d"; fi; done
