"""nav2_waypoint_follower for Python: Nav2's waypoint follower (``follow_waypoints``)."""
