# The README's two commands: `make serve` and `make test`. Each does its own set-up.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
INSTALLED := $(VENV)/.installed

# The dashboard: npm installs from package-lock.json (npm ci) into node_modules, whose hidden lockfile
# (node_modules/.package-lock.json) marks when; Vite builds frontend/dist from the sources.
FRONTEND := frontend
NODE_MODULES := $(FRONTEND)/node_modules/.package-lock.json
DIST := $(FRONTEND)/dist/index.html
FRONTEND_SOURCES := $(shell find $(FRONTEND)/src -type f 2>/dev/null) \
	$(addprefix $(FRONTEND)/,index.html vite.config.ts tsconfig.json package.json)

.PHONY: serve test lint typecheck pytest vitest setup frontend api-types screenshots clean warm

setup: $(INSTALLED)

$(INSTALLED): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(INSTALLED)

# npm ci only when package.json or package-lock.json is newer than the last install.
$(NODE_MODULES): $(FRONTEND)/package.json $(FRONTEND)/package-lock.json
	cd $(FRONTEND) && npm ci --no-audit --no-fund
	touch $(NODE_MODULES)

$(DIST): $(NODE_MODULES) $(FRONTEND_SOURCES)
	cd $(FRONTEND) && npm run build

frontend: $(DIST)

# Regenerate the dashboard's API types (frontend/src/api/schema.d.ts) after changing the server's models.
api-types: $(INSTALLED) $(NODE_MODULES)
	cd $(FRONTEND) && PYTHON=$(CURDIR)/$(BIN)/python npm run gen:api

serve: $(INSTALLED) $(DIST)
	$(BIN)/horde serve

lint: $(INSTALLED) $(NODE_MODULES)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .
	cd $(FRONTEND) && npm run lint

typecheck: $(INSTALLED)
	$(BIN)/mypy

vitest: $(NODE_MODULES)
	cd $(FRONTEND) && npm test

# Needs the built dashboard for the browser tests; tests/test_api_types.py checks that the committed
# API types match the server's OpenAPI schema. Two processes run the tests that share no timing bound
# (pytest-xdist, a file to a process), and beside them a third runs schemathesis (its cases share one test id,
# which pytest-xdist cannot split, and no bound on time: its report is printed after theirs); then one process
# runs the tests marked `serial` (a bound on time, or the whole machine) alone. The engine's kernels are
# compiled first in both dtypes (`warm`, see horde/warm.py), so that no test process pays for a compile.
# The three side-by-side processes keep numpy's BLAS to one thread each: with every core already taken, its
# threads wait on each other (a test of 3000 products by a 1000 x 1000 matrix took 21 s in the suite; beside two
# busy processes, 5.0 s with BLAS's own threads, 1.8 s with one).
FUZZ := tests/server/test_schemathesis.py
ONE_BLAS := OPENBLAS_NUM_THREADS=1
pytest: $(INSTALLED) $(DIST)
	$(BIN)/python -m horde.warm
	mkdir -p .horde
	$(ONE_BLAS) $(BIN)/python -m pytest -p no:cacheprovider $(FUZZ) > .horde/schemathesis.log 2>&1 & fuzz=$$!; \
	$(ONE_BLAS) $(BIN)/python -m pytest -n 2 --dist loadfile --no-loadscope-reorder -m "not serial"; others=$$?; \
	wait $$fuzz; fuzzed=$$?; echo "--- $(FUZZ), run beside them:"; cat .horde/schemathesis.log; \
	test $$others -eq 0 && test $$fuzzed -eq 0
	$(BIN)/python -m pytest -m serial --ignore=$(FUZZ)

# The engine's kernels compiled into numba's cache for every dtype (minutes on a cold cache, a second after).
warm: $(INSTALLED)
	$(BIN)/python -m horde.warm

# The kernels compile in the background, one process a dtype, while the dashboard builds and the checks run
# (they compile nothing): 4 to 11 minutes of a core each on a fresh clone, side by side, with the machine.
test: $(INSTALLED)
	$(BIN)/python -m horde.warm float64 & float64=$$!; \
	$(BIN)/python -m horde.warm float32 & float32=$$!; \
	$(MAKE) lint typecheck vitest frontend; checks=$$?; \
	wait $$float64 && wait $$float32 && test $$checks -eq 0
	$(MAKE) pytest

# The browser tests write their screenshots to test-artifacts/screenshots; this refreshes the ones the
# README and docs/ show, on purpose (make test never touches docs/).
DOC_SHOTS := dashboard-live.png dashboard.png demon-editor.png protocol.png world-editor.png view.png \
	classroom-1024.png classroom-1440.png classroom-1920.png world-drawn.png protocol-group.png baird.png
screenshots: $(INSTALLED) $(DIST)
	$(BIN)/python -m pytest -q -m e2e tests/e2e
	cd test-artifacts/screenshots && cp $(DOC_SHOTS) ../../docs/

clean:
	rm -rf $(VENV) .pytest_cache .mypy_cache .ruff_cache $(FRONTEND)/node_modules $(FRONTEND)/dist
