from . import OnShutdown

__all__ = ["OnShutdown"]
