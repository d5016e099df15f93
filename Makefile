# The two commands a newcomer needs (each sets up .venv first when needed):
#   make demo   run the main job: the mission demo in the simulated house (about two minutes)
#   make test   run the test suite
# Other targets: make pipeline-demo (the perception-to-knowledge pipeline on a real RGB-D frame),
# make setup, make clean.
SHELL := /bin/bash
VENV := .venv
DEMO_DATA := reports/demo
PIPELINE_DURATION ?= 20
PIPELINE_DATA := reports/pipeline-demo

.PHONY: setup demo pipeline-demo test clean

setup:
	@scripts/setup.sh

# The simulated house: explore it, anchor everything, then find the red mug the world moved while
# the robot was away; the report (summary.md, scorecard.json, map.png, frames/, knowledge.pddl,
# account.log) lands in $(DEMO_DATA)/report, and its summary is printed at the end.
demo: setup
	@$(VENV)/bin/sailor demo --output $(DEMO_DATA)

# The whole perception graph on a real RGB-D frame for PIPELINE_DURATION seconds, from an empty
# world each time; then what the robot now knows: the knowledge base it left behind.
pipeline-demo: setup
	@rm -rf $(PIPELINE_DATA) && mkdir -p $(PIPELINE_DATA)
	@export ROS_AUTOMATIC_DISCOVERY_RANGE=$${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST} \
		SAILOR_DATA=$(CURDIR)/$(PIPELINE_DATA) && \
		$(VENV)/bin/sailor launch sailor --duration $(PIPELINE_DURATION) && \
		echo && echo "What the robot knows now (sailor knowledge show --store sqlite://$(PIPELINE_DATA)/knowledge.db):" && \
		$(VENV)/bin/sailor knowledge show --store sqlite://$(CURDIR)/$(PIPELINE_DATA)/knowledge.db

# Two pytest workers by default (the CI machine has two cores; most of the suite waits on DDS and
# simulated missions in real time); a module's or class's tests stay on one worker, so a stack
# started once per module is started once. TEST_WORKERS=0 runs everything in one process.
TEST_WORKERS ?= 2

# With SAILOR_UPSTREAM=path/to/sources (the layout of ../shared/upstream: KANT, YASMIN, MERLIN2...),
# the tests against the real MERLIN2 stack run too (scripts/upstream_env.sh builds it once), and the
# behaviour suite runs a second time, on the real YASMIN instead of the project's own subset.
test: setup
	@upstream_env="$$(scripts/upstream_env.sh)" && . "$$upstream_env" && \
		SAILOR_DARKNET_DATA=$$(scripts/fetch_test_data.sh) $(VENV)/bin/python -m pytest -n $(TEST_WORKERS) --dist loadscope --durations=15 && \
		if [ -n "$${SAILOR_UPSTREAM:-}" ]; then \
			echo "The behaviour suite again, on the real YASMIN from $$SAILOR_UPSTREAM:"; \
			SAILOR_STATE_MACHINES=real $(VENV)/bin/python -m pytest test/unit/behaviors; \
		fi

clean:
	rm -rf $(VENV) build *.egg-info .pytest_cache
