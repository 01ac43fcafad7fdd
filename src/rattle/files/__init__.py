"""Files: the primitives every layer writes and reads with — atomic writes and output sets, CSV
tables, bounded reads of input files, run metadata. They know nothing of rattle's models, results
or configuration (they import only :mod:`rattle.errors`), so the results' ``.to_csv()``, the maps'
store and the command line use them without reaching the configuration reader
(:mod:`rattle.io`, which re-exports them under their public names).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

#: Public name → the module that defines it, imported on first use (PEP 562): the command line
#: reaches ``._read`` and ``._atomic`` without numpy, which ``._csv`` and ``._metadata`` need.
_LAZY: dict[str, str] = {
    **dict.fromkeys(["STAGING_PREFIX", "OutputSet", "atomic_path", "atomic_write_bytes", "atomic_write_text",
                     "recover_staging", "RecoveryWarning", "WriteError", "describe_os_error"], "._atomic"),
    **dict.fromkeys(["format_csv", "read_csv", "write_csv"], "._csv"),
    **dict.fromkeys(["MAX_CONFIG_BYTES", "MAX_TOML_DEPTH", "MAX_KEY_PARTS", "MAX_CSV_FIELD", "read_bounded", "read_toml",
                     "check_input_file", "check_toml_bounds", "csv_rows"], "._read"),
    **dict.fromkeys(["environment", "metadata_document", "rattle_version", "to_jsonable", "write_metadata"],
                    "._metadata"),
}


if TYPE_CHECKING:
    from ._atomic import (
        STAGING_PREFIX, OutputSet, atomic_path, atomic_write_bytes, atomic_write_text, RecoveryWarning,
        WriteError, describe_os_error, recover_staging,
    )
    from ._csv import format_csv, read_csv, write_csv
    from ._metadata import environment, metadata_document, rattle_version, to_jsonable, write_metadata
    from ._read import (
        MAX_CONFIG_BYTES, MAX_CSV_FIELD, MAX_KEY_PARTS, MAX_TOML_DEPTH, check_input_file, check_toml_bounds, csv_rows,
        read_bounded, read_toml,
    )

__all__ = [
    "MAX_CONFIG_BYTES", "MAX_CSV_FIELD", "MAX_KEY_PARTS", "MAX_TOML_DEPTH", "check_toml_bounds", "csv_rows",
    "OutputSet", "STAGING_PREFIX", "atomic_path", "atomic_write_bytes", "atomic_write_text",
    "check_input_file", "environment", "format_csv", "metadata_document", "rattle_version", "read_bounded",
    "read_csv", "read_toml", "recover_staging", "RecoveryWarning", "to_jsonable", "write_csv", "write_metadata",
    "WriteError", "describe_os_error",
]

__getattr__, __dir__ = lazy_exports(__name__, globals(), _LAZY, __all__)
