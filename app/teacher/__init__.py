"""The teacher's view of a classroom: every learner's progress, live, over DDS.

- ``record``       one learner's progress as plain data; the stuck rule; table and CSV
- ``wire``         the classroom-wide topics, their QoS, and message <-> record
- ``beacon``       inside each learner dashboard: publishes its progress, shows notices
- ``roster``       inside the ``classroom`` command: everyone's latest progress
- ``page``         the teacher page (its own viser server, port and token)
- ``status``       ``ros2-classroom classroom status``: the same table in a terminal

Progress travels on a domain every learner and the teacher share (the
*classroom domain*), carried by a second, small participant in each
dashboard (``app.ros.side_participant``); the learners' own domains stay
isolated.
"""
