# The two commands a newcomer needs (each sets up .venv first when needed):
#   make demo   run the main job
#   make test   run the test suite
# Other targets: make setup, make clean.
SHELL := /bin/bash
VENV := .venv
DEMO_DURATION ?= 10

.PHONY: setup demo test clean

setup:
	@scripts/setup.sh

demo: setup
	@ROS_AUTOMATIC_DISCOVERY_RANGE=$${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST} \
		$(VENV)/bin/sailor launch camera --duration $(DEMO_DURATION)

test: setup
	@SAILOR_DARKNET_DATA=$$(scripts/fetch_test_data.sh) $(VENV)/bin/python -m pytest

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
