"""ament_copyright: does every source file carry a copyright notice? (our Python version)

``ros2 pkg create`` writes ``test/test_copyright.py``, which imports
``ament_copyright.main.main``; there is no wheel of it, so ``colcon test``
of a fresh package would fail on that import. This is the check as the test
uses it: ``main(argv=['.', 'test'])`` returns 0 when every non-empty Python
file under those paths has a copyright line near its top.
"""
