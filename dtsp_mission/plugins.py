"""Loading plugins from entry-point groups: one mechanism for built-ins and third parties.

A plugin that fails to import, or is not what its group expects, is reported (logged, and
returned as the error) and skipped; it never breaks the rest.
"""

from __future__ import annotations

import logging
from importlib.metadata import entry_points
from typing import Callable

log = logging.getLogger(__name__)


#: The distribution whose entry points are the built-ins: a plugin of another distribution
#: registering the same name never replaces one.
BUILT_IN = "dtsp-mission"


def _distribution(entry_point) -> str:
    dist = entry_point.dist
    return dist.metadata["Name"] if dist is not None else "?"


def _in_order(group: str) -> list:
    """The entry points of ``group`` by name, a built-in before any other of its name."""
    return sorted(entry_points(group=group),
                  key=lambda e: (e.name, _distribution(e).lower() != BUILT_IN))


def clashes(group: str) -> list[tuple[str, str, str]]:
    """(name, distribution ignored, distribution kept) for every entry point of ``group``
    that registers a name another already has (a built-in's, or an earlier plugin's): it is
    ignored, and said so."""
    kept: dict[str, str] = {}
    found = []
    for entry_point in _in_order(group):
        owner = _distribution(entry_point)
        if entry_point.name in kept:
            found.append((entry_point.name, owner, kept[entry_point.name]))
        else:
            kept[entry_point.name] = owner
    return found


def load_group(group: str, accepts: Callable[[object], bool],
               expected: str) -> dict[str, object | Exception]:
    """Every entry point of ``group`` by name, loaded; a broken one maps to its error.  A
    built-in wins over a plugin of the same name (:func:`clashes`), whether or not that plugin
    loads.

    ``accepts`` says whether a loaded object is a valid plugin of the group; ``expected`` names
    what it should be, for the error message.
    """
    found: dict[str, object | Exception] = {}
    for entry_point in _in_order(group):
        if entry_point.name in found:
            log.warning("%s plugin %r of %s is ignored: the name is taken (built-ins win)",
                        group, entry_point.name, _distribution(entry_point))
            continue
        try:
            loaded = entry_point.load()
            if not accepts(loaded):
                raise TypeError(f"{entry_point.value} is not {expected}")
            found[entry_point.name] = loaded
        except Exception as error:  # a broken plugin must not break the program
            log.warning("%s plugin %r is broken: %r", group, entry_point.name, error)
            found[entry_point.name] = error
    return found


def load_one(group: str, name: str, accepts: Callable[[object], bool],
             expected: str) -> object | Exception | None:
    """The entry point ``name`` of ``group``, loaded alone (a built-in before a plugin of
    that name, as :func:`load_group` decides); its error if it is broken; None if there is
    none.  A command line loads only the command it runs."""
    for entry_point in _in_order(group):
        if entry_point.name != name:
            continue
        try:
            loaded = entry_point.load()
            if not accepts(loaded):
                raise TypeError(f"{entry_point.value} is not {expected}")
            return loaded
        except Exception as error:  # a broken plugin must not break the program
            log.warning("%s plugin %r is broken: %r", group, entry_point.name, error)
            return error
    return None


def origins(group: str) -> dict[str, str]:
    """For each entry point of ``group``, the distribution that provides it ("name version"),
    without loading anything."""
    found: dict[str, str] = {}
    for entry_point in _in_order(group):
        dist = entry_point.dist
        found.setdefault(entry_point.name,
                         f"{dist.metadata['Name']} {dist.version}" if dist is not None else "?")
    return found


def working(found: dict[str, object | Exception]) -> dict[str, object]:
    """The plugins of a :func:`load_group` result that loaded."""
    return {name: plugin for name, plugin in found.items() if not isinstance(plugin, Exception)}
