"""tools/suite_time.py reads the workers' timelines as tests/conftest.py writes them."""

from __future__ import annotations

from pathlib import Path

from tools.suite_time import main, read_worker, report

GW0 = """\
23:59:50 start tests/browser/test_a.py::test_one load 1.2
00:00:10 end   tests/browser/test_a.py::test_one cpu 30.0
00:00:10 waited 5 s for a core's slot: tests/browser/test_a.py::test_two
00:00:15 start tests/browser/test_a.py::test_two load 3.0
Current thread 0x00007f (most recent call first):
00:00:25 end   tests/browser/test_a.py::test_two cpu unknown (1.0 s left the tree)
"""
GW1 = """\
23:59:50 start tests/unit/test_b.py::test_three load 1.2
00:00:30 end   tests/unit/test_b.py::test_three cpu 10.0
"""


def _artifacts(tmp_path: Path) -> Path:
    for name, text in (("gw0", GW0), ("gw1", GW1)):
        (tmp_path / name).mkdir()
        (tmp_path / name / "timeline.txt").write_text(text)
    return tmp_path


def test_a_worker_has_its_tests_their_cpu_and_its_slot_waits_across_midnight(tmp_path):
    worker = read_worker(_artifacts(tmp_path) / "gw0" / "timeline.txt")
    assert [(t.nodeid.split("::")[1], t.wall, t.cpu) for t in worker.tests] == [
        ("test_one", 20, 30.0),
        ("test_two", 10, 0.0),  # no figure: counted as none, never guessed
    ]
    assert worker.slot_wait == 5


def test_the_report_says_how_busy_the_cores_were_and_ranks_by_cpu(tmp_path, capsys):
    root = _artifacts(tmp_path)
    text = report([read_worker(root / w / "timeline.txt") for w in ("gw0", "gw1")], 2, 5)
    # 40 CPU-s over a 40 s span on 2 cores: half of what they could give.
    assert text.startswith("3 tests over 0.7 min on 2 workers; their CPU 40 s = 50 % of 2 cores")
    folders = text.split("by folder")[1].split("by module")[0].splitlines()[1:3]
    assert [line.split()[-1] for line in folders] == ["tests/browser", "tests/unit"]
    assert main([str(root), "--cores", "2"]) == 0
    assert "50 % of 2 cores" in capsys.readouterr().out
    assert main([str(tmp_path / "none")]) == 1
