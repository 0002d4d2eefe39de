"""The ``dtsp-mission`` command group.

Every command, built-in or third-party, is registered in the ``dtsp_mission.commands``
entry-point group and loaded through it, so the plugin path runs on every start.  A command
that fails to load is listed as broken (with the reason, under ``-v``) and the rest still work.
"""

from __future__ import annotations

import logging

import click

from .. import __version__
from ..plugins import load_group, load_one

COMMAND_GROUP = "dtsp_mission.commands"


def commands() -> dict[str, click.Command | Exception]:
    """Installed commands by name; a plugin that fails to load maps to its error."""
    return load_group(COMMAND_GROUP, lambda c: isinstance(c, click.Command), "a click command")


def _broken_command(name: str, error: BaseException) -> click.Command:
    @click.command(name=name, help=f"(broken plugin: {error.__class__.__name__})")
    def broken() -> None:
        raise click.ClickException(f"the '{name}' command could not be loaded: {error!r}")
    return broken


class PluginGroup(click.Group):
    """A click group whose commands come from the ``dtsp_mission.commands`` entry-point group,
    loaded on first use."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self._loaded = False

    def _load(self) -> None:
        if self._loaded:
            return
        self._loaded = True
        for name, command in commands().items():
            if name in self.commands:
                continue
            if isinstance(command, Exception):
                command = _broken_command(name, command)
            self.add_command(command, name)

    def list_commands(self, ctx: click.Context) -> list[str]:
        self._load()
        return super().list_commands(ctx)

    def get_command(self, ctx: click.Context, name: str) -> click.Command | None:
        # only the command asked for is imported: a command line starts in a fraction of
        # the time all of them take
        if name not in self.commands and not self._loaded:
            command = load_one(COMMAND_GROUP, name, lambda c: isinstance(c, click.Command),
                               "a click command")
            if command is None:
                self._load()               # unknown: click lists the others
            else:
                self.add_command(_broken_command(name, command)
                                 if isinstance(command, Exception) else command, name)
        return super().get_command(ctx, name)


@click.group(cls=PluginGroup,
             context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="dtsp-mission")
@click.option("-v", "--verbose", count=True, help="More log output (repeatable).")
@click.option("-q", "--quiet", is_flag=True, help="Only errors.")
def cli(verbose: int, quiet: bool) -> None:
    """Plan Dubins tours through many targets for fixed-wing UAVs and turn them into MAVLink
    missions."""
    level = logging.ERROR if quiet else (logging.DEBUG if verbose > 1 else
                                         logging.INFO if verbose else logging.WARNING)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
