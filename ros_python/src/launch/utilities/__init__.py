"""Helpers shared by actions and substitutions (upstream's ``launch.utilities``)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

from ..launch_description_entity import LaunchDescriptionEntity
from ..substitution import Substitution

if TYPE_CHECKING:
    from ..launch_context import LaunchContext
    from ..some_substitutions_type import SomeSubstitutionsType

__all__ = [
    "normalize_to_list_of_entities",
    "normalize_to_list_of_substitutions",
    "perform_substitutions",
    "is_a",
    "is_a_subclass",
]


def normalize_to_list_of_substitutions(subs: SomeSubstitutionsType) -> list[Substitution]:
    """Text becomes a TextSubstitution; a sequence of text and substitutions stays in order."""
    from ..substitutions.text_substitution import TextSubstitution

    def one(item: Any) -> Substitution:
        if isinstance(item, Substitution):
            return item
        if isinstance(item, str):
            return TextSubstitution(text=item)
        if isinstance(item, (int, float, bool)):  # a common slip; upstream wants text
            return TextSubstitution(text=str(item))
        raise TypeError(
            f"Failed to normalize given item of type '{type(item).__name__}', when only "
            "'str' or 'launch.Substitution' were expected."
        )

    if isinstance(subs, (str, Substitution)):
        return [one(subs)]
    if isinstance(subs, Iterable):
        return [one(item) for item in subs]
    return [one(subs)]


def perform_substitutions(context: LaunchContext, subs: Iterable[Substitution]) -> str:
    return "".join(context.perform_substitution(sub) for sub in subs)


def normalize_to_list_of_entities(entities: Any) -> list[LaunchDescriptionEntity]:
    """One entity, a list of them, or nested lists, flattened into a list."""
    if entities is None:
        return []
    if isinstance(entities, LaunchDescriptionEntity):
        return [entities]
    flat: list[LaunchDescriptionEntity] = []
    for item in entities:
        flat.extend(normalize_to_list_of_entities(item))
    return flat


def is_a(obj: Any, entity_type: type) -> bool:
    return isinstance(obj, entity_type)


def is_a_subclass(obj: Any, entity_type: type) -> bool:
    return isinstance(obj, entity_type) or (isinstance(obj, type) and issubclass(obj, entity_type))


def ensure_argument_type(argument: Any, types: Any, argument_name: str, caller: str = "") -> None:
    """Raise TypeError naming the argument when it has the wrong type."""
    if not isinstance(types, (list, tuple)):
        types = [types]
    if not any(isinstance(argument, t) for t in types):
        names = ", ".join(repr(getattr(t, "__name__", str(t))) for t in types)
        where = f"{caller}: " if caller else ""
        raise TypeError(
            f"{where}Expected '{argument_name}' to be one of [{names}], "
            f"but got '{argument}' of type '{type(argument).__name__}'"
        )
