from .scoped import SetParameter

__all__ = ["SetParameter"]
