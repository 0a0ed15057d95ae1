from . import OnProcessIO

__all__ = ["OnProcessIO"]
