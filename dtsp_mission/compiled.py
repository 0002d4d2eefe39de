"""Whether the compiled kernels are cached on this machine, so a command can say that its
first run compiles them (numba takes about 40 s of CPU the first time, nothing after)."""

from __future__ import annotations

import os
from pathlib import Path

#: The largest compiled module; its cache is there only after a first full compilation.
_PROBE = ("planning", "improve")


def kernels_cached() -> bool:
    """True when numba's cache holds the improver's kernels (where numba looks for it:
    ``NUMBA_CACHE_DIR``, else the package's ``__pycache__``, else the user's cache)."""
    package = Path(__file__).resolve().parent
    folder, module = _PROBE
    places = []
    if os.environ.get("NUMBA_CACHE_DIR"):
        places.append(Path(os.environ["NUMBA_CACHE_DIR"]))
    else:
        places += [package / folder / "__pycache__",
                   Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "numba"]
    return any(next(place.rglob(f"{module}.*.nbi"), None) is not None
               for place in places if place.is_dir())
