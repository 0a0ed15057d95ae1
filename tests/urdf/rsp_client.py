"""A program written for the real robot_state_publisher, run against ours from outside.

It imports only rclpy, message packages and numpy (run with ``python -I``
from a folder outside the project). It starts ``python -m
robot_state_publisher`` itself, as ``ros2 run`` would, feeds it
``/joint_states`` and prints one JSON report of what came back with its own,
independently computed transforms (quaternions composed from rpy and
axis-angle, never a rotation matrix).
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np
import rclpy
from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
from rcl_interfaces.srv import SetParameters
from rclpy.qos import DurabilityPolicy, QoSProfile
from sensor_msgs.msg import JointState
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

URDF = """<?xml version="1.0"?>
<robot name="outside">
  <link name="base_link"/>
  <link name="pan"/><link name="tilt"/><link name="slider"/><link name="camera"/>
  <link name="wheel"/><link name="follower"/>
  <joint name="pan_joint" type="revolute"><parent link="base_link"/><child link="pan"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.2 -0.3 0.4"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tilt_joint" type="revolute"><parent link="pan"/><child link="tilt"/>
    <origin xyz="0 0 0.5" rpy="0 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/></joint>
  <joint name="slide_joint" type="prismatic"><parent link="tilt"/><child link="slider"/>
    <origin xyz="0.2 0 0" rpy="1.0 0 0"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <joint name="wheel_joint" type="continuous"><parent link="base_link"/><child link="wheel"/>
    <origin xyz="-0.3 0 0.05" rpy="1.5707963 0 0"/><axis xyz="0 0 -1"/></joint>
  <joint name="follow_joint" type="revolute"><parent link="pan"/><child link="follower"/>
    <origin xyz="0 0.1 0"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="tilt_joint" multiplier="0.5" offset="0.1"/></joint>
  <joint name="camera_joint" type="fixed"><parent link="slider"/><child link="camera"/>
    <origin xyz="0.05 -0.02 0.1" rpy="-1.5707963 0 -1.5707963"/></joint>
