"""MAVSDK's log, kept to what a user should see."""

from __future__ import annotations

_installed = False


def quiet_mavsdk_log() -> None:
    """Show only MAVSDK's errors, except the send failures of a link being torn down.

    Subscribes once per process, before the first MAVSDK instance: MAVSDK's threads may be
    logging through the callback, and replacing it under them frees what they call."""
    global _installed
    if _installed:
        return
    from mavsdk.logging import LogLevel, log_subscribe

    def handled(level, message, file, line) -> bool:   # True: MAVSDK does not print it
        return level < LogLevel.ERROR or "Sending message failed" in str(message)

    log_subscribe(handled)
    _installed = True
