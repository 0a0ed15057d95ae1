"""SimEngine: one MuJoCo world with the diffbot and the arm, driven as their drivers would be.

No ROS here: nodes/sim_world.py wraps it, tests use it alone. Not thread-safe:
one thread owns it (the node's physics thread, under its lock).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numpy as np

from nodes.common.arm_kinematics import JOINT_LIMITS, JOINT_NAMES
from nodes.common.sim.assets import load_world
from nodes.common.sim.diff_drive import wheel_speeds
from nodes.common.sim.lidar import Lidar
from nodes.common.sim.trajectory import Plan, check_trajectory

WHEEL_JOINTS = ("left_wheel_joint", "right_wheel_joint")
WHEEL_MOTORS = ("left_wheel_motor", "right_wheel_motor")
ARM_SERVOS = tuple(f"{name}_servo" for name in JOINT_NAMES)
FINGER_JOINTS = ("left_finger_joint", "right_finger_joint")
FINGER_SERVOS = ("left_finger_servo", "right_finger_servo")
ARM_HOME = (0.0, math.radians(60.0), math.radians(-110.0), math.radians(-40.0))
GRIPPER_MAX_OPENING = 0.09  # m between the fingers, fully open
SETTLE_TIME = 0.3  # s of physics after a reset, before time starts
ARM_LIMITS = dict(zip(JOINT_NAMES, JOINT_LIMITS, strict=True))


@dataclass(frozen=True)
class Pose2D:
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


class SimEngine:
    """A world: steps it, takes commands, and reads the robots' sensors."""

    def __init__(
        self,
        world: str = "room",
        *,
        start: Pose2D = Pose2D(),
        drive_radius: float = 0.033,
        drive_separation: float = 0.16,
        seed: int | None = None,
    ) -> None:
        self.model = load_world(world)  # WorldError with the reason when it does not load
        self.data = mujoco.MjData(self.model)
        self.drive_radius = drive_radius
        self.drive_separation = drive_separation
        names = {self.model.joint(i).name for i in range(self.model.njnt)}
        self.has_mobile = all(j in names for j in WHEEL_JOINTS) and "base_free" in names
        self.has_arm = all(j in names for j in JOINT_NAMES + FINGER_JOINTS)
        self.joint_names: tuple[str, ...] = (WHEEL_JOINTS if self.has_mobile else ()) + (
            JOINT_NAMES + FINGER_JOINTS if self.has_arm else ()
        )
        self._qadr = np.array([self.model.joint(n).qposadr[0] for n in self.joint_names], int)
        self._vadr = np.array([self.model.joint(n).dofadr[0] for n in self.joint_names], int)
        self.lidar: Lidar | None = None
        if self.has_mobile:
            self.base_id = self.model.body("base_link").id
            self._base_q = self.model.joint("base_free").qposadr[0]
            self._motors = [self.model.actuator(a).id for a in WHEEL_MOTORS]
            self.lidar = Lidar(self.model, "lidar", seed=seed)
        if self.has_arm:
            self._arm_servos = [self.model.actuator(a).id for a in ARM_SERVOS]
            self._finger_servos = [self.model.actuator(a).id for a in FINGER_SERVOS]
            self._arm_q = np.array([self.model.joint(n).qposadr[0] for n in JOINT_NAMES], int)
        self.start = start
        self.arm_plan: Plan | None = None
        self.arm_plan_start = 0.0
        self.reset()

    # --- time and stepping ---------------------------------------------------------
    @property
    def time(self) -> float:
        return float(self.data.time)

    @property
    def timestep(self) -> float:
        return float(self.model.opt.timestep)

    def step(self, count: int = 1) -> None:
        """Advance ``count`` physics steps, following the arm's trajectory as it goes."""
        for _ in range(count):
            if self.arm_plan is not None:
                self._follow_plan()
            mujoco.mj_step(self.model, self.data)

    def reset(self, start: Pose2D | None = None, keep_time: bool = False) -> None:
        """Everything back to its initial state; the mobile robot at ``start``."""
        if start is not None:
            self.start = start
        now = self.data.time
        mujoco.mj_resetData(self.model, self.data)
        if keep_time:
            self.data.time = now
        if self.has_mobile:
            q = self._base_q
            self.data.qpos[q : q + 3] = (self.start.x, self.start.y, 0.0)
            half = self.start.yaw / 2.0
            self.data.qpos[q + 3 : q + 7] = (math.cos(half), 0.0, 0.0, math.sin(half))
        if self.has_arm:
            self.data.qpos[self._arm_q] = ARM_HOME
            self.data.ctrl[self._arm_servos] = ARM_HOME
            self.set_gripper(GRIPPER_MAX_OPENING)
        self.arm_plan = None
        # Let everything settle on its contacts (a spawn), then start the clock where it was.
        settled_at = self.data.time
        mujoco.mj_step(self.model, self.data, int(SETTLE_TIME / self.timestep))
        self.data.time = settled_at
        mujoco.mj_forward(self.model, self.data)

    # --- mobile base -----------------------------------------------------------------
    def drive(self, linear: float, angular: float) -> None:
        """Set the wheel motors for a body velocity (m/s, rad/s), as the base driver does."""
        left, right = wheel_speeds(linear, angular, self.drive_radius, self.drive_separation)
        self.data.ctrl[self._motors] = (left, right)

    def encoders(self) -> tuple[float, float]:
        """Wheel angles (rad) from the encoder sensors."""
        left = self.data.sensor("left_wheel_encoder").data[0]
        right = self.data.sensor("right_wheel_encoder").data[0]
        return float(left), float(right)

    def imu(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(orientation x,y,z,w; angular velocity rad/s; linear acceleration m/s^2), IMU frame."""
        w, x, y, z = self.data.sensor("imu_orientation").data
        gyro = self.data.sensor("imu_gyro").data.copy()
        accel = self.data.sensor("imu_accel").data.copy()
        return np.array([x, y, z, w]), gyro, accel

    def base_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """Ground truth of base_link in the world: position, quaternion x,y,z,w."""
        pos = self.data.xpos[self.base_id].copy()
        w, x, y, z = self.data.xquat[self.base_id]
        return pos, np.array([x, y, z, w])

    def base_yaw(self) -> float:
        x, y, z, w = self.base_pose()[1]
        return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))

    def base_velocity(self) -> tuple[np.ndarray, np.ndarray]:
        """Ground-truth (linear, angular) velocity of base_link in its own frame.

        mjOBJ_XBODY: at the body's origin and axes (mjOBJ_BODY would use its inertial frame).
        """
        res = np.zeros(6)
        mujoco.mj_objectVelocity(
            self.model, self.data, mujoco.mjtObj.mjOBJ_XBODY, self.base_id, res, 1
        )
        return res[3:], res[:3]

    # --- arm -------------------------------------------------------------------------
    def arm_positions(self) -> np.ndarray:
        return self.data.qpos[self._arm_q].copy()

    def command_trajectory(self, names: list[str], points: list[tuple[list[float], float]]) -> Plan:
        """Start following a trajectory now; TrajectoryError says why one is refused."""
        current = self.data.ctrl[self._arm_servos].copy()  # continue from the last setpoint
        plan = check_trajectory(names, points, JOINT_NAMES, ARM_LIMITS, current)
        self.arm_plan = plan
        self.arm_plan_start = self.time
        return plan

    def _follow_plan(self) -> None:
        plan = self.arm_plan
        assert plan is not None
        elapsed = self.time - self.arm_plan_start
        targets = plan.sample(elapsed)
        for k, joint in enumerate(plan.joints):
            self.data.ctrl[self._arm_servos[joint]] = targets[k]
        if elapsed > plan.duration:
            self.arm_plan = None

    def set_gripper(self, opening: float) -> float:
        """Finger opening in metres (0 closed, 0.09 open), clamped; returns what was set."""
        opening = max(0.0, min(GRIPPER_MAX_OPENING, opening))
        self.data.ctrl[self._finger_servos] = (opening / 2.0, opening / 2.0)
        return opening

    def tool_position(self) -> np.ndarray:
        """World position of the fingertips' midpoint (the tool_tip site)."""
        return self.data.site("tool_tip").xpos.copy()

    # --- everything ------------------------------------------------------------------
    def joint_state(self) -> tuple[tuple[str, ...], np.ndarray, np.ndarray]:
        """Names, positions and velocities of every actuated joint (wheels, arm, fingers)."""
        return (
            self.joint_names,
            self.data.qpos[self._qadr].copy(),
            self.data.qvel[self._vadr].copy(),
        )

    def body_position(self, name: str) -> np.ndarray:
        return self.data.body(name).xpos.copy()

    def body_pose(self, name: str) -> tuple[np.ndarray, np.ndarray]:
        """World position and quaternion (x, y, z, w) of a body."""
        body = self.data.body(name)
        w, x, y, z = body.xquat
        return body.xpos.copy(), np.array([x, y, z, w])

    def snapshot(self) -> np.ndarray:
        """A copy of the state a camera needs to draw the world (qpos)."""
        return self.data.qpos.copy()
