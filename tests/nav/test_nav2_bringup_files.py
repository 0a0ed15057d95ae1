"""nav2_bringup without ROS: its params file in Nav2's layout, its launch files, RewrittenYaml."""

from __future__ import annotations

import ast
from pathlib import Path

from nav2_bringup import params_file, share_files
from nav2_common.launch.rewritten_yaml import rewrite

from app import PROJECT_ROOT
from app.catalog import NAV2_PARAMS, lookup
from tests.nav.bringup_helpers import PARAMETERS, load, node_sections

NODES = {
    "/amcl", "/bt_navigator", "/controller_server", "/planner_server", "/map_server",
    "/waypoint_follower", "/global_costmap/global_costmap", "/local_costmap/local_costmap",
    "/lifecycle_manager_localization", "/lifecycle_manager_navigation",
}  # fmt: skip


def test_the_params_file_has_nav2s_layout():
    document = load(params_file())
    sections = node_sections(document)
    assert set(sections) == NODES
    # Nav2's nesting: the costmaps under their namespace, plugins' parameters under their name.
    assert PARAMETERS in document["global_costmap"]["global_costmap"]
    controller = sections["/controller_server"]
    assert controller["FollowPath.plugin"].startswith("nav2_regulated_pure_pursuit_controller")
    assert sections["/planner_server"]["GridBased.plugin"] == "nav2_navfn_planner::NavfnPlanner"
    costmap = sections["/global_costmap/global_costmap"]
    assert costmap["plugins"] == ["static_layer", "obstacle_layer", "inflation_layer"]
    assert costmap["inflation_layer.inflation_radius"] == 0.55
    amcl = sections["/amcl"]
    assert amcl["base_frame_id"] == "base_link" and amcl["set_initial_pose"] is True
    assert (amcl["initial_pose.x"], amcl["initial_pose.y"], amcl["initial_pose.yaw"]) == (0, 0, 0)


def test_the_share_folder_holds_three_launch_files_and_the_params_file():
    files = share_files()
    assert set(files) == {
        "share/nav2_bringup/launch/bringup_launch.py",
        "share/nav2_bringup/launch/localization_launch.py",
        "share/nav2_bringup/launch/navigation_launch.py",
        "share/nav2_bringup/params/nav2_params.yaml",
    }
    for path, text in files.items():
        if not path.endswith(".py"):
            continue
        tree = ast.parse(text)
        assert any(
            isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description"
            for n in tree.body
        ), path
        declared = {
            n.args[0].value
            for n in ast.walk(tree)
            if isinstance(n, ast.Call)
            and getattr(n.func, "id", "") == "DeclareLaunchArgument"
            and isinstance(n.args[0], ast.Constant)
        }
        assert {"namespace", "params_file", "use_sim_time", "autostart"} <= declared, path
        if "navigation_launch" not in path:
            assert "map" in declared, path


def test_the_catalogs_office_amcl_reads_the_params_file():
    entry = lookup("amcl_office")
    assert "--params-file" in entry.argv_tail()
    assert (PROJECT_ROOT / NAV2_PARAMS).resolve() == params_file().resolve()


def test_rewritten_yaml_sets_values_adds_missing_ones_and_nests_under_a_namespace():
    document = {
        "map_server": {PARAMETERS: {"yaml_filename": "", "frame_id": "map"}},
        "global_costmap": {"global_costmap": {PARAMETERS: {"robot_radius": 0.15}}},
    }
    out = rewrite(document, {"yaml_filename": "/maps/office.yaml", "use_sim_time": True})
    assert out["map_server"][PARAMETERS] == {
        "yaml_filename": "/maps/office.yaml", "frame_id": "map", "use_sim_time": True,
    }  # fmt: skip
    assert out["global_costmap"]["global_costmap"][PARAMETERS]["use_sim_time"] is True
    assert document["map_server"][PARAMETERS]["yaml_filename"] == ""  # the source is untouched
    nested = rewrite(document, {}, "/robot1")
    assert set(node_sections(nested)) == {
        "/robot1/map_server", "/robot1/global_costmap/global_costmap",
    }  # fmt: skip


def test_params_file_path_is_inside_the_package():
    assert params_file().is_file()
    assert Path(params_file()).parent.name == "params"
