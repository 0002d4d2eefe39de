"""``dtsp-mission plugins``: what is installed in every plugin group, and what is broken."""

from __future__ import annotations

import json

import click

from ..export import EXPORTER_GROUP, exporters
from ..planning import PLANNER_GROUP, planners
from ..plugins import clashes, origins
from ..upload import UPLOADER_GROUP, uploaders
from .main import COMMAND_GROUP, commands

#: (group label, entry-point group, loader) for every plugin group, in pipeline order.
GROUPS = (("planners", PLANNER_GROUP, planners),
          ("exporters", EXPORTER_GROUP, exporters),
          ("uploaders", UPLOADER_GROUP, uploaders),
          ("commands", COMMAND_GROUP, commands))


def _summary(plugin: object) -> str:
    if isinstance(plugin, click.Command):
        return (plugin.get_short_help_str(70) if plugin.help else "")
    text = getattr(plugin, "description", "") or ""
    extensions = getattr(plugin, "extensions", ())
    return f"{text} ({', '.join(extensions)})" if extensions else text


def inventory() -> list[dict[str, str]]:
    """One record per installed plugin: group, name, distribution, state ("ok" or "broken"),
    and a summary (for a broken one, why it failed to load)."""
    records = []
    for label, group, load in GROUPS:
        provided_by = origins(group)
        for name, plugin in load().items():
            broken = isinstance(plugin, Exception)
            records.append({"group": label, "name": name, "distribution": provided_by.get(name, "?"),
                            "state": "broken" if broken else "ok",
                            "summary": repr(plugin) if broken else _summary(plugin)})
        for name, ignored, kept in clashes(group):
            records.append({"group": label, "name": name, "distribution": ignored,
                            "state": "ignored", "summary": f"the name is {kept}'s"})
    return records


@click.command()
@click.option("--json", "as_json", is_flag=True, help="Print the list as JSON.")
def plugins(as_json: bool) -> None:
    """List installed planners, exporters, uploaders and commands, built-in or third-party, with
    the distribution that provides each; broken plugins are listed with the reason (and skipped
    everywhere else).

    Example: dtsp-mission plugins
    """
    records = inventory()
    if as_json:
        click.echo(json.dumps(records, indent=2))
        return
    for label, _, _ in GROUPS:
        click.echo(f"{label}:")
        rows = [r for r in records if r["group"] == label]
        name_width = max((len(r["name"]) for r in rows), default=0)
        dist_width = max((len(r["distribution"]) for r in rows), default=0)
        for r in rows:
            state = "BROKEN: " if r["state"] == "broken" else ""
            click.echo(f"  {r['name']:<{name_width}}  {r['distribution']:<{dist_width}}  "
                       f"{state}{r['summary']}")
    broken = sum(r["state"] == "broken" for r in records)
    if broken:
        click.echo(f"{broken} broken plugin(s): skipped by every command.", err=True)
    for label, group, _ in GROUPS:
        for name, ignored, kept in clashes(group):
            click.echo(f"{label}: {name!r} of {ignored} is ignored: {kept} already provides "
                       f"{name!r} (a built-in is never replaced)", err=True)
