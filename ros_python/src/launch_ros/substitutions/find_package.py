from . import FindPackageShare

__all__ = ["FindPackageShare"]
