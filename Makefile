# graspdef: two commands on a fresh Debian/Ubuntu machine.
#   make demo   set up (.venv, package, dependencies) and run the main job
#   make test   set up, then run the test suite (tests marked `slow` are excluded), one worker per core
PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed

.PHONY: setup demo test test-slow clean system-packages

# Debian packages the Python dependencies need at run time (installed when run as root):
# gcc and python3-dev (numba's pycc compiles and links the ahead-of-time kernels), libgomp1 (numba's OpenMP), libusb-1.0-0 (open3d), chromium + driver (browser tests), and
# pymeshlab's shared libraries: libgl1, libopengl0, libfontconfig1, libgmp10 (it loads them at import)
DEB_PACKAGES := gcc python3-dev libgomp1 libusb-1.0-0 chromium chromium-driver libgl1 libopengl0 libfontconfig1 libgmp10

system-packages:
	@if [ "$$(id -u)" = "0" ] && command -v apt-get >/dev/null 2>&1; then \
	  missing=""; for p in $(DEB_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	  if [ -n "$$missing" ]; then echo "installing Debian packages:$$missing"; \
	    ( apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq $$missing ) > /tmp/graspdef-apt.log 2>&1 \
	    || { tail -n 40 /tmp/graspdef-apt.log; echo "apt-get failed: see /tmp/graspdef-apt.log"; exit 1; }; fi; \
	else echo "not root: skipping Debian packages ($(DEB_PACKAGES))"; fi

SETUP_LOG := $(VENV)/setup.log

# The set-up's output goes to .venv/setup.log; it is shown only if a step fails.
$(STAMP): pyproject.toml
	@$(MAKE) --no-print-directory system-packages
	@echo "setting up $(VENV) (log: $(SETUP_LOG)) ..."
	@$(PYTHON) -m venv $(VENV)
	@( $(PY) -m pip install --upgrade pip && \
	   $(PY) -m pip install -e ".[dev,bench,register,viewer,sim,sweep,objects]" ) > $(SETUP_LOG) 2>&1 \
	  || { tail -n 40 $(SETUP_LOG); echo "set-up failed: the whole log is $(SETUP_LOG)"; exit 1; }
	@touch $(STAMP)
	@echo "set-up done"

# the ahead-of-time build of the compiled kernels (graspdef.compiled): small solves then need no
# numba at run time (0.5 s of every process); rebuilt when a kernel source changes.  Then
# `graspdef bench kernels` checks it against numba's JIT build on small solves, which also leaves
# numba's on-disk cache warm (a first large solve would otherwise compile for ~40 s)
KERNEL_SOURCES := graspdef/compiled.py graspdef/shell/_kernels.py graspdef/shell/volume.py \
                  graspdef/solve/_kernels.py graspdef/contact/_kernels.py
AOT_STAMP := graspdef/_aot.json

$(AOT_STAMP): $(STAMP) $(KERNEL_SOURCES)
	@echo "compiling the kernels (ahead of time, then numba's cache) ..."
	@( $(PY) -m graspdef.compiled && $(VENV)/bin/graspdef -q bench kernels ) >> $(SETUP_LOG) 2>&1 \
	  || { rm -f $(AOT_STAMP); tail -n 20 $(SETUP_LOG); echo "the ahead-of-time kernels were not built or not checked (see $(SETUP_LOG)): graspdef runs on numba's JIT alone, 0.5 s slower to start (tests/test_compiled.py fails)"; }

setup: $(STAMP) $(AOT_STAMP)

demo: setup
	$(VENV)/bin/graspdef grasp tennis_ball --force 21.48 --out out/demo_tennis_ball
	$(VENV)/bin/graspdef report out/demo_tennis_ball
	@echo "look at it: out/demo_tennis_ball/report.html, or $(VENV)/bin/graspdef view out/demo_tennis_ball"

# pytest-xdist: one worker per core (at most 4), a test file's tests on one worker (their
# module-scoped fixtures are built once); every test must pass alone, in any file order
XDIST  := -n auto --maxprocesses 4 --dist loadfile

test: setup
	$(PY) -m pytest -q -m "not slow" $(XDIST)

test-slow: setup
	$(PY) -m pytest -q -m slow $(XDIST)

clean:
	rm -rf $(VENV) out .pytest_cache
