"""tf2_ros's BufferInterface: ``transform()`` for any registered message type.

Conversions live in registries keyed by message type, filled by packages such
as tf2_geometry_msgs when they are imported, as upstream does it.
"""

from __future__ import annotations

from collections.abc import Callable
from copy import deepcopy
from typing import Any

from geometry_msgs.msg import TransformStamped
from rclpy.duration import Duration
from rclpy.time import Time
from std_msgs.msg import Header

TransformableObject = Any
NO_TIMEOUT = Duration()  # the default timeout: do not wait
TransformableObjectType = Any


class TypeException(Exception):
    """A type has no registered transform or conversion."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class NotImplementedException(Exception):
    """A BufferInterface subclass lacks lookup_transform or can_transform."""

    def __init__(self) -> None:
        super().__init__("CanTransform or LookupTransform not implemented")
        self.errstr = "CanTransform or LookupTransform not implemented"


class TransformRegistration:
    """Message type -> function(obj, TransformStamped) -> transformed obj (shared by all)."""

    __type_map: dict[Any, Callable[[Any, TransformStamped], Any]] = {}

    def print_me(self) -> None:
        print(TransformRegistration.__type_map)

    def add(self, key: Any, callback: Callable[[Any, TransformStamped], Any]) -> None:
        TransformRegistration.__type_map[key] = callback

    def get(self, key: Any) -> Callable[[Any, TransformStamped], Any]:
        if key not in TransformRegistration.__type_map:
            raise TypeException(f"Type {key} is not loaded or supported")
        return TransformRegistration.__type_map[key]


class ConvertRegistration:
    """Conversions between message types and other types, for ``new_type``."""

    __to_msg_map: dict[Any, Callable[[Any], Any]] = {}
    __from_msg_map: dict[Any, Callable[[Any], Any]] = {}
    __convert_map: dict[tuple[Any, Any], Callable[[Any], Any]] = {}

    def add_from_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration.__from_msg_map[key] = callback

    def add_to_msg(self, key: Any, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration.__to_msg_map[key] = callback

    def add_convert(self, key: tuple[Any, Any], callback: Callable[[Any], Any]) -> None:
        ConvertRegistration.__convert_map[key] = callback

    def get_from_msg(self, key: Any) -> Callable[[Any], Any]:
        if key not in ConvertRegistration.__from_msg_map:
            raise TypeException(f"Type {key} is not loaded or supported")
        return ConvertRegistration.__from_msg_map[key]

    def get_to_msg(self, key: Any) -> Callable[[Any], Any]:
        if key not in ConvertRegistration.__to_msg_map:
            raise TypeException(f"Type {key} is not loaded or supported")
        return ConvertRegistration.__to_msg_map[key]

    def get_convert(self, key: tuple[Any, Any]) -> Callable[[Any], Any]:
        if key not in ConvertRegistration.__convert_map:
            raise TypeException(f"Type {key} is not loaded or supported")
        return ConvertRegistration.__convert_map[key]


def convert(a: Any, b_type: Any) -> Any:
    """``a`` as ``b_type``, directly or through its message form."""
    c = ConvertRegistration()
    try:
        return c.get_convert((type(a), b_type))(a)
    except TypeException:
        if type(a) is b_type:
            return deepcopy(a)
        return c.get_from_msg(b_type)(c.get_to_msg(type(a))(a))


def Stamped(obj: Any, stamp: Time, frame_id: str) -> Any:
    obj.header = Header(frame_id=frame_id, stamp=stamp)
    return obj


class BufferInterface:
    """What every tf2 buffer offers; ``transform`` works for registered types."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(
        self,
        object_stamped: Any,
        target_frame: str,
        timeout: Duration = NO_TIMEOUT,
        new_type: Any = None,
    ) -> Any:
        """``object_stamped`` expressed in ``target_frame`` at its own stamp."""
        do_transform = self.registration.get(type(object_stamped))
        res = do_transform(
            object_stamped,
            self.lookup_transform(
                target_frame, object_stamped.header.frame_id, object_stamped.header.stamp, timeout
            ),
        )
        return res if new_type is None else convert(res, new_type)

    def transform_full(
        self,
        object_stamped: Any,
        target_frame: str,
        target_time: Time,
        fixed_frame: str,
        timeout: Duration = NO_TIMEOUT,
        new_type: Any = None,
    ) -> Any:
        """As ``transform``, into ``target_frame`` at ``target_time``, via ``fixed_frame``."""
        do_transform = self.registration.get(type(object_stamped))
        res = do_transform(
            object_stamped,
            self.lookup_transform_full(
                target_frame,
                target_time,
                object_stamped.header.frame_id,
                object_stamped.header.stamp,
                fixed_frame,
                timeout,
            ),
        )
        return res if new_type is None else convert(res, new_type)

    def lookup_transform(
        self, target_frame: str, source_frame: str, time: Time, timeout: Duration = NO_TIMEOUT
    ) -> TransformStamped:
        raise NotImplementedException()

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration = NO_TIMEOUT,
    ) -> TransformStamped:
        raise NotImplementedException()

    def can_transform(
        self, target_frame: str, source_frame: str, time: Time, timeout: Duration = NO_TIMEOUT
    ) -> bool:
        raise NotImplementedException()

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Time,
        source_frame: str,
        source_time: Time,
        fixed_frame: str,
        timeout: Duration = NO_TIMEOUT,
    ) -> bool:
        raise NotImplementedException()
