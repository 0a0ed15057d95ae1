from . import IfCondition

__all__ = ["IfCondition"]
