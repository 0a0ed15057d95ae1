"""Raised when a launch file cannot be loaded."""


class InvalidLaunchFileError(Exception):
    def __init__(self, extension: str = "", *, likely_errors: list[Exception] | None = None):
        self._extension = extension
        self._likely_errors = likely_errors or []
        if self._likely_errors:
            detail = "\n".join(str(e) for e in self._likely_errors)
            message = f"Caught exception when trying to load file of format [{extension}]: {detail}"
        else:
            message = (
                f"The launch file may have a syntax error, or its format is unknown: [{extension}]"
            )
        super().__init__(message)

    @property
    def likely_errors(self) -> list[Exception]:
        return self._likely_errors
