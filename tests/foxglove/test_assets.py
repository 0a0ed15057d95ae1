"""A robot description's package:// files reach Foxglove's 3D panel ("fetchAsset"), and
nothing else does: no other scheme, no way out of the package's share folder."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from app.foxglove.assets import fetch_asset
from tests.foxglove.client import FoxgloveClient

MESH = b"solid cube\nendsolid cube\n"


@pytest.fixture
def prefix(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[Path]:
    """An install prefix with one package, `my_robot`, holding a mesh; a secret beside it."""
    index = tmp_path / "install" / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    (index / "my_robot").write_text("")
    meshes = tmp_path / "install" / "share" / "my_robot" / "meshes"
    meshes.mkdir(parents=True)
    (meshes / "base.stl").write_bytes(MESH)
    (tmp_path / "secret.txt").write_text("not for you")
    (meshes / "out").symlink_to(tmp_path / "secret.txt")
    monkeypatch.setenv("AMENT_PREFIX_PATH", str(tmp_path / "install"))
    yield tmp_path


def test_a_package_file_is_served_and_nothing_outside_it(prefix: Path):
    assert fetch_asset("package://my_robot/meshes/base.stl") == MESH
    refused = [
        "package://my_robot/meshes/missing.stl",
        "package://my_robot/../../secret.txt",
        "package://my_robot/meshes/out",  # a link out of the share folder
        "package://other/meshes/base.stl",  # no such package
        "package://my_robot/",
        f"file://{prefix / 'secret.txt'}",
        "http://example.com/x.stl",
    ]
    assert [fetch_asset(uri) for uri in refused] == [None] * len(refused)


@pytest.mark.ros
def test_foxglove_fetches_a_mesh_through_the_bridge(prefix: Path, probe):
    from app.foxglove import FoxgloveBridge

    bridge = FoxgloveBridge(probe.node, port=0)
    bridge.start()
    fox = FoxgloveClient(bridge.url)
    try:
        fox.wait_for(lambda: fox.server_info, 10, "serverInfo")
        assert "assets" in fox.server_info["capabilities"]
        assert fox.fetch_asset("package://my_robot/meshes/base.stl") == (0, "", MESH)
        status, error, data = fox.fetch_asset("package://my_robot/../../secret.txt")
        assert status != 0 and data == b"" and error
    finally:
        fox.close()
        bridge.close()
