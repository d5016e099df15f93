# The two commands a newcomer needs (each sets up .venv first when needed):
#   make demo   run the main job
#   make test   run the test suite
# Other targets: make mission-demo (the simulated house: a mission, then a report), make setup,
# make clean.
SHELL := /bin/bash
VENV := .venv
DEMO_DURATION ?= 20
DEMO_DATA := reports/demo

MISSION_DEMO_DATA := reports/mission-demo

.PHONY: setup demo mission-demo test clean

setup:
	@scripts/setup.sh

# The whole graph on a real RGB-D frame for DEMO_DURATION seconds, from an empty world each time;
# then what the robot now knows: the knowledge base it left behind.
demo: setup
	@rm -rf $(DEMO_DATA) && mkdir -p $(DEMO_DATA)
	@export ROS_AUTOMATIC_DISCOVERY_RANGE=$${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST} \
		SAILOR_DATA=$(CURDIR)/$(DEMO_DATA) && \
		$(VENV)/bin/sailor launch sailor --duration $(DEMO_DURATION) && \
		echo && echo "What the robot knows now (sailor knowledge show --store sqlite://$(DEMO_DATA)/knowledge.db):" && \
		$(VENV)/bin/sailor knowledge show --store sqlite://$(CURDIR)/$(DEMO_DATA)/knowledge.db

# The simulated house: explore, the red mug moved behind the robot's back, find it; the report
# (summary.md, scorecard.json, map.png, frames/, knowledge.pddl) lands in $(MISSION_DEMO_DATA)/report.
mission-demo: setup
	@rm -rf $(MISSION_DEMO_DATA) && mkdir -p $(MISSION_DEMO_DATA)
	@export ROS_AUTOMATIC_DISCOVERY_RANGE=$${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST} \
		SAILOR_DATA=$(CURDIR)/$(MISSION_DEMO_DATA) && \
		$(VENV)/bin/sailor launch demo; \
		status=$$?; echo; cat $(MISSION_DEMO_DATA)/report/summary.md 2>/dev/null; exit $$status

test: setup
	@SAILOR_DARKNET_DATA=$$(scripts/fetch_test_data.sh) $(VENV)/bin/python -m pytest

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
