"""Exercises: the learner writes a node, runs it as a real process, and is graded on the graph.

- ``model``: exercise files (``lessons/NN_slug/exercises/<slug>/``), validated at load;
- ``workspace``: the learner's code on disk (never lost) and their attempts;
- ``lint``: compile + pyflakes before a Run;
- ``runner``: the learner's file as a supervised process (contained when serving others);
- ``grader`` + ``probes``: the lessons' checks plus probes that drive the node;
- ``panel``: the Exercise tab; ``editor``: the code editor page it embeds;
- ``cli``: ``ros2-classroom exercise list|starter|solution|check``.
"""
