"""Bad input on the command line: one clear line and a non-zero exit, no traceback."""

import socket

from tests.conftest import run_cli


def test_list_prints_the_catalog():
    result = run_cli("list")
    assert result.returncode == 0
    assert "talker" in result.stdout and "chatter_demo" in result.stdout


def test_run_unknown_node_is_a_clear_error():
    result = run_cli("run", "no_such_node")
    assert result.returncode == 2
    assert "no catalog node named 'no_such_node'" in result.stderr
    assert "Traceback" not in result.stderr


def test_busy_port_is_a_clear_error():
    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        result = run_cli("serve", "--port", str(port))
    assert result.returncode == 2
    assert f"port {port} on 127.0.0.1 is already in use" in result.stderr
    assert "Traceback" not in result.stderr


def test_serving_beyond_loopback_is_refused():
    result = run_cli("serve", "--host", "0.0.0.0", "--port", "1")
    assert result.returncode == 2
    assert "refusing to serve on 0.0.0.0" in result.stderr


def test_bad_domain_id_is_a_usage_error():
    result = run_cli("serve", "--domain-id", "999")
    assert result.returncode == 2
    assert "between 0 and 101" in result.stderr


def test_run_package_and_unknown_executable_is_a_clear_error():
    result = run_cli("run", "turtlesim", "turtle_rocket")
    assert result.returncode == 2
    assert "'turtle_rocket' is not in package 'turtlesim'" in result.stderr
    assert "turtlesim_node" in result.stderr  # what the package has
    assert "Traceback" not in result.stderr
