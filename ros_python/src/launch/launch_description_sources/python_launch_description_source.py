from . import PythonLaunchDescriptionSource

__all__ = ["PythonLaunchDescriptionSource"]
