"""The errors dtsp-mission raises.

Every error derives from :class:`DtspError`; each subclass also derives from the built-in
exception a caller would naturally catch (``ValueError``, ``OSError``), so library users need
not know this module.  The CLI turns any :class:`DtspError` into a one-line message and exit
code 2; nothing else is caught there.
"""

from __future__ import annotations


class DtspError(Exception):
    """Root of every error raised deliberately by dtsp-mission."""


class InputError(DtspError, ValueError):
    """The user's input (targets, radius, options) cannot be planned as given."""


class MissionTooLarge(InputError):
    """The mission needs more items than the vehicle holds (``max_items``): ``needed``
    items (at least) against ``capacity``."""

    def __init__(self, message: str, needed: int = 0, capacity: int = 0) -> None:
        super().__init__(message)
        self.needed, self.capacity = needed, capacity


class FileFormatError(DtspError, ValueError):
    """A file could be read but its content is not what its format requires."""


class FileAccessError(DtspError, OSError):
    """A file could not be read or written."""


class TourInvalidError(DtspError, ValueError):
    """A tour failed the geometric checker; the message lists what failed."""


class LinkError(DtspError, OSError):
    """Talking to a vehicle failed: no heartbeat, a timeout, a rejected mission.

    ``on_vehicle`` says, as far as it is known, what the vehicle holds afterwards (an upload
    to ArduPilot is not atomic); empty when nothing is known.
    """

    def __init__(self, message: str, on_vehicle: str = "", nothing_sent: bool = False) -> None:
        super().__init__(message + (f"; {on_vehicle}" if on_vehicle else ""))
        self.reason = message
        self.on_vehicle = on_vehicle
        #: the vehicle refused the mission before asking for any item (MISSION_COUNT refused):
        #: by the mission protocol it keeps the mission it held
        self.nothing_sent = nothing_sent
