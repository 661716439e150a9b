# Every target creates .venv on first use and installs wavesph with its test extras, so a
# fresh machine needs only python3 (with venv) and make.
VENV   ?= .venv
PYTHON ?= python3
STAMP  := $(VENV)/.installed-stamp

.PHONY: demo test test-slow clean

$(STAMP): pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -e '.[test]'
	touch $@

demo: $(STAMP)          ## the main job: a coupled demo on embedded defaults
	$(VENV)/bin/wavesph demo

test: $(STAMP)          ## the default test run (slow physics runs excluded)
	$(VENV)/bin/python -m pytest

test-slow: $(STAMP)     ## the long physics runs only
	$(VENV)/bin/python -m pytest -m slow

clean:
	rm -rf $(VENV) build *.egg-info runs
