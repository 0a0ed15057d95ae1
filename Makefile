# ROS 2 Classroom. Two commands do everything on a fresh machine:
#   make run    set up, then start the dashboard on http://127.0.0.1:8080
#   make test   set up, then run the whole test suite (headless browser included)

# The ROS 2 Jazzy wheels exist for CPython 3.10-3.12: take the first that works.
PYTHON ?= $(shell for p in python3.11 python3.12 python3.10 python3; do \
	$$p -c 'import sys; sys.exit(not ((3, 10) <= sys.version_info[:2] <= (3, 12)))' \
	2>/dev/null && { echo $$p; break; }; done)
VENV := .venv
VPY := $(VENV)/bin/python
STAMP := $(VENV)/.classroom-setup
# Every folder of interfaces/ with a package.xml is a rosidl package we build.
INTERFACES := $(patsubst %/package.xml,%,$(wildcard interfaces/*/package.xml))
INTERFACE_FILES := $(foreach p,$(INTERFACES),$(wildcard $(p)/msg/* $(p)/srv/* $(p)/action/*) \
	$(p)/CMakeLists.txt $(p)/package.xml $(p)/pyproject.toml)
EDITOR := app/exercises/editor
EDITOR_STAMP := $(EDITOR)/node_modules/.classroom-setup
HUB_PROXY := app/hub/proxy
HUB_PROXY_STAMP := $(HUB_PROXY)/node_modules/.classroom-setup
AXE := tests/browser/axe
AXE_STAMP := $(AXE)/node_modules/.classroom-setup
FOXGLOVE_CLIENT := tests/foxglove/wsclient
FOXGLOVE_CLIENT_STAMP := $(FOXGLOVE_CLIENT)/node_modules/.classroom-setup
ARGS ?=

.PHONY: setup run test check browser sandbox lint docs bench screenshots clean render bytecode

setup: $(STAMP) $(EDITOR_STAMP) $(HUB_PROXY_STAMP) $(AXE_STAMP) $(FOXGLOVE_CLIENT_STAMP) render bytecode

# Our modules' bytecode, written ahead (issue 43): where PYTHONDONTWRITEBYTECODE is set
# (as on this project's machines) Python never caches it, so every dashboard, node and
# learner process compiled some 300 modules again: 0.2 s of a dashboard's start-up.
# compileall writes whatever that variable says and skips what is up to date.
bytecode: $(STAMP)
	@$(VPY) -m compileall -q -j 0 app nodes ros_python/src >/dev/null

# The exercise code editor (Ace), from the npm registry at the version the lock file pins.
$(EDITOR_STAMP): $(EDITOR)/package.json $(EDITOR)/package-lock.json
	@command -v npm >/dev/null 2>&1 || { \
		echo "== installing Debian's npm for the exercise editor"; \
		SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
		$$SUDO apt-get update -q && $$SUDO apt-get install -y -q npm; }
	@echo "== installing the exercise editor (ace-builds from npm)"
	npm ci --prefix $(EDITOR) --no-audit --no-fund --loglevel=error
	@touch $(EDITOR_STAMP)

# JupyterHub's configurable-http-proxy (deploy/, tests/hub), from npm like the editor.
$(HUB_PROXY_STAMP): $(HUB_PROXY)/package.json $(HUB_PROXY)/package-lock.json $(EDITOR_STAMP)
	@echo "== installing JupyterHub's configurable-http-proxy (npm)"
	npm ci --prefix $(HUB_PROXY) --no-audit --no-fund --loglevel=error
	@touch $(HUB_PROXY_STAMP)

# axe-core, the accessibility checker the browser tests inject into the page (npm, like the editor).
$(AXE_STAMP): $(AXE)/package.json $(AXE)/package-lock.json $(EDITOR_STAMP)
	@echo "== installing axe-core for the accessibility tests (npm)"
	npm ci --prefix $(AXE) --no-audit --no-fund --loglevel=error
	@touch $(AXE_STAMP)

# @foxglove/ws-protocol, the client Lichtblick is built on, for tests/foxglove (npm, like the editor).
$(FOXGLOVE_CLIENT_STAMP): $(FOXGLOVE_CLIENT)/package.json $(FOXGLOVE_CLIENT)/package-lock.json $(EDITOR_STAMP)
	@echo "== installing @foxglove/ws-protocol for the Foxglove bridge's tests (npm)"
	npm ci --prefix $(FOXGLOVE_CLIENT) --no-audit --no-fund --loglevel=error
	@touch $(FOXGLOVE_CLIENT_STAMP)

$(STAMP): pyproject.toml ros_python/pyproject.toml $(INTERFACE_FILES)
	@test -n "$(PYTHON)" || { echo "error: ROS 2 Jazzy wheels need CPython 3.10, 3.11 or 3.12; none found" >&2; exit 1; }
	@echo "== creating $(VENV) with $(PYTHON)"
	$(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install --quiet --upgrade pip
	@echo "== installing the dashboard and the ROS 2 Jazzy wheels"
	$(VPY) -m pip install --quiet -e '.[test,interfaces-build]'
	@echo "== installing ros_python (our Python versions of tf2_ros, launch, ...)"
	$(VPY) -m pip install --quiet -e ./ros_python
	@for pkg in $(INTERFACES); do \
		echo "== building the $$(basename $$pkg) interface package with rosidl"; \
		$(VPY) -m pip install --quiet --no-build-isolation --force-reinstall --no-deps ./$$pkg || exit 1; \
		kind=$$(basename $$(ls -d $$pkg/srv $$pkg/msg $$pkg/action 2>/dev/null | head -1)); \
		$(VPY) -c "import importlib, sys; importlib.import_module(sys.argv[1]); print(sys.argv[1], 'OK')" \
			$$(basename $$pkg).$$kind || exit 1; \
	done
	@touch $(STAMP)

# Through a keeper (app/keep_serving.py): a dashboard ended by its ROS guard starts again.
run: setup
	$(VPY) -m app.keep_serving serve $(ARGS)

# Debian's Chromium (never a downloaded browser). The browser tests run its headless
# shell: the same build without the full browser's windows, Playwright's default for
# headless (each new page of the full one also loaded the omnibox's own web page in a
# renderer of its own). Benchmarks and screenshots keep the full browser a learner has.
HEADLESS_SHELL := /usr/lib/chromium/chromium-headless-shell
browser:
	@command -v chromium >/dev/null 2>&1 && test -x $(HEADLESS_SHELL) || { \
		echo "== installing Debian's chromium and its headless shell"; \
		SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
		$$SUDO apt-get update -q && $$SUDO apt-get install -y -q chromium chromium-headless-shell; }

# Headless rendering for the MuJoCo camera (nodes/sim_world.py): Mesa's EGL, and
# OSMesa as the fallback; a GPU's own EGL driver is used where one is installed.
render:
	@ldconfig -p | grep -q 'libEGL_mesa.so.0' && ldconfig -p | grep -q 'libOSMesa.so' || { \
		echo "== installing Mesa's EGL and OSMesa for headless camera rendering"; \
		SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
		$$SUDO apt-get update -q && $$SUDO apt-get install -y -q libegl1 libegl-mesa0 libgl1-mesa-dri libosmesa6; }

# Contained learner code runs under uids of its own (app/containment/contain.py).
# When Python lives under a private /root, those uids must be able to pass
# through it: o+x lets them reach the interpreter, not list or read /root.
sandbox: setup
	@real=$$($(VPY) -c 'import os, sys; print(os.path.realpath(sys.base_prefix))'); \
	case "$$real" in /root/*) \
		if [ "$$(id -u)" = 0 ] && [ $$(( 0$$(stat -c %a /root) & 1 )) -eq 0 ]; then \
			echo "== chmod o+x /root: contained learner code must reach $$real"; \
			chmod o+x /root; fi;; esac

# Every test runs inside a private network namespace with only loopback
# (tests/run.py sets it up): DDS traffic cannot leave the machine. Three
# pytest-xdist workers, each in a namespace of its own; ARGS="--workers 1" for one.
test: setup browser sandbox lint
	$(VPY) tests/run.py $(ARGS)

# Fast feedback for whoever changes the code: lint, types, contracts and the docs, the
# unit tests, and one smoke test of each front end (panels and stage in a browser, the
# ros2 verbs, a lesson walked on real nodes, an exercise graded). `make test` stays the
# whole suite; this is the few minutes' subset to run before it.
SMOKE := tests/unit \
	tests/browser/test_first_smoke.py::test_start_watch_and_stop_talker_and_listener \
	tests/integration/test_ros2cli_graph.py::test_node_topic_service_and_action_verbs \
	"tests/integration/test_lessons_walk.py::test_every_step_of_the_lesson_passes_on_real_nodes[05_topics]" \
	"tests/exercises/test_grading.py::test_grading[counter_publisher-reference]" \
	"tests/exercises/test_grading.py::test_grading[counter_publisher-never_increments]"
check: setup browser sandbox lint
	$(VPY) tests/run.py --workers 2 $(SMOKE) $(ARGS)

# Style, the layer contracts of pyproject.toml (import-linter) and types (mypy).
# PYTHONPATH: check this checkout's app/, whatever the editable install points at.
lint: setup
	$(VENV)/bin/ruff check app nodes ros_python tests bench lessons docs tools
	$(VENV)/bin/ruff format --check app nodes ros_python tests bench lessons docs tools
	PYTHONPATH=$(CURDIR) $(VENV)/bin/lint-imports
	PYTHONPATH=$(CURDIR) $(VPY) -m mypy
	@$(MAKE) --no-print-directory docs

# The documentation site (MkDocs with Material) into .site/, strictly: a broken link, a
# missing page or a page left out of the navigation fails. Its architecture picture is
# drawn from the code (tools/architecture.py), so it cannot go stale.
docs: setup
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --quiet

bench: setup browser
	$(VPY) tests/run.py --bench $(ARGS)

# The README's pictures, from the real product in headless Chromium (docs/screenshots.py).
screenshots: setup browser
	$(VPY) tests/run.py --script docs/screenshots.py

clean:
	rm -rf $(VENV) .site $(EDITOR)/node_modules $(HUB_PROXY)/node_modules $(AXE)/node_modules $(addsuffix /build,$(INTERFACES)) .mypy_cache .import_linter_cache
