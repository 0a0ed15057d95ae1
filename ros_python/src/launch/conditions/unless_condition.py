from . import UnlessCondition

__all__ = ["UnlessCondition"]
