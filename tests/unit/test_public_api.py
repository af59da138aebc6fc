"""The public API, as anyio's tests/test_all_attributes.py checks its own, over every
module of the package (ADR 0056).

- every module of ``otonav`` imports, and every name in its ``__all__`` resolves;
- the public packages (no ``_`` in their path) and each one's ``__all__`` are pinned
  below: adding or removing a public name fails here until this list says so;
- what a public package exports is otonav's own (a class or function defined in otonav,
  a module of otonav), not a re-export of a dependency;
- no two public packages export one name for different things (the one pair that does,
  argued in ADR 0056, is listed).
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import types
from itertools import combinations

import pytest

import otonav

pytestmark = pytest.mark.unit

MODULES = sorted(
    info.name
    for info in pkgutil.walk_packages(otonav.__path__, "otonav.")
    if info.name != "otonav.__main__"  # importing it runs the CLI
)
PUBLIC_PACKAGES = sorted(
    info.name
    for info in pkgutil.walk_packages(otonav.__path__, "otonav.")
    if info.ispkg and not any(part.startswith("_") for part in info.name.split("."))
)

PINNED: dict[str, tuple[str, ...]] = {
    "otonav.actors": (
        "AvoidingNavigator",
        "BaseController",
        "BaseLimits",
        "Bridge",
        "CommandWatch",
        "EXTERNAL_COMMAND_WAIT",
        "Navigator",
        "SafetyLayer",
        "topics",
    ),
    "otonav.bench": (),
    "otonav.cli": (
        "build_parser",
        "load_scenario",
        "load_stack",
        "main",
    ),
    "otonav.control": (
        "DiffDriveGeometry",
        "OdometryEstimate",
        "Pose2D",
        "estimate_odometry",
        "integrate_odometry",
        "limit_twist",
        "twist_to_wheels",
        "wheels_to_twist",
    ),
    "otonav.embed": (
        "DEFAULT_MAX_RUNS",
        "HOST_QOS",
        "LiveStack",
        "LiveSubscription",
        "check_run",
        "default_limiter",
        "open_live_stack",
        "run_scenario_async",
    ),
    "otonav.hal": (
        "BoxObstacle",
        "FakeHardware",
        "GroundTruth",
        "HardwareHealth",
        "HealthLevel",
        "ImuSample",
        "PolygonObstacle",
        "RangeScan",
        "RobotGeometry",
        "RobotHardwareInterface",
        "RoundObstacle",
        "WheelSetpoint",
        "WheelState",
    ),
    "otonav.hal.can": (
        "BusError",
        "BusPeer",
        "CanBusInterface",
        "CanEndpoint",
        "DriveMonitor",
        "MonitorLimits",
        "Phase",
        "RawFrame",
        "WheelAxis",
        "open_endpoint",
    ),
    "otonav.hal.mujoco": (
        "MujocoInterface",
        "NoDisplayError",
        "SceneError",
        "ViewerHandle",
        "compile_scene",
        "scene_names",
        "scene_path",
    ),
    "otonav.hal.sim": (
        "AxisModel",
        "AxisParams",
        "BusFaults",
        "DriveEmulator",
        "DriveMount",
    ),
    "otonav.msgs": (
        "Clock",
        "DiagnosticArray",
        "DiagnosticStatus",
        "Frame",
        "HardwareStatus",
        "Header",
        "Imu",
        "JointState",
        "KeyValue",
        "LaserScan",
        "Log",
        "MapMetaData",
        "Message",
        "NavDiagnostics",
        "NavState",
        "OccupancyGrid",
        "Odometry",
        "Parameter",
        "ParameterEvent",
        "ParameterValue",
        "Point",
        "Pose",
        "PoseStamped",
        "PoseWithCovariance",
        "Quaternion",
        "SafetyState",
        "ScenarioVerdict",
        "TFMessage",
        "Time",
        "Transform",
        "TransformStamped",
        "Twist",
        "TwistStamped",
        "TwistWithCovariance",
        "Vector3",
        "WheelCommand",
    ),
    "otonav.nav": (
        "DwaParams",
        "DwaResult",
        "GoToGoalParams",
        "GoalCommand",
        "GuardParams",
        "NavOutput",
        "Navigation",
        "NavigationParams",
        "SafetyParams",
        "SafetyResult",
        "centre_clearance",
        "dwa_step",
        "go_to_goal",
        "goal_problem",
        "guard_blocked",
        "safe_command",
        "wrap_angle",
    ),
    "otonav.record": (
        "DamagedRecordingError",
        "RecordingError",
        "RecordingSummary",
        "RecordingWriter",
        "RotatingRecordingWriter",
        "TopicSummary",
        "read_messages",
        "salvage",
        "summarize_recording",
        "write_bag_directory",
    ),
    "otonav.replay": (
        "Divergence",
        "ReplayInputError",
        "ReplayResult",
        "TopicComparison",
        "replay_recording",
    ),
    "otonav.engine": (
        "HOST_QOS",
        "Extras",
        "ExtrasError",
        "LiveStack",
        "LiveSubscription",
        "open_extras",
        "open_live_stack",
    ),
    "otonav.foxglove": (
        "FoxgloveServer",
        "LiveView",
        "LiveViewError",
    ),
    "otonav.record.cdr": (
        "ENCAPSULATION",
        "decode",
        "encode",
        "flat_values",
    ),
    "otonav.ros2": (
        "Ros2Bridge",
        "Ros2Error",
        "Ros2Statistics",
    ),
    "otonav.runtime": (
        "Actor",
        "ActorCrashedError",
        "ActorDefinitionError",
        "ActorStatus",
        "Bus",
        "Clock",
        "DEFAULT_QOS",
        "DeadlockError",
        "Durability",
        "Endpoint",
        "EventKind",
        "Graph",
        "Input",
        "JumpSource",
        "LATCHED_QOS",
        "LoopHeldError",
        "MAX_STEP_BATCH",
        "MailboxStatistics",
        "OtonavRuntimeError",
        "Output",
        "Publisher",
        "QoS",
        "QoSIncompatibleError",
        "Rate",
        "RealTime",
        "RealTimeClock",
        "Reliability",
        "RestartPolicy",
        "SENSOR_DATA_QOS",
        "SimTimeoutError",
        "Subscription",
        "System",
        "SystemEvent",
        "TimeMode",
        "TimeSource",
        "TimeSourceError",
        "TopicTypeError",
        "Virtual",
        "VirtualClock",
        "VirtualTimeLoop",
        "WallClockCeilingError",
        "WiringError",
        "current_clock",
        "next_message",
        "run_blocking",
        "until",
        "virtual_loop_factory",
    ),
    "otonav.scenario": (
        "BUILTIN",
        "BoxSpec",
        "Coordinate",
        "DENSE",
        "GeneratedWorld",
        "GoalSpec",
        "Judge",
        "SPARSE",
        "ScenarioConfig",
        "StartSpec",
        "Verdict",
        "WorldParams",
        "check_goal",
        "generate_world",
        "generate_worlds",
        "run_scenario",
        "walled_in",
    ),
    "otonav.stack": (
        "BaseConfig",
        "ConfigFileError",
        "DwaConfig",
        "GuardConfig",
        "NavConfig",
        "RatesConfig",
        "SafetyConfig",
        "StackConfig",
        "StackSession",
        "WorldConfig",
        "apply_overrides",
        "build_actors",
        "build_world",
        "describe_validation_error",
        "load_stack_file",
        "to_json",
    ),
    "otonav.sweep": (
        "GenerateSpec",
        "RunOutcome",
        "RunTask",
        "SweepSpec",
        "all_records",
        "execute",
        "load_sweep",
        "make_backend",
        "plan_runs",
        "prepare",
        "run_sweep",
        "summarize",
        "sweep_results",
        "write_report",
    ),
    "otonav.sweep.backends": (
        "Backend",
        "Emit",
        "error_outcome",
        "hang_deadline",
    ),
    "otonav.testing": (
        "ReplayCrashError",
        "replay",
        "running_stack",
    ),
}
"""Each public package's ``__all__``. Change it here on purpose, with the docs."""

