"""Events travel through the launch service's queue to the event handlers."""


class Event:
    name = "launch.event.Event"

    def __repr__(self) -> str:
        return f"<{type(self).__name__}>"
