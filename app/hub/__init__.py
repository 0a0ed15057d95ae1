"""Serving the dashboard through Jupyter: a learner's own dashboard behind the hub's login."""