</robot>
"""
JOINTS = {  # name: (parent, child, xyz, rpy, type, axis)
    "pan_joint": ("base_link", "pan", (0.1, 0.2, 0.3), (0.2, -0.3, 0.4), "revolute", (0, 0, 1)),
    "tilt_joint": ("pan", "tilt", (0, 0, 0.5), (0, 0, 0), "revolute", (0, 1, 0)),
    "slide_joint": ("tilt", "slider", (0.2, 0, 0), (1.0, 0, 0), "prismatic", (1, 0, 0)),
    "wheel_joint": (
        "base_link",
        "wheel",
        (-0.3, 0, 0.05),
        (1.5707963, 0, 0),
        "continuous",
        (0, 0, -1),
    ),
    "follow_joint": ("pan", "follower", (0, 0.1, 0), (0, 0, 0), "revolute", (1, 0, 0)),
    "camera_joint": (
        "slider",
        "camera",
        (0.05, -0.02, 0.1),
        (-1.5707963, 0, -1.5707963),
        "fixed",
        None,
    ),
}


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def axis_angle(axis, angle):
    s = math.sin(angle / 2) / math.sqrt(sum(v * v for v in axis))
    return (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2))


def rotate(q, v):
    x, y, z, w = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


def expected(name, position):
    """(translation, quaternion x y z w) of parent -> child, composed by hand."""
    _, _, xyz, rpy, kind, axis = JOINTS[name]
    q_origin = qmul(
        axis_angle((0, 0, 1), rpy[2]),
        qmul(axis_angle((0, 1, 0), rpy[1]), axis_angle((1, 0, 0), rpy[0])),
    )
    if kind in ("revolute", "continuous"):
        return list(xyz), list(qmul(q_origin, axis_angle(axis, position)))
    if kind == "prismatic":
        moved = rotate(q_origin, [a * position for a in axis])
        return [xyz[i] + moved[i] for i in range(3)], list(q_origin)
    return list(xyz), list(q_origin)


class Output:
    """A process's output lines, read in a thread."""

    def __init__(self, proc: subprocess.Popen) -> None:
        self.lines: list[str] = []
        self.thread = threading.Thread(target=self._read, args=(proc,), daemon=True)
        self.thread.start()

    def _read(self, proc) -> None:
        for line in proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def wait_for(self, text: str, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if any(text in line for line in self.lines):
                return True
            time.sleep(0.05)
        return False


def start(args, workdir):
    return subprocess.Popen(
        [sys.executable, "-m", "robot_state_publisher", *args],
        cwd=workdir,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1", "RCUTILS_LOGGING_BUFFERED_STREAM": "0"},
        start_new_session=True,
    )


def stop(proc) -> int:
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(timeout=5)
    return proc.returncode


def spin_until(node, predicate, timeout):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline and not predicate():
        rclpy.spin_once(node, timeout_sec=0.05)
    return bool(predicate())


def main() -> None:
    report: dict = {}
    workdir = tempfile.mkdtemp(prefix="rsp_outside_")
    urdf_path = os.path.join(workdir, "outside.urdf")
    with open(urdf_path, "w") as f:  # with an inertia on the root link, which KDL warns about
        f.write(
            URDF.replace(
                '<link name="base_link"/>',
                '<link name="base_link"><inertial><mass value="2"/><inertia ixx="1" ixy="0" '
                'ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>',
            )
        )
    params = os.path.join(workdir, "params.yaml")
    with open(params, "w") as f:
        f.write("robot_state_publisher:\n  ros__parameters:\n    publish_frequency: 20.0\n")
        f.write("    robot_description: " + json.dumps(URDF) + "\n")
    procs = []
    rclpy.init()
    node = rclpy.create_node("rsp_outside_client")
    try:
        main_proc = start(["--ros-args", "--params-file", params], workdir)
        procs.append(main_proc)
        out = Output(main_proc)
        report["initialized"] = out.wait_for("Robot initialized", 20)
        time.sleep(1.0)  # it has published: everything below joins late
        latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
        statics: dict = {}
        descriptions: list[str] = []
        dynamic: list = []
        node.create_subscription(
            TFMessage,
            "/tf_static",
            lambda m: statics.update({t.child_frame_id: t for t in m.transforms}),
            latched,
        )
        node.create_subscription(
            String, "/robot_description", lambda m: descriptions.append(m.data), latched
        )
        node.create_subscription(TFMessage, "/tf", lambda m: dynamic.extend(m.transforms), 100)
        spin_until(node, lambda: statics and descriptions, 15)
        report["description_matches"] = bool(descriptions) and descriptions[0] == URDF
        report["static"] = {
            child: {
                "parent": t.header.frame_id,
                "got": [
                    [
                        t.transform.translation.x,
                        t.transform.translation.y,
                        t.transform.translation.z,
                    ],
                    [
                        t.transform.rotation.x,
                        t.transform.rotation.y,
                        t.transform.rotation.z,
                        t.transform.rotation.w,
                    ],
                ],
            }
            for child, t in statics.items()
        }
        report["static_expected"] = {"camera": list(expected("camera_joint", 0.0))}
        publisher = node.create_publisher(JointState, "/joint_states", 10)
        rng = np.random.default_rng(int(time.time()))
        positions = {
            "pan_joint": float(rng.uniform(-3, 3)),
            "tilt_joint": float(rng.uniform(-2, 2)),
            "slide_joint": float(rng.uniform(0, 1)),
            "wheel_joint": float(rng.uniform(-10, 10)),
            "not_in_this_robot": 1.0,
        }
        report["positions"] = positions
        stamp_of = {}

        def publish_state():
            msg = JointState()
            msg.header.stamp = node.get_clock().now().to_msg()
            msg.name = list(positions)
            msg.position = list(positions.values())
            stamp_of["last"] = (msg.header.stamp.sec, msg.header.stamp.nanosec)
            publisher.publish(msg)

        timer = node.create_timer(0.01, publish_state)
        spin_until(node, lambda: len({t.child_frame_id for t in dynamic}) >= 5, 15)
        received_frames = {}
        for t in dynamic:
            received_frames[t.child_frame_id] = {
                "parent": t.header.frame_id,
                "stamp": [t.header.stamp.sec, t.header.stamp.nanosec],
                "got": [
                    [
                        t.transform.translation.x,
                        t.transform.translation.y,
                        t.transform.translation.z,
                    ],
                    [
                        t.transform.rotation.x,
                        t.transform.rotation.y,
                        t.transform.rotation.z,
                        t.transform.rotation.w,
                    ],
                ],
            }
        report["dynamic"] = received_frames
        follow = positions["tilt_joint"] * 0.5 + 0.1
        report["dynamic_expected"] = {
            JOINTS[name][1]: list(expected(name, positions.get(name, follow)))
            for name in ("pan_joint", "tilt_joint", "slide_joint", "wheel_joint", "follow_joint")
        }
        # publish_frequency 20 limits each joint to 20 transforms a second (we send 100/s).
        dynamic.clear()
        t0 = time.monotonic()
        spin_until(node, lambda: time.monotonic() - t0 > 2.0, 3)
        report["pan_rate"] = sum(1 for t in dynamic if t.child_frame_id == "pan") / (
            time.monotonic() - t0
        )
        node.destroy_timer(timer)
        # A JointState whose names and positions disagree is refused with upstream's words.
        bad = JointState(name=["pan_joint", "tilt_joint"], position=[0.1])
        publisher.publish(bad)
        report["invalid_logged"] = out.wait_for("ignored an invalid JointState message", 5)
        # A broken description at run time is refused with the reason; the robot stays.
        client = node.create_client(SetParameters, "/robot_state_publisher/set_parameters")
        client.wait_for_service(timeout_sec=10)
        request = SetParameters.Request(
            parameters=[
                Parameter(
                    name="robot_description",
                    value=ParameterValue(
                        type=ParameterType.PARAMETER_STRING,
                        string_value="<robot name='x'><link name='a'/>",
                    ),
                )
            ]
        )
        future = client.call_async(request)
        spin_until(node, future.done, 10)
        result = future.result().results[0] if future.done() else None
        report["bad_set"] = (
            {"successful": result.successful, "reason": result.reason} if result else None
        )
        # A good new description replaces the robot: new static frames arrive.
        new_urdf = URDF.replace(
            '<link name="follower"/>', '<link name="follower"/><link name="extra"/>'
        ).replace(
            "</robot>",
            '<joint name="extra_joint" type="fixed"><parent link="camera"/><child link="extra"/>'
            '<origin xyz="0 0 1"/></joint></robot>',
        )
        request.parameters[0].value.string_value = new_urdf
        future = client.call_async(request)
        spin_until(node, future.done, 10)
        report["good_set"] = bool(future.done() and future.result().results[0].successful)
        report["new_static"] = spin_until(node, lambda: "extra" in statics, 10)
        report["main_alive"] = main_proc.poll() is None
        report["main_log"] = out.lines[-40:]
        report["main_exit"] = stop(main_proc)
        # The old command-line form: a URDF file name as the first argument.
        file_proc = start(
            [urdf_path, "--ros-args", "-r", "__node:=rsp_from_file", "-p", "frame_prefix:=r2/"],
            workdir,
        )
        procs.append(file_proc)
        file_out = Output(file_proc)
        report["file_initialized"] = file_out.wait_for("Robot initialized", 20)
        spin_until(node, lambda: "r2/camera" in statics, 15)
        prefixed = statics.get("r2/camera")
        report["prefixed_parent"] = prefixed.header.frame_id if prefixed else None
        report["file_log"] = file_out.lines[:10]
        report["file_exit"] = stop(file_proc)
        # The terminal form: -p robot_description:="$(xacro model.urdf.xacro)".
        if len(sys.argv) > 1:
            xacro = os.path.join(os.path.dirname(sys.executable), "xacro")
            described = subprocess.run([xacro, sys.argv[1]], capture_output=True, text=True)
            xacro_proc = start(
                ["--ros-args", "-p", f"robot_description:={described.stdout}"], workdir
            )
            procs.append(xacro_proc)
            report["xacro_initialized"] = Output(xacro_proc).wait_for("Robot initialized", 20)
            report["xacro_exit"] = stop(xacro_proc)
            # No description at all: FATAL and a failing exit, as upstream.
        empty_proc = start([], workdir)
        procs.append(empty_proc)
        try:
            report["empty_exit"] = empty_proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            report["empty_exit"] = None
        empty_out = Output(empty_proc)
        empty_out.thread.join(5)
        report["empty_log"] = empty_out.lines
    finally:
        for proc in procs:
            stop(proc)
        node.destroy_node()
        rclpy.try_shutdown()
    print("REPORT " + json.dumps(report))


if __name__ == "__main__":
    main()
