"""What the simulation probes share (registers no kind): the world's controls, a recorder
of the robot's ground truth, random start poses, and the verdict's numbers.

A simulation probe grades behaviour, the way Duckietown and JdeRobot grade:
it puts the robot at a start pose the learner does not choose (drawn from the
exercise's ranges with the grading's seed, and redrawn until the room allows
it), lets the learner's node drive, and measures what the robot really did
from ``/ground_truth/odom`` and the world file's floor plan, never from the
learner's own outputs.

One trial:

1. wait for ``/sim_world`` (the exercise's setup starts it) and read its
   world, start pose and real-time factor;
2. set ``use_sim_time`` on the learner's node, as a simulator's launch file
   does, so its timers count simulated seconds (it stays set: see 5);
3. pause the physics, set the start pose (and anything the learner's node is
   told, such as a goal), reset the world, set the grading's real-time
   factor (faster than real time: judged in simulated seconds, it changes
   nothing but the wait) and go on;
4. record the ground truth until the probe has seen enough;
5. put back the world's parameters. ``use_sim_time`` stays true, as a launch
   file leaves it (the world runs on after a grading): turning it off makes
   rclpy destroy the node's /clock subscription from a worker thread of the
   learner's executor, and rclpy 7.1.6's MultiThreadedExecutor, building its
   next wait set meanwhile, dies of that (``InvalidHandle: cannot use
   Destroyable because destruction was requested``, a few trials in a
   thousand; issue 38). Turning it on only creates entities, which is safe.
"""

from __future__ import annotations

import bisect
import math
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rcl_interfaces.msg import Parameter
from rcl_interfaces.srv import GetParameters, SetParameters
from std_srvs.srv import Empty

from app.exercises.probes.base import ProbeContext, draw
from app.lessons.checks._sim_topics import SIM_NODE, Pose, pose_of, world_map, wrap
from app.lessons.checks._world_map import WorldMap
from app.ros import params
from app.ros.calls import call_again_until_answered, wait_for_server
from app.ros.errors import Ros2Error
from app.ros.monitor import MessageInfo

if TYPE_CHECKING:
    from collections.abc import Mapping

    from rclpy.client import Client

READY_WAIT_SEC = 30.0  # a world starting on a busy machine: MuJoCo, the model, the camera
SERVICE_SEC = 10.0  # a world stepping on a busy machine can be slow to answer
TOUCH = 0.01  # m: the body this close to an obstacle touches it
# Slower than this (m/s, rad/s) over a few seconds, the robot stands still: a slow final
# approach (a few cm/s) still counts as moving.
STILL_SPEED, STILL_TURN = 0.005, 0.01
ASKED_SPEED, ASKED_TURN = 0.01, 0.02  # a /cmd_vel below both asks for no real motion
DEFAULT_RTF = 2.0
QUIET_WAIT = 3.0  # s at most for the samples sent before a pause to arrive
WORLD_PARAMS = ("x", "y", "yaw", "real_time_factor", "camera_rate")
# A command that asked for motion, then nothing for this long (simulated s; a controller
# sends one every 0.05 s): the wheels drove on an old command, as on a starved computer.
SILENT_DRIVE = 0.3


@dataclass(frozen=True)
class Sample:
    """One ground-truth pose: simulation time, position, heading."""

    t: float
    x: float
    y: float
    yaw: float


@dataclass(frozen=True)
class Command:
    """One /cmd_vel message: when its publisher sent it (s, wall clock) and whether it
    asked for motion."""

    sent: float
    moving: bool


@dataclass(frozen=True)
class SilentDrive:
    """The wheels ran on an old command: from ``at`` (s into the trial) for ``seconds`` of
    simulation, nothing new came."""

    at: float
    seconds: float


