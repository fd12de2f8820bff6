# graspdef: two commands on a fresh Debian/Ubuntu machine.
#   make demo   set up (.venv, package, dependencies) and run the main job
#   make test   set up, then run the test suite (tests marked `slow` are excluded)
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: setup demo test test-slow clean system-packages

# Debian packages the Python dependencies need at run time (installed when run as root).
DEB_PACKAGES := libgomp1 libusb-1.0-0 chromium chromium-driver

system-packages:
	@if [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then \
	  missing=""; for p in $(DEB_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	  if [ -n "$$missing" ]; then apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing; fi; \
	else echo "not root: skipping Debian packages ($(DEB_PACKAGES))"; fi

$(STAMP): pyproject.toml
	$(MAKE) system-packages
	$(PYTHON) -m venv $(VENV)
	$(PY) -m pip install -q --upgrade pip
	$(PY) -m pip install -q -e ".[dev,bench,register,viewer,sim,sweep]"
	touch $(STAMP)

setup: $(STAMP)

demo: setup
	$(VENV)/bin/graspdef grasp tennis_ball --force 21.48 --out out/demo_tennis_ball
	$(VENV)/bin/graspdef report out/demo_tennis_ball
	@echo "look at it: out/demo_tennis_ball/report.html, or $(VENV)/bin/graspdef view out/demo_tennis_ball"

test: setup
	$(PY) -m pytest -q -m "not slow"

test-slow: setup
	$(PY) -m pytest -q -m slow

clean:
	rm -rf $(VENV) out .pytest_cache
