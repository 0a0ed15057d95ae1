"""Raised when a substitution cannot be performed (a missing variable, a failed command)."""


class SubstitutionFailure(RuntimeError):
    pass