class Recorder:
    """Every /ground_truth/odom and /odom message as planar poses, and every /cmd_vel
    (the executor thread writes).

    /cmd_vel tells the probe when to stop watching (a robot that stands still while
    its node still asks it to move was held up, e.g. by a busy machine, and is watched on)
    and whether the node that drives was silent while the robot drove; the verdict comes
    from the ground truth.
    """

    def __init__(self, ctx: ProbeContext) -> None:
        self._node = ctx.call.node
        self._lock = threading.Lock()
        self.truth: list[Sample] = []
        self.odom: list[Pose] = []
        # When the world sent each ground-truth sample (s, its wall clock) and the sample's
        # simulation time: a command's send time in simulated seconds.
        self.clock: list[tuple[float, float]] = []
        self.commands: list[Command] = []
        # Simulation time (the newest ground-truth stamp) when /cmd_vel last asked for motion.
        self.moving_asked = -math.inf
        sub = self._node.create_subscription
        self._subs = [
            sub(Odometry, "/ground_truth/odom", self._on_truth, 50),  # type: ignore[arg-type]
            sub(Odometry, "/odom", self._on_odom, 50),
            sub(Twist, "/cmd_vel", self._on_cmd_vel, 50),  # type: ignore[arg-type]
        ]

    # Two parameters: rclpy passes the message info (a dict) as the second.
    def _on_cmd_vel(self, msg: Twist, info: MessageInfo) -> None:
        moving = abs(msg.linear.x) > ASKED_SPEED or abs(msg.angular.z) > ASKED_TURN
        with self._lock:
            self.commands.append(Command(_sent(info), moving))
            if moving:
                self.moving_asked = self.truth[-1].t if self.truth else 0.0

    def asked_to_move(self, within: float = 1.0) -> bool:
        """Whether /cmd_vel asked for motion in the last ``within`` s of simulation time, the
        clock the trial's ``hold`` counts in (a wall-clock second is 2 simulated s at 2x, and
        fewer on a world slowed by a busy machine)."""
        with self._lock:
            newest = self.truth[-1].t if self.truth else 0.0
            return 0.0 <= newest - self.moving_asked < within  # < 0: time reset since

    def _on_truth(self, msg: Odometry, info: MessageInfo) -> None:
        pose = pose_of(msg)
        with self._lock:
            self.truth.append(Sample(pose.t, pose.x, pose.y, pose.yaw))
            self.clock.append((_sent(info), pose.t))

    def _on_odom(self, msg: Odometry) -> None:
        with self._lock:
            self.odom.append(pose_of(msg))

    def newest(self) -> Sample | None:
        with self._lock:
            return self.truth[-1] if self.truth else None

    def count(self) -> int:
        with self._lock:
            return len(self.truth)

    def since(self, t0: float) -> list[Sample]:
        with self._lock:
            return [s for s in self.truth if s.t > t0]

    def odom_since(self, t0: float) -> list[Pose]:
        with self._lock:
            return [p for p in self.odom if p.t > t0]

    def sim_time_at(self, wall: float) -> float | None:
        """The simulation time when the world's wall clock read ``wall``: that of the last
        ground-truth sample it sent by then (None: none yet). Not the newest sample heard,
        which lags behind when this process is short of the processor."""
        with self._lock:
            return sim_time_at(self.clock, wall)

    def silent_drives(self, t0: float) -> list[SilentDrive]:
        """Since simulation time ``t0``: each time the wheels drove on an old command."""
        with self._lock:
            return silent_drives(self.commands, self.clock, t0)

    def close(self) -> None:
        for sub in self._subs:
            self._node.destroy_subscription(sub)


def _sent(info: MessageInfo) -> float:
    """When the publisher sent a message (s, wall clock); now if the middleware said not."""
    stamp = info.get("source_timestamp") or 0
    return stamp * 1e-9 if stamp > 0 else time.time()


def sim_time_at(clock: Sequence[tuple[float, float]], wall: float) -> float | None:
    """The simulation time of the last ground-truth sample the world sent by wall-clock
    time ``wall`` (None: none by then); ``clock``: (wall send time, simulation time) pairs
    in the order sent."""
    at = bisect.bisect_right(clock, (wall, math.inf)) - 1
    return clock[at][1] if at >= 0 else None


def silent_drives(
    commands: Sequence[Command], clock: Sequence[tuple[float, float]], t0: float
) -> list[SilentDrive]:
    """Each command that asked for motion and was followed by nothing for more than
    SILENT_DRIVE simulated seconds (the world's cmd_vel timeout stops the wheels later),
    after simulation time ``t0``. ``clock``: (wall send time, simulation time) pairs of
    the ground truth, in order, which put each command's send time on the simulation's
    clock (the world may run slower than the wall clock on a busy machine)."""
    times = [sim_time_at(clock, command.sent) for command in commands]
    out = []
    for before, start, end in zip(commands, times, times[1:], strict=False):
        if start is None or end is None:
            continue  # sent before the world's first sample: not the trial's
        if before.moving and start > t0 and end - start > SILENT_DRIVE:
            out.append(SilentDrive(start - t0, end - start))
    return out


def _parameter(name: str, value: object) -> Parameter:
    return Parameter(name=name, value=params.parameter_value(value))


