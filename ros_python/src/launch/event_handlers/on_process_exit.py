from . import OnProcessExit

__all__ = ["OnProcessExit"]
