from . import AnyLaunchDescriptionSource

__all__ = ["AnyLaunchDescriptionSource"]
