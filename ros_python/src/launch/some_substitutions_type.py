"""The types a substitution argument accepts: text, a substitution, or a sequence of both."""

from __future__ import annotations

from collections.abc import Iterable
from typing import Union

from .substitution import Substitution

SomeSubstitutionsType = Union[str, Substitution, Iterable[str | Substitution]]  # noqa: UP007
SomeSubstitutionsType_types_tuple = (str, Substitution)