class Services:
    """Service clients kept for a whole probe: a fresh client per call would wait for
    discovery each time, seconds on a busy machine."""

    def __init__(self, ctx: ProbeContext) -> None:
        self._ctx = ctx
        self._clients: dict[tuple[str, type], Client] = {}

    def call(self, name: str, srv_type: type, request: object) -> object:
        key = (name, srv_type)
        if key not in self._clients:
            self._clients[key] = self._ctx.call.node.create_client(srv_type, name)
        client = self._clients[key]
        what = f"service '{name}'"
        wait_for_server(self._ctx.call, client.service_is_ready, SERVICE_SEC, what)
        # Every request made here may arrive twice (parameters, pause, reset, is_active).
        return call_again_until_answered(self._ctx.call, client, request, SERVICE_SEC, what)

    def get(self, node: str, names: list[str]) -> dict[str, object]:
        request = GetParameters.Request(names=names)
        response: GetParameters.Response = self.call(
            f"{node}/get_parameters", GetParameters, request
        )
        values = [params.python_value(v) for v in response.values]
        return dict(zip(names, values, strict=True))

    def set(self, node: str, values: Mapping[str, object]) -> None:
        """Set several parameters in one request; a refusal raises with the node's reason."""
        request = SetParameters.Request(parameters=[_parameter(k, v) for k, v in values.items()])
        response: SetParameters.Response = self.call(
            f"{node}/set_parameters", SetParameters, request
        )
        for name, result in zip(values, response.results, strict=False):
            if not result.successful:
                raise Ros2Error(f"{node} refused {name}={values[name]!r}: {result.reason}")

    def empty(self, name: str) -> None:
        self.call(name, Empty, Empty.Request())

    def close(self) -> None:
        for client in self._clients.values():
            self._ctx.call.node.destroy_client(client)
        self._clients.clear()


@dataclass
class World:
    """The running simulation as the probe found it: its floor plan, what to put back,
    and the clients to drive it."""

    name: str
    plan: WorldMap
    saved: dict[str, object]
    rtf: float
    services: Services


def _wait_for_world(ctx: ProbeContext, recorder: Recorder) -> None:
    deadline = time.monotonic() + READY_WAIT_SEC
    names: set[str] = set()
    while recorder.newest() is None or f"{SIM_NODE}/set_parameters" not in names:
        if time.monotonic() > deadline:
            raise Ros2Error(
                f"no simulation: {SIM_NODE} did not publish /ground_truth/odom within "
                f"{READY_WAIT_SEC:g} s (the exercise starts it: is another world running?)"
            )
        ctx.call.sleep(0.2)
        names = {name for name, _ in ctx.call.node.get_service_names_and_types()}


@contextmanager
def simulation(
    ctx: ProbeContext, rtf: float, learner_sim_time: bool = True
) -> Iterator[tuple[World, Recorder]]:
    """The world, ready for trials; afterwards its parameters as before, the learner's node
    left on simulation time (never turned off: that kills a multithreaded learner).

    ``learner_sim_time`` False leaves the learner's clock alone: a node that talks to
    servers on the wall clock (the Nav2 stack as the catalog starts it) stays on it."""
    recorder = Recorder(ctx)
    services = Services(ctx)
    world: World | None = None
    try:
        _wait_for_world(ctx, recorder)
        current = services.get(SIM_NODE, ["world", *WORLD_PARAMS])
        name = str(current.pop("world"))
        world = World(name, world_map(name), current, rtf, services)
        try:
            if learner_sim_time:
                services.set(ctx.learner_node, {"use_sim_time": True})  # already true: no change
        except Ros2Error as exc:
            raise Ros2Error(
                f"could not set use_sim_time on {ctx.learner_node}: {exc} (is its executor busy?)"
            ) from None
        yield world, recorder
    finally:
        try:
            if world is not None:
                services.set(SIM_NODE, world.saved)
        except Ros2Error:
            pass  # the world is gone: nothing to put back
        services.close()
        recorder.close()


