"""Lessons: the course data (``schema``), live checks, the runner of step actions, progress."""
