"""Options shared by several commands, defined once so a flag means the same everywhere, and
the one place where library errors become CLI errors."""

from __future__ import annotations

import functools
from typing import Callable

import click

from ..errors import DtspError


class UserError(click.ClickException):
    """A message for the user and exit code 2, with nothing half-written."""

    exit_code = 2


def reports_errors(function: Callable) -> Callable:
    """Turn :class:`DtspError` raised inside a command into a :class:`UserError`."""
    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except DtspError as error:
            raise UserError(str(error)) from None
    return wrapper


radius_option = click.option(
    "--radius", "rho_m", type=float, required=True, metavar="METRES",
    help="Minimum turn radius rho of the aircraft, in metres.")
seed_option = click.option("--seed", type=int, default=0, show_default=True,
                           help="Seed of every random choice; the same seed gives the same result.")
