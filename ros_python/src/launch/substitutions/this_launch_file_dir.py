"""``ThisLaunchFileDir`` lives in this_launch_file (upstream's module name kept)."""

from .this_launch_file import ThisLaunchFileDir

__all__ = ["ThisLaunchFileDir"]
