"""Where the real autopilots' SITL builds are: ``DTSP_SITL_DIR`` (a folder holding
``arduplane-sitl-bin/`` and ``px4-sitl-bin/``), else a ``shared/`` folder beside or above the
working directory or this package's checkout (how the workplace lays them out)."""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

ARDUPLANE_DIR = "arduplane-sitl-bin"
PX4_DIR = "px4-sitl-bin"


@dataclass(frozen=True)
class SitlBinaries:
    """The folders of the two builds (None where absent) and why one was not found."""

    arduplane: Path | None
    px4: Path | None
    searched: tuple[Path, ...]

    def missing(self, autopilot: str) -> str | None:
        """None if ``autopilot`` ("ardupilot" or "px4") can be flown, else why not."""
        found = self.arduplane if autopilot == "ardupilot" else self.px4
        if found is not None:
            return None
        name = ARDUPLANE_DIR if autopilot == "ardupilot" else PX4_DIR
        return (f"no {name}/ in {', '.join(str(p) for p in self.searched) or 'any place searched'} "
                "(set DTSP_SITL_DIR to the folder holding it)")


def _candidates() -> list[Path]:
    places = []
    if os.environ.get("DTSP_SITL_DIR"):
        places.append(Path(os.environ["DTSP_SITL_DIR"]))
    for start in (Path.cwd(), Path(__file__).resolve().parents[2]):
        for folder in (start, *start.parents[:3]):
            places.append(folder / "shared")
            places.append(folder.parent / "shared")
    seen, unique = set(), []
    for place in places:
        if place not in seen:
            seen.add(place)
            unique.append(place)
    return unique


def _usable(folder: Path, executable: str) -> bool:
    binary = folder / executable
    return binary.is_file() and os.access(binary, os.X_OK)


def find_binaries() -> SitlBinaries:
    """The SITL builds found (each checked to hold its executable)."""
    places = _candidates()
    arduplane = next((p / ARDUPLANE_DIR for p in places
                      if _usable(p / ARDUPLANE_DIR, "arduplane")), None)
    px4 = next((p / PX4_DIR for p in places if _usable(p / PX4_DIR, "bin/px4")
                and (p / PX4_DIR / "start.sh").is_file()), None)
    return SitlBinaries(arduplane, px4, tuple(p for p in places if p.is_dir()))
