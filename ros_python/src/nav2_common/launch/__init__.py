"""Launch helpers of Nav2's launch files (upstream's ``nav2_common.launch``)."""

from .rewritten_yaml import RewrittenYaml

__all__ = ["RewrittenYaml"]
