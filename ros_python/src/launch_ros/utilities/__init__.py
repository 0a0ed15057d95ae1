"""Namespace helpers shared by Node and PushRosNamespace."""

from __future__ import annotations


def prefix_namespace(base_ns: str | None, ns: str | None) -> str | None:
    """``ns`` inside ``base_ns``; an absolute ``ns`` stands alone."""
    if base_ns is None or base_ns in ("", "/"):
        return ns if ns not in ("",) else base_ns
    if ns is None or ns == "":
        return base_ns
    if ns.startswith("/"):
        return ns
    return f"{base_ns.rstrip('/')}/{ns}"


def make_namespace_absolute(namespace: str | None) -> str | None:
    if namespace is None:
        return None
    return namespace if namespace.startswith("/") else "/" + namespace
