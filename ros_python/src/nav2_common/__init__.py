"""nav2_common: what Nav2's launch files share (``nav2_common.launch.RewrittenYaml``)."""
