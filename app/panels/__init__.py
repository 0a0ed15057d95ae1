"""Browser panels that do what rqt and the ros2 tools do, one concept each.

A panel owns its viser handles and follows the threading model written in
app.ui: callbacks post intents, jobs wait on ROS, the UI thread owns state.
"""
