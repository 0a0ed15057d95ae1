from . import OnProcessStart

__all__ = ["OnProcessStart"]
