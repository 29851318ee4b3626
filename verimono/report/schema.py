"""The JSON schema of ``results.json`` and ``baseline.json``: saving and loading live in
:mod:`verimono.results` (its docstring states the layout); this module re-exports their names."""

from __future__ import annotations

from ..errors import SchemaError
from ..results import (OPTIONAL, SCHEMA_NAME, SCHEMA_VERSION, VERSIONED, check_compatible, environment, load,
                       loads, report_from_dict, report_to_dict)

__all__ = ["SCHEMA_NAME", "SCHEMA_VERSION", "VERSIONED", "OPTIONAL", "SchemaError", "environment",
           "report_to_dict", "report_from_dict", "check_compatible", "loads", "load"]
