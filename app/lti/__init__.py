"""LTI 1.3 (LTI Advantage): how a school's LMS launches the classroom and gets its grades.

Pure Python, no ROS and no web server: the hub's teacher service (or the
classroom server) owns the routes and hands each request to these pieces.
The tool's private key and the score outbox live with that service only,
never in a learner's server or browser.
"""
