# Everything a fresh machine needs: `make demo` and `make test` create .venv and install on first use.
PYTHON ?= python3
VENV := .venv
BIN := $(VENV)/bin
STAMP := $(VENV)/.installed-stamp

VENV2 := .venv-ros2

.PHONY: demo test coverage test-slow test-long bench lint format clean ros-env ros-bench realsense-env ros2-env ros2-bench

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

demo: $(STAMP)  ## locate the fruit of the shipped RGB-D frame, write out/demo/
	$(BIN)/symfruit demo --output out/demo

# Debian's ROS 1 packages for `symfruit ros` and its real-master test: apt-get installs them when they are
# missing and apt is usable (root or password-less sudo); the venv then sees exactly those packages through
# a .pth file. Elsewhere it prints why it skipped and the ROS tests skip; under CI a skip is an error.
ros-env: $(STAMP)  ## make Debian's ROS 1 (rospy, rosmaster, message packages) usable from the venv
	$(BIN)/python -m symfruit.ros.debian --install $(if $(filter true 1,$(CI) $(SYMFRUIT_REQUIRE_ROS)),--require,)

# ROS 2 for `symfruit ros2` and its tests: the ROS 2 wheels (extra `ros2`) in a venv of their own, $(VENV2), and
# vision_msgs built there from the shipped upstream definitions (cmake and g++ from apt when missing). Up to date
# it only says so. Elsewhere it prints why it skipped and the ROS 2 tests skip; under CI a skip is an error.
ros2-env: $(STAMP)  ## make $(VENV2): rclpy, Fast DDS and vision_msgs for `symfruit ros2`
	$(BIN)/python -m symfruit.ros.ros2env --venv $(VENV2) --project . $(if $(filter true 1,$(CI) $(SYMFRUIT_REQUIRE_ROS)),--require,)

# pyrealsense2 (a dev dependency where a wheel exists) loads the system's libusb-1.0: installed here when it
# is missing and apt is usable; elsewhere the SDK comparison tests skip (symfruit reads the bags without it).
realsense-env: $(STAMP)  ## make pyrealsense2 importable (libusb-1.0 from apt) for the SDK comparison tests
	@if $(BIN)/python -c "import pyrealsense2" 2>/dev/null; then echo "realsense-env: ok"; else \
	  if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null; then \
	    apt-get install -y --no-install-recommends libusb-1.0-0 >/dev/null 2>&1 || \
	    { apt-get update >/dev/null 2>&1 && apt-get install -y --no-install-recommends libusb-1.0-0 >/dev/null 2>&1; }; fi; \
	  if $(BIN)/python -c "import pyrealsense2" 2>/dev/null; then echo "realsense-env: ok (libusb-1.0 installed)"; \
	  else echo "realsense-env: skipped: pyrealsense2 does not import here; the SDK comparison tests skip"; fi; fi

# pytest keeps its assertion-rewritten test modules in __pycache__ even where PYTHONDONTWRITEBYTECODE is set:
# rewriting the ~90 test modules again costs each xdist worker about 3.5 s of CPU on every run.
test: $(STAMP) ros-env ros2-env realsense-env  ## lint, type check and the test suite (slow evaluation runs excluded)
	$(BIN)/ruff check src tests examples docs
	$(BIN)/ruff format --check src tests examples docs
	$(BIN)/mypy
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -m "not slow" -n auto --dist loadgroup --durations=15

# Coverage is its own target, not part of `make test`: measuring it (every line, and every CLI and ROS subprocess,
# through [tool.coverage.run]) costs about two fifths more CPU than the suite itself.
coverage: $(STAMP) ros-env ros2-env realsense-env  ## the quick suite under coverage: the missing lines, and a failure below 95 %
	PYTHONDONTWRITEBYTECODE= $(BIN)/python -m pytest -m "not slow" -n auto --dist loadgroup --cov=symfruit --cov-report=term-missing:skip-covered \
	  --cov-fail-under=95

test-slow: $(STAMP)  ## the whole suite, slow evaluation runs included
	$(BIN)/python -m pytest

test-long: $(STAMP)  ## property and fuzz tests with fresh random cases and many more of them
	SYMFRUIT_HYPOTHESIS=long $(BIN)/python -m pytest -m "not slow"

bench: $(STAMP)  ## the project's benchmark
	$(BIN)/symfruit bench

ros-bench: ros-env  ## latency of the ROS node on the example frame (real master, node subprocess)
	$(BIN)/python -m symfruit.ros.bench

ros2-bench: ros2-env  ## latency of the ROS 2 node on the example frame (node subprocess, frames from rclpy)
	$(VENV2)/bin/python -m symfruit.ros.bench2

lint: $(STAMP)
	$(BIN)/ruff check src tests examples docs

format: $(STAMP)
	$(BIN)/ruff format src tests examples docs
	$(BIN)/ruff check --fix src tests examples docs

clean:
	rm -rf $(VENV) $(VENV2) out .pytest_cache .ruff_cache
