from .scoped import SetRemap

__all__ = ["SetRemap"]
