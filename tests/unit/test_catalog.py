import pytest

from app import PROJECT_ROOT, catalog


def test_every_entry_names_an_existing_node_module():
    for entry in catalog.ENTRIES:
        assert (PROJECT_ROOT / "nodes" / f"{entry.module}.py").is_file(), entry.name
        assert entry.node_name.startswith("/")


def test_groups_only_reference_catalog_entries():
    for group in catalog.GROUPS:
        for member in group.members:
            catalog.lookup(member)


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(catalog.UnknownNodeError, match="talker"):
        catalog.lookup("rm -rf /")


def test_remapped_listener_command():
    entry = catalog.lookup("listener2")
    assert entry.argv_tail() == ["--ros-args", "-r", "__node:=listener2"]
    assert entry.ros2_run_command().endswith("listener --ros-args -r __node:=listener2")
