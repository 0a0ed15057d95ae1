from . import OnExecutionComplete

__all__ = ["OnExecutionComplete"]
