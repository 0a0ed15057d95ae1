"""tools/suite_cpu_by_process.py reads acct(2) records as Linux writes them (version 3)."""

from __future__ import annotations

from pathlib import Path

from tools.suite_cpu_by_process import (
    ACCT_FILE,
    PROCESSES_FILE,
    RECORD,
    START_FILE,
    decode_comp,
    kind_of,
    main,
    read_records,
)

RENDERER = "/usr/lib/chromium/chromium --type=renderer --lang=en-US"
DASHBOARD = "/v/.venv/bin/python -m app serve --port 4711 --progress-dir /tmp/p"
TALKER = "/v/.venv/bin/python -m nodes.talker --ros-args"
PROGRAM = "/v/.venv/bin/python /tmp/pytest-of-root/pytest-3/popen-gw2/code0/counter.py"


def _comp(ticks: int) -> int:
    """comp_t as the kernel encodes it: the exponent grows while the mantissa overflows."""
    exponent = 0
    while ticks > 0x1FFF:
        ticks >>= 3
        exponent += 1
    return (exponent << 13) | ticks


def _record(pid: int, start: int, cpu_ticks: int, name: bytes, version: int = 3) -> bytes:
    user, system = cpu_ticks - cpu_ticks // 4, cpu_ticks // 4
    return RECORD.pack(
        0, version, 0, 0, 0, 0, pid, 1, start, 1.0,
        _comp(user), _comp(system), 0, 0, 0, 0, 0, 0, name,
    )  # fmt: skip


def _recorded_run(tmp_path: Path) -> Path:
    records = [
        _record(10, 1000, 250, b"chromium"),  # 2.5 s
        _record(11, 1001, 100, b"python3.11"),  # 1 s
        _record(10, 2000, 50, b"python3.11"),  # pid 10 again, later: the talker
        _record(12, 1500, 30, b"ros2"),  # never sampled: ended within the second
        _record(13, 1200, 40, b"python3.11"),  # 0.4 s
        _record(14, 500, 900, b"bash"),  # began before the recording: not the run's
        _record(15, 1300, 999, b"odd", version=2),  # a record this reader does not know
    ]
    (tmp_path / ACCT_FILE).write_bytes(b"".join(records))
    (tmp_path / START_FILE).write_text("900.00")
    sampled = [
        f"10\t1000.40\t{RENDERER}",
        f"11\t1001.70\t{DASHBOARD}",
        f"10\t2000.20\t{TALKER}",
        f"13\t1200.10\t{PROGRAM}",
        "14\t500.00\tbash -c 'while :; do :; done'",
    ]
    (tmp_path / PROCESSES_FILE).write_text("\n".join(sampled) + "\n")
    return tmp_path


def test_comp_t_values_past_the_mantissa_read_back():
    assert decode_comp(_comp(10_000)) == 10_000  # one step of the exponent: exact here
    assert decode_comp(_comp(8191)) == 8191
    assert decode_comp(0) == 0


def test_a_reused_pid_gets_the_command_line_of_its_own_start(tmp_path):
    ended = read_records((_recorded_run(tmp_path) / ACCT_FILE).read_bytes())
    assert [(e.pid, e.cpu) for e in ended] == [
        (10, 2.5), (11, 1.0), (10, 0.5), (12, 0.3), (13, 0.4), (14, 9.0),
    ]  # fmt: skip
    assert kind_of(RENDERER, "chromium") == "chromium renderer"
    assert kind_of(DASHBOARD, "python3.11") == "dashboard"
    assert kind_of(TALKER, "python3.11") == "python -m nodes.talker"
    assert kind_of(PROGRAM, "python3.11") == "learner program"
    assert kind_of(None, "ros2") == "short-lived: ros2"


def test_the_report_sums_each_group_of_the_runs_processes(tmp_path, capsys):
    assert main(["report", str(_recorded_run(tmp_path)), "--kinds"]) == 0
    text = capsys.readouterr().out
    assert text.startswith("5 CPU-s in 5 processes"), text  # 2.5 + 1 + 0.5 + 0.3 + 0.4 = 4.7
    lines = text.splitlines()
    assert lines[3] == "     2  53.2  Chromium and Playwright (browser tests' pages)", lines
    assert "     1  21.3  dashboards (python -m app serve)" in lines
    assert "     0  10.6  other catalog nodes (talker, turtlesim, tf2 demos...)" in lines
    assert "     0   8.5  learner programs and tests' helper scripts" in lines
    assert any(line.endswith("short-lived: ros2 (1 processes)") for line in lines), lines
    assert "bash" not in text  # the loop started before the recording is not counted


def test_python_options_before_the_module_or_script_are_passed_over():
    assert kind_of("python3 -X faulthandler -m nodes.crashing_node", "python3") == (
        "python -m nodes.crashing_node"
    )
    assert kind_of("python -u -W ignore -I /x/tests/tf2/outside_check.py 1", "p") == (
        "python outside_check.py"
    )
    assert kind_of("python -c import sys", "python") == "python -c"
    assert kind_of("python -m app exercise check x", "python") == "python -m app"
