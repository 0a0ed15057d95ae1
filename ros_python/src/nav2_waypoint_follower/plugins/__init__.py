"""Waypoint task executors: what the follower does on arriving at a waypoint."""
