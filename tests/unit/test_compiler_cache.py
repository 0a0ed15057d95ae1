"""The run's compiler cache (tests/run.py ``compiler_cache``): set for the run, gone after,
and shared by workspaces in different temporary folders."""

from __future__ import annotations

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from tests import run
from tests.run import compiler_cache, compiler_cache_env

SOURCE = '#include <stdio.h>\nint main(void) { puts("hi"); return 0; }\n'


def test_the_cache_is_the_runs_and_only_the_tests_that_ask_get_it(monkeypatch):
    monkeypatch.setattr(run.shutil, "which", lambda name: f"/usr/bin/{name}")
    monkeypatch.delenv(run.COMPILER_CACHE, raising=False)
    env = {"KEEP": "1"}
    with compiler_cache(env) as folder:
        assert folder is not None and folder.is_dir()
        assert env == {"KEEP": "1", run.COMPILER_CACHE: str(folder)}
        monkeypatch.setenv(run.COMPILER_CACHE, str(folder))
        asked = compiler_cache_env()
        assert asked["CCACHE_DIR"] == str(folder)
        assert asked["CMAKE_C_COMPILER_LAUNCHER"] == asked["CMAKE_CXX_COMPILER_LAUNCHER"]
        assert asked["CMAKE_CXX_COMPILER_LAUNCHER"] == "/usr/bin/ccache"
        assert asked["CCACHE_BASEDIR"].startswith(str(Path(tempfile.gettempdir()).resolve()))
    assert not folder.exists()
    assert env == {"KEEP": "1"}


def test_without_ccache_nothing_is_set(monkeypatch):
    monkeypatch.setattr(run.shutil, "which", lambda name: None)
    env: dict[str, str] = {}
    with compiler_cache(env) as folder:
        assert folder is None and env == {}
    monkeypatch.setenv(run.COMPILER_CACHE, "/somewhere")
    assert compiler_cache_env() == {}


def test_the_same_source_in_another_workspace_is_a_hit(tmp_path):
    """As the three interface builds are: the same file under two test folders of pytest's
    temporary root, compiled from inside each workspace's build folder."""
    if shutil.which("ccache") is None or shutil.which("cc") is None:
        pytest.fail("ccache and a C compiler are needed: `make test` installs ccache")
    with compiler_cache(os.environ):
        env = {"PATH": "/usr/bin:/bin", **compiler_cache_env()}
        assert str(tmp_path.resolve()).startswith(env["CCACHE_BASEDIR"]), (
            f"pytest's folder {tmp_path} is not under base_dir {env['CCACHE_BASEDIR']}"
        )
        for name in ("first_ws", "second_ws_deeper"):
            src, build = tmp_path / name / "src", tmp_path / name / "build"
            src.mkdir(parents=True)
            build.mkdir()
            (src / "hello.c").write_text(SOURCE)
            subprocess.run(
                [
                    env["CMAKE_C_COMPILER_LAUNCHER"],
                    "cc",
                    "-c",
                    str(src / "hello.c"),
                    "-o",
                    "hello.o",
                ],
                cwd=build,
                env=env,
                check=True,
                timeout=60,
            )
            assert (build / "hello.o").stat().st_size > 0
        stats = subprocess.run(
            ["ccache", "--print-stats"], env=env, capture_output=True, text=True, check=True
        ).stdout
    counts = dict(line.split("\t")[:2] for line in stats.splitlines() if "\t" in line)
    hits = int(counts.get("direct_cache_hit", 0)) + int(counts.get("preprocessed_cache_hit", 0))
    assert hits == 1, stats