SAME_NAME_DIFFERENT_THINGS: dict[str, frozenset[str]] = {
    # rosgraph_msgs/msg/Clock (the /clock message) and the actors' sim-time clock: ROS 2
    # has the same pair (rosgraph_msgs.msg.Clock, rclpy.clock.Clock); ADR 0056.
    "Clock": frozenset({"otonav.msgs", "otonav.runtime"}),
}


@pytest.mark.parametrize("name", MODULES)
def test_every_module_imports_and_its_all_resolves(name: str) -> None:
    module = importlib.import_module(name)
    exported = getattr(module, "__all__", ())
    missing = [n for n in exported if not hasattr(module, n)]
    assert not missing, f"{name}.__all__ names what it does not have: {missing}"
    twice = sorted({n for n in exported if list(exported).count(n) > 1})
    assert not twice, f"{name}.__all__ lists {twice} twice"


def test_the_public_packages_are_the_pinned_ones() -> None:
    assert set(PUBLIC_PACKAGES) == set(PINNED), (
        f"new public packages {sorted(set(PUBLIC_PACKAGES) - set(PINNED))}, "
        f"gone {sorted(set(PINNED) - set(PUBLIC_PACKAGES))}: pin them in PINNED"
    )


@pytest.mark.parametrize("name", PUBLIC_PACKAGES)
def test_a_public_package_exports_exactly_its_pinned_names(name: str) -> None:
    exported = importlib.import_module(name).__all__
    assert isinstance(exported, tuple)
    pinned = set(PINNED.get(name, ()))
    added, removed = sorted(set(exported) - pinned), sorted(pinned - set(exported))
    fix = "if meant, update PINNED (and the docs that list the API)"
    assert not added, f"{name}.__all__ gained {added}; {fix}"
    assert not removed, f"{name}.__all__ lost {removed}; {fix}"


