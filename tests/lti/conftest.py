"""The LTI tests' fixtures: the test LMS, the tool's keys, an outbox folder."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from app.lti.keys import ToolKeys
from tests.lti.platform import TestPlatform


@pytest.fixture(scope="module")
def tool_keys(tmp_path_factory: pytest.TempPathFactory) -> ToolKeys:
    return ToolKeys.load_or_create(tmp_path_factory.mktemp("lti") / "keys")


@pytest.fixture
def platform(tool_keys: ToolKeys) -> Iterator[TestPlatform]:
    lms = TestPlatform()
    lms.tool_jwks = tool_keys.public_jwks()  # the teacher pasted the tool's key set
    yield lms
    lms.close()


@pytest.fixture
def outbox_dir(tmp_path: Path) -> Path:
    return tmp_path / "outbox"
