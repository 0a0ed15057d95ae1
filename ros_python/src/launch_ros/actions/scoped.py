"""PushRosNamespace, SetParameter and SetRemap: settings for the Nodes after them in a scope."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from launch.action import Action
from launch.utilities import normalize_to_list_of_substitutions, perform_substitutions

from ..parameter_descriptions import evaluate_value
from ..utilities import make_namespace_absolute, prefix_namespace

if TYPE_CHECKING:
    from launch import LaunchContext


class PushRosNamespace(Action):
    """Nodes after it (in the same GroupAction) are inside ``namespace``."""

    def __init__(self, namespace: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__namespace = normalize_to_list_of_substitutions(namespace)

    @property
    def namespace(self) -> Any:
        return self.__namespace

    def execute(self, context: LaunchContext) -> None:
        pushed = perform_substitutions(context, self.__namespace)
        previous = context.launch_configurations.get("ros_namespace")
        namespace = make_namespace_absolute(prefix_namespace(previous, pushed))
        if namespace is not None:
            context.launch_configurations["ros_namespace"] = namespace


class SetParameter(Action):
    """Sets a parameter on every Node after it (in the same scope)."""

    def __init__(self, name: Any, value: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__name = normalize_to_list_of_substitutions(name)
        self.__value = value

    @property
    def name(self) -> Any:
        return self.__name

    @property
    def value(self) -> Any:
        return self.__value

    def execute(self, context: LaunchContext) -> None:
        name = perform_substitutions(context, self.__name)
        value = evaluate_value(context, self.__value)
        params = list(context.launch_configurations.get("global_params", []))
        params.append((name, value))
        context.launch_configurations["global_params"] = params


class SetRemap(Action):
    """Applies a remapping to every Node after it (in the same scope)."""

    def __init__(self, src: Any, dst: Any, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        self.__src = normalize_to_list_of_substitutions(src)
        self.__dst = normalize_to_list_of_substitutions(dst)

    def execute(self, context: LaunchContext) -> None:
        remaps = list(context.launch_configurations.get("ros_remaps", []))
        remaps.append(
            (perform_substitutions(context, self.__src), perform_substitutions(context, self.__dst))
        )
        context.launch_configurations["ros_remaps"] = remaps


class SetUseSimTime(SetParameter):
    def __init__(self, value: Any, **kwargs: Any) -> None:
        super().__init__("use_sim_time", value, **kwargs)