@pytest.mark.parametrize("name", PUBLIC_PACKAGES)
def test_exports_are_otonavs_own(name: str) -> None:
    module = importlib.import_module(name)
    foreign = []
    for n in module.__all__:
        value = getattr(module, n)
        if isinstance(value, types.ModuleType):
            origin = value.__name__
        elif inspect.isclass(value) or inspect.isfunction(value):
            origin = value.__module__
        else:  # constants, type aliases: defined by an otonav module's assignment
            continue
        if not (origin == "otonav" or origin.startswith("otonav.")):
            foreign.append(f"{n} (from {origin})")
    assert not foreign, f"{name} re-exports what is not otonav's: {foreign}"


def test_no_two_packages_export_one_name_for_different_things() -> None:
    exports = {name: importlib.import_module(name) for name in PUBLIC_PACKAGES}
    clashes = []
    for (a, ma), (b, mb) in combinations(exports.items(), 2):
        for n in sorted(set(ma.__all__) & set(mb.__all__)):
            if getattr(ma, n) is getattr(mb, n):
                continue  # the same object re-exported
            if SAME_NAME_DIFFERENT_THINGS.get(n) == frozenset({a, b}):
                continue
            clashes.append(f"{a}.{n} vs {b}.{n}")
    assert not clashes, f"one name, different things: {clashes} (rename one side; ADR 0056)"


def _exported_elsewhere(name: str) -> set[int]:
    """Objects another public package (or ``otonav.errors``) exports."""
    others = [n for n in PUBLIC_PACKAGES if n != name] + ["otonav.errors"]
    return {
        id(getattr(module, n))
        for module in map(importlib.import_module, others)
        for n in module.__all__
    }


@pytest.mark.parametrize("name", PUBLIC_PACKAGES)
def test_every_public_import_is_exported(name: str) -> None:
    """A public name a package's ``__init__`` defines or imports is exported, unless it
    is another public package's export it only uses (an annotation, a base class)."""
    module = importlib.import_module(name)
    elsewhere = _exported_elsewhere(name)
    public = {
        n
        for n, value in vars(module).items()
        if not n.startswith("_")
        and getattr(value, "__module__", "").startswith("otonav.")
        and not isinstance(value, types.ModuleType)  # submodules are not API
        and id(value) not in elsewhere
    }
    assert public <= set(module.__all__), (
        f"{name} imports but does not export: {public - set(module.__all__)}"
    )