def release(
    ctx: ProbeContext,
    world: World,
    recorder: Recorder,
    start: tuple[float, float, float],
    learner: Mapping[str, object] | None = None,
) -> float:
    """Put the robot at ``start`` (paused), tell the learner's node ``learner``, and go.

    Returns the simulation time the trial starts at: later samples are the trial's.
    """
    services = world.services
    services.empty("/pause_physics")
    x, y, yaw = start
    # No camera during a trial: nothing graded looks at it, and rendering at a faster
    # real-time factor would take the cores the learner's node needs.
    trial = {"x": x, "y": y, "yaw": yaw, "real_time_factor": world.rtf, "camera_rate": 0.0}
    services.set(SIM_NODE, trial)
    services.empty("/reset_world")  # the robot at the start, odometry at zero, time goes on
    if learner:
        services.set(ctx.learner_node, learner)
    # Paused, the world publishes nothing: once nothing has come for a while, what was on
    # its way before the pause has arrived, and every later sample is the trial's.
    count = recorder.count()
    for _ in range(int(QUIET_WAIT / 0.1)):
        ctx.call.sleep(0.1)
        if recorder.count() == count:
            break
        count = recorder.count()
    newest = recorder.newest()
    assert newest is not None
    services.empty("/unpause_physics")
    return newest.t


def draw_pose(
    ctx: ProbeContext,
    ranges: Mapping[str, object],
    fits: Callable[[float, float, float], bool],
    tries: int = 20000,
) -> tuple[float, float, float]:
    """A pose drawn from ``{x, y, yaw}`` ranges, drawn again until ``fits`` accepts it."""
    for _ in range(tries):
        x, y, yaw = (float(draw(ctx.rng, ranges[k])) for k in ("x", "y", "yaw"))
        if fits(x, y, yaw):
            return x, y, yaw
    raise ValueError(f"no pose drawn from {ranges} fits the world in {tries} tries")


def run_until(
    ctx: ProbeContext,
    recorder: Recorder,
    t0: float,
    start: tuple[float, float, float],
    sim_seconds: float,
    rtf: float,
    done: Callable[[list[Sample]], bool],
) -> tuple[list[Sample], str]:
    """Samples from ``t0`` (the first at ``start``) until ``done`` says so or ``sim_seconds``
    of simulation pass.

    The wall-clock bound is generous (a busy machine runs the world slower than asked);
    past it, the second value says how far the simulation got.
    """
    wall_limit = sim_seconds / max(rtf, 0.25) * 4.0 + 20.0
    deadline = time.monotonic() + wall_limit
    while True:
        samples = recorder.since(t0)
        # A sample from before the reset that arrived late is not the trial's.
        while samples and math.hypot(samples[0].x - start[0], samples[0].y - start[1]) > 0.03:
            samples.pop(0)
        if samples and (samples[-1].t - t0 >= sim_seconds or done(samples)):
            return samples, ""
        if time.monotonic() > deadline:
            got = samples[-1].t - t0 if samples else 0.0
            return samples, (
                f"the simulation ran only {got:.1f} of {sim_seconds:g} s in {wall_limit:.0f} s "
                "of wall-clock time (the machine is too busy to grade now)"
            )
        ctx.call.sleep(0.1)


def elapsed(samples: list[Sample], t0: float) -> float:
    return samples[-1].t - t0 if samples else 0.0


def at_rest(samples: list[Sample], seconds: float) -> bool:
    """The robot stood still (position and heading) over the last ``seconds``."""
    if not samples or samples[-1].t - samples[0].t < seconds:
        return False
    end = samples[-1]
    window = [s for s in samples if s.t >= end.t - seconds]
    first = window[0]
    moved = math.hypot(end.x - first.x, end.y - first.y)
    turned = abs(wrap(end.yaw - first.yaw))
    return moved <= STILL_SPEED * seconds and turned <= STILL_TURN * seconds


def path_length(samples: list[Sample]) -> float:
    return sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(samples, samples[1:], strict=False))


@dataclass(frozen=True)
class Touch:
    """Where the body came closest to the room: distance, what, when (s into the trial)."""

    distance: float
    name: str
    at: float


def closest_touch(plan: WorldMap, samples: list[Sample], t0: float) -> Touch:
    best = Touch(math.inf, "", 0.0)
    for s in samples:
        near = plan.clearance(s.x, s.y, s.yaw)
        if near.distance < best.distance:
            best = Touch(near.distance, near.name, s.t - t0)
    return best


def touch_text(touch: Touch) -> str:
    if touch.distance <= TOUCH:
        return f"the robot touched {touch.name} at {touch.at:.1f} s"
    return f"the body never came closer than {touch.distance:.2f} m to anything ({touch.name})"


def pose_text(pose: tuple[float, float, float]) -> str:
    return f"(x={pose[0]:.2f}, y={pose[1]:.2f}, yaw={pose[2]:.2f})"
