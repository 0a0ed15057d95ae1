"""Exercise: a launch file for a greeter and a listener that hears it.

In a full ROS 2 install this file would begin with
    from launch import LaunchDescription
    from launch_ros.actions import Node
and run with `ros2 launch`. Here both names come from the bottom of the file,
and running it (the Run button, or `python3` on this file) launches it.
"""


def generate_launch_description():
    return LaunchDescription(
        [
            Node(
                package="tutorial_nodes",
                executable="parameters_node",
                name="launch_greeter",
                # TODO 1: give it the parameter greeting = "Ahoy".
                output="screen",
            ),
            # TODO 2: a second Node: the executable "listener" of the same
            #         package, named "launch_listener", with its topic
            #         "chatter" remapped to "greeting".
        ]
    )


# ---------------------------------------------------------------------------
# Below: the classroom's stand-in for `ros2 launch`. The launch and
# launch_ros packages are not installed here (they are not on PyPI), so
# these few lines take their place. You do not need to change them.
# They accept the Node(...) keywords this course uses, start each node as
# `ros2 run tutorial_nodes <executable> --ros-args ...` would, print every
# line of output prefixed with the node's label, and stop with Ctrl+C.
# ---------------------------------------------------------------------------


class LaunchDescription:
    def __init__(self, entities=()):
        self.entities = list(entities)


class Node:
    def __init__(
        self,
        *,
        package,
        executable,
        name=None,
        namespace=None,
        parameters=(),
        remappings=(),
        arguments=(),
        output="screen",
        ros_arguments=(),
    ):
        import importlib.util
        import json
        import sys

        if package != "tutorial_nodes":
            raise SystemExit(f"launch: no package {package!r} here (try 'tutorial_nodes')")
        if importlib.util.find_spec(f"nodes.{executable}") is None:
            raise SystemExit(f"launch: package 'tutorial_nodes' has no executable {executable!r}")
        self.executable = executable
        self.argv = [sys.executable, "-m", f"nodes.{executable}", *map(str, arguments)]
        self.argv += ["--ros-args", *ros_arguments]
        if name:
            self.argv += ["-r", f"__node:={name}"]
        if namespace:
            self.argv += ["-r", f"__ns:={namespace}"]
        for source, target in remappings:
            self.argv += ["-r", f"{source}:={target}"]
        for table in parameters:
            if not isinstance(table, dict):
                raise SystemExit("launch: parameters=[...] takes dictionaries here")
            for key, value in table.items():
                self.argv += ["-p", f"{key}:={json.dumps(value)}"]  # read as YAML


def launch(description):
    """Start every Node, relay their output, and wait until they end or Ctrl+C."""
    import signal
    import subprocess
    import threading
    import time

    def relay(label, stream):
        for raw in stream:
            print(f"[{label}] {raw.decode(errors='replace').rstrip()}", flush=True)

    running = []
    for number, node in enumerate(description.entities, start=1):
        label = f"{node.executable}-{number}"
        process = subprocess.Popen(node.argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
        print(f"[INFO] [launch]: {label} started with pid [{process.pid}]", flush=True)
        thread = threading.Thread(target=relay, args=(label, process.stdout), daemon=True)
        thread.start()
        running.append((label, process, thread))

    def wait_all(seconds):
        deadline = time.monotonic() + seconds
        while any(p.poll() is None for _l, p, _t in running) and time.monotonic() < deadline:
            time.sleep(0.1)

    try:
        wait_all(float("inf"))
    except KeyboardInterrupt:
        print("[WARNING] [launch]: interrupted (SIGINT), stopping the nodes", flush=True)
    finally:
        wait_all(2.0)  # Ctrl+C in a terminal reaches every node of the group at once
        for signal_to_send, grace in ((signal.SIGINT, 3.0), (signal.SIGKILL, 1.0)):
            for _label, process, _thread in running:
                if process.poll() is None:
                    process.send_signal(signal_to_send)
            wait_all(grace)
        for label, process, thread in running:
            thread.join(1.0)
            print(f"[INFO] [launch]: {label} ended with exit code {process.poll()}", flush=True)


if __name__ == "__main__":
    launch(generate_launch_description())
