"""The data folder of the siconos stage (:func:`locate_data`): a given folder, ``$VERIMONO_SHARED``, or the Siconos
data shipped in the package."""

from __future__ import annotations

import os
from pathlib import Path

from ...core.errors import StageUnavailable
from ...lcs.siconos import PACKAGED_DATA, siconos_root


def locate_data(explicit: str | os.PathLike | None = None) -> Path:
    """The data folder of the siconos stage: ``explicit``, else ``$VERIMONO_SHARED`` if it is a folder, else
    the Siconos data shipped in the package (``verimono/data``); a given folder must hold that layout."""
    env = os.environ.get("VERIMONO_SHARED")
    if explicit is not None:
        path = Path(explicit)
    elif env and Path(env).is_dir():
        path = Path(env)
    else:
        return PACKAGED_DATA
    try:
        siconos_root(path)
    except FileNotFoundError as exc:
        raise StageUnavailable(f"data folder {path}: {exc}") from None
    return path
