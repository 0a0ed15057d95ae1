"""Learner code's rule and its containment: below everything that runs learner code.

- ``policy``: whether learner code may run here, and whether contained
  (``RunPolicy``, set once by whoever serves the dashboard);
- ``sandbox``: the contained argv for the supervisor, whether this machine can
  contain, and the end of a contained run's leftovers;
- ``contain``: the launcher a contained program starts through (by path).

Exercises, the learner's workspace, launch files, the editor's completion
worker and the ros2 verbs all run learner code through these; none of these
imports them.
"""
