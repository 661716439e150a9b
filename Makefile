# Every target creates .venv on first use and installs wavesph with its test extras, so a
# fresh machine needs only python3 (with venv) and make.
VENV   ?= .venv
PYTHON ?= python3
STAMP  := $(VENV)/.installed-stamp

.PHONY: demo test test-unit test-slow clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -e '.[test]'
	touch $@

demo: $(STAMP)          ## the main job: a coupled demo on embedded defaults
	$(VENV)/bin/wavesph demo

# Tiers (markers in pyproject.toml, `unit` applied by tests/conftest.py): `make test-unit` runs
# no numba kernel (under 2 min); `make test` is everything but `slow`; `make test-slow` is `slow`
# only. Extra pytest options go in PYTEST_ADDOPTS (.ci/run records durations and junit.xml so).
test: $(STAMP)          ## the default test run (slow physics runs excluded)
	$(VENV)/bin/python -m pytest

test-unit: $(STAMP)     ## the quick tier: no numba kernel call, each test under 1 s
	$(VENV)/bin/python -m pytest -m 'unit and not slow'

test-slow: $(STAMP)     ## the long physics runs only
	$(VENV)/bin/python -m pytest -m slow

clean:
	rm -rf $(VENV) build *.egg-info runs
