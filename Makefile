# `make run` and `make test` each do all the set-up themselves on a fresh machine.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed

.PHONY: run test test-slow test-lowest test-newest lint clean native test-native docs

# Reinstall only when pyproject.toml or setup.py changed since the last install. The sumo extra (libsumo,
# eclipse-sumo, about 230 MB) is installed too where it can be; where it cannot, the SUMO engine's tests skip and say
# why.
$(STAMP): pyproject.toml setup.py
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	$(BIN)/python -m pip install --quiet -e '.[sumo]' > $(VENV)/sumo-install.log 2>&1 \
		|| echo "notice: the sumo extra (libsumo, eclipse-sumo) could not be installed, the SUMO engine tests will skip (see $(VENV)/sumo-install.log)"
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/liansuo tui

# The suite runs on every core (pytest-xdist): many tests wait on servers, consoles and subprocesses. -rs prints why
# each skipped test was skipped.
test: $(STAMP)
	$(BIN)/python -m pytest -n auto --dist worksteal -rs
	$(BIN)/ruff check .
	$(BIN)/mypy

# The documentation site with the API reference from the docstrings (mkdocs.yml), into site/.
docs: $(STAMP)
	$(BIN)/mkdocs build --strict

# The long equivalence and exploration checks (marker slow): a quiet cycle against the full one on every station and
# script, every mutant caught, explore's reductions against its full search. CI runs them after make test.
test-slow: $(STAMP)
	$(BIN)/python -m pytest -n auto --dist worksteal -m slow -rs

# The wheel in a fresh environment outside the checkout (tests/test_wheel.py), its dependencies installed by uv at the
# lowest versions pyproject.toml allows (lowest-direct: each at its floor, on Python 3.11, which uv fetches if it is
# not here) or at the newest: the floors stay true (README.md, "Dependencies").
test-lowest: $(STAMP)
	$(BIN)/python -m pip install --quiet uv
	LIANSUO_WHEEL_RESOLUTION=lowest-direct $(BIN)/python -m pytest -p no:cacheprovider -m wheel tests/test_wheel.py

test-newest: $(STAMP)
	$(BIN)/python -m pip install --quiet uv
	LIANSUO_WHEEL_RESOLUTION=highest $(BIN)/python -m pytest -p no:cacheprovider -m wheel tests/test_wheel.py

# The hot path compiled with mypyc (setup.py, docs/native.md): about 1.5-2x faster, the same results. Needs a C
# compiler and Python's headers; `make clean` goes back to pure Python. `make test` runs the suite on the pure
# modules either way (tests/conftest.py) and tests/test_native.py compares the two (pytest -m native).
native: $(STAMP)
	$(BIN)/python -m pip install --quiet --upgrade 'setuptools>=77' 'mypy>=1.10'
	LIANSUO_NATIVE=1 $(BIN)/python -m pip install --quiet --no-build-isolation --no-deps -e .

# The native wheel built from a copy of the checkout, each command's answer compared with the Python sources'.
test-native: $(STAMP)
	$(BIN)/python -m pip install --quiet --upgrade 'setuptools>=77' 'mypy>=1.10'
	$(BIN)/python -m pytest -m native tests/test_native.py

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/mypy

clean:
	rm -rf $(VENV) build src/*.egg-info .pytest_cache .mypy_cache .ruff_cache
	find . -path ./.venv -prune -o -name '*.so' -print -exec rm -f {} +
