"""``launch_ros.actions.Node``: one ``ros2 run PACKAGE EXECUTABLE --ros-args ...``.

The command line is upstream's: the executable from the ament index, then
``arguments``, then ``--ros-args`` with ``ros_arguments``, ``-r __node:=``,
``-r __ns:=`` (inside any PushRosNamespace), the parameters (SetParameter's
first) and the remappings (SetRemap's first). Dictionary parameters are
passed as ``-p name:=value`` (upstream writes them to a temporary YAML file
first; the node receives the same values), parameter files as
``--params-file``.
"""

from __future__ import annotations

import json
import os
from collections.abc import Iterable, Mapping
from typing import TYPE_CHECKING, Any

from launch.actions import ExecuteProcess
from launch.substitution import Substitution
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

from ..parameter_descriptions import ParameterFile, evaluate_value
from ..substitutions import ExecutableInPackage
from ..utilities import make_namespace_absolute, prefix_namespace

if TYPE_CHECKING:
    from launch import LaunchContext


def _flatten(prefix: str, table: Mapping[Any, Any], out: list[tuple[str, Any]]) -> None:
    for key, value in table.items():
        name = f"{prefix}{key}" if isinstance(key, str) else str(key)
        if isinstance(value, Mapping):
            _flatten(name + ".", value, out)
        else:
            out.append((name, value))


def _param_text(value: Any) -> str:
    """A value as rcl reads ``-p`` (YAML; JSON is YAML)."""
    return json.dumps(value)


class Node(ExecuteProcess):
    def __init__(
        self,
        *,
        executable: Any,
        package: Any | None = None,
        name: Any | None = None,
        namespace: Any | None = None,
        exec_name: Any | None = None,
        parameters: Iterable[Any] | None = None,
        remappings: Iterable[tuple[Any, Any]] | None = None,
        ros_arguments: Iterable[Any] | None = None,
        arguments: Iterable[Any] | None = None,
        **kwargs: Any,
    ) -> None:
        if package is not None:
            executable_sub: Any = ExecutableInPackage(package=package, executable=executable)
        else:
            executable_sub = executable
        self.__package = package
        self.__executable = normalize_to_list_of_substitutions(executable)
        self.__node_name = None if name is None else normalize_to_list_of_substitutions(name)
        self.__namespace = (
            None if namespace is None else normalize_to_list_of_substitutions(namespace)
        )
        self.__exec_name = exec_name
        if parameters is not None and isinstance(parameters, (str, Mapping, Substitution)):
            raise TypeError("Node(parameters=...) takes a list: parameters=[{'name': value}]")
        self.__parameters = list(parameters) if parameters is not None else []
        self.__remappings = list(remappings) if remappings is not None else []
        self.__ros_arguments = [
            normalize_to_list_of_substitutions(a) for a in (ros_arguments or [])
        ]
        self.__arguments = [normalize_to_list_of_substitutions(a) for a in (arguments or [])]
        super().__init__(cmd=[executable_sub], name=exec_name, **kwargs)
        self.__expanded_node_name = "<node_name_unspecified>"
        self.__expanded_node_namespace = ""

    @property
    def node_package(self) -> Any:
        return self.__package

    @property
    def node_executable(self) -> list[Substitution]:
        return self.__executable

    @property
    def node_name(self) -> str:
        """The fully qualified node name, once the node has started."""
        ns = self.__expanded_node_namespace.rstrip("/")
        return f"{ns}/{self.__expanded_node_name}"

    def is_node_name_fully_specified(self) -> bool:
        return self.__node_name is not None

    def _process_label_base(self, context: LaunchContext, cmd: list[str]) -> str:
        if self.__exec_name is not None:
            return perform_substitutions(
                context, normalize_to_list_of_substitutions(self.__exec_name)
            )
        return os.path.basename(perform_substitutions(context, self.__executable))

    def _perform_cmd(self, context: LaunchContext) -> list[str]:
        cmd = super()._perform_cmd(context)  # the executable, found in the ament index
        cmd += [perform_substitutions(context, a) for a in self.__arguments]
        cmd.append("--ros-args")
        cmd += [perform_substitutions(context, a) for a in self.__ros_arguments]
        if self.__node_name is not None:
            self.__expanded_node_name = perform_substitutions(context, self.__node_name)
            cmd += ["-r", f"__node:={self.__expanded_node_name}"]
        own_ns = None
        if self.__namespace is not None:
            own_ns = perform_substitutions(context, self.__namespace)
        base_ns = context.launch_configurations.get("ros_namespace")
        namespace = make_namespace_absolute(prefix_namespace(base_ns, own_ns))
        if namespace is not None:
            self.__expanded_node_namespace = namespace
            cmd += ["-r", f"__ns:={namespace}"]
        for item in [*context.launch_configurations.get("global_params", []), *self.__parameters]:
            cmd += self.__parameter_args(context, item)
        remaps = [*context.launch_configurations.get("ros_remaps", []), *self.__remappings]
        for source, target in remaps:
            src = perform_substitutions(context, normalize_to_list_of_substitutions(source))
            dst = perform_substitutions(context, normalize_to_list_of_substitutions(target))
            cmd += ["-r", f"{src}:={dst}"]
        return cmd

    def __parameter_args(self, context: LaunchContext, item: Any) -> list[str]:
        if isinstance(item, tuple) and len(item) == 2:  # from SetParameter
            name = perform_substitutions(context, normalize_to_list_of_substitutions(item[0]))
            return ["-p", f"{name}:={_param_text(evaluate_value(context, item[1]))}"]
        if isinstance(item, Mapping):
            pairs: list[tuple[str, Any]] = []
            _flatten("", item, pairs)
            args: list[str] = []
            for name, value in pairs:
                args += ["-p", f"{name}:={_param_text(evaluate_value(context, value))}"]
            return args
        if isinstance(item, ParameterFile):
            return ["--params-file", item.evaluate(context)]
        if isinstance(item, (str, os.PathLike, Substitution, list)):
            path = perform_substitutions(
                context,
                normalize_to_list_of_substitutions(
                    os.fspath(item) if isinstance(item, os.PathLike) else item
                ),
            )
            if not os.path.isfile(path):
                raise RuntimeError(f"parameter file '{path}' does not exist")
            return ["--params-file", path]
        raise TypeError(
            f"Node parameters must be dictionaries or parameter file paths, got "
            f"'{type(item).__name__}': {item!r}"
        )
