from .scoped import PushRosNamespace

__all__ = ["PushRosNamespace"]
