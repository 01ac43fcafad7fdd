"""Input and output: the configuration file, sound-path and measured tables — and, under their
public names, the file primitives of :mod:`rattle.files` (CSV tables, run metadata, atomic writes).

The numerical core never touches files; everything that reads or writes lives here or in
:mod:`rattle.files`.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import lazy_exports

#: Public name → the module that defines it, or for the file primitives their public home
#: :mod:`rattle.files` (itself lazy). Imported on first use (PEP 562): the command line reaches the
#: bounded reads and atomic writes without numpy, which ``._config`` (the model) and the CSV and
#: metadata primitives need.
_LAZY: dict[str, str] = {
    **dict.fromkeys(["STAGING_PREFIX", "OutputSet", "atomic_path", "atomic_write_bytes", "atomic_write_text",
                     "recover_staging", "RecoveryWarning"], "..files"),
    **dict.fromkeys(["DEFAULT_HARMONICS", "DEFAULT_OMEGA", "AnalysisSettings", "RunConfig", "check_harmonics",
                     "config_from_dict", "dumps_toml", "load_config", "model_to_toml_dict",
                     "rename_keys"], "._config"),
    **dict.fromkeys(["format_csv", "read_csv", "write_csv"], "..files"),
    **dict.fromkeys(["read_path_csv", "PATH_COLUMNS"], "._paths"),
    **dict.fromkeys(["read_measured_csv", "parse_measured_csv", "MeasuredTable", "MEASURED_SPEED_COLUMNS",
                     "MEASURED_VALUE_COLUMNS"], "._measured"),
    **dict.fromkeys(["MAX_CONFIG_BYTES", "read_bounded", "check_input_file"], "..files"),
    **dict.fromkeys(["environment", "metadata_document", "rattle_version", "to_jsonable", "write_metadata"],
                    "..files"),
}


#: Names that moved out of ``rattle.io``: the column lists are the results' own (SPEC §3 columns
#: of the result attributes). Still served here, with a DeprecationWarning.
_MOVED: dict[str, str] = dict.fromkeys(["FRF_COLUMNS", "ORBIT_COLUMNS", "SWEEP_COLUMNS"], "rattle.results")


if TYPE_CHECKING:
    from ..files import (
        MAX_CONFIG_BYTES, STAGING_PREFIX, OutputSet, RecoveryWarning, atomic_path, atomic_write_bytes,
        atomic_write_text, check_input_file, environment, format_csv, metadata_document, rattle_version, read_bounded,
        read_csv, recover_staging, to_jsonable, write_csv, write_metadata,
    )
    from ._config import (
        DEFAULT_HARMONICS, DEFAULT_OMEGA, AnalysisSettings, RunConfig, check_harmonics, config_from_dict, dumps_toml,
        load_config, model_to_toml_dict, rename_keys,
    )
    from ._paths import PATH_COLUMNS, read_path_csv
    from ._measured import (
        MEASURED_SPEED_COLUMNS, MEASURED_VALUE_COLUMNS, MeasuredTable, parse_measured_csv, read_measured_csv,
    )

__all__ = [
    # configuration
    "load_config", "config_from_dict", "RunConfig", "AnalysisSettings",
    "DEFAULT_OMEGA", "DEFAULT_HARMONICS", "model_to_toml_dict", "dumps_toml", "rename_keys",
    "check_harmonics",
    # csv
    "write_csv", "read_csv", "format_csv",
    # sound path tables ([[paths]], SPEC §6)
    "read_path_csv", "PATH_COLUMNS",
    # measured run-ups (rattle compare --measured)
    "read_measured_csv", "parse_measured_csv", "MeasuredTable", "MEASURED_SPEED_COLUMNS", "MEASURED_VALUE_COLUMNS",
    # metadata
    "write_metadata", "metadata_document", "to_jsonable", "rattle_version", "environment",
    # atomic writes, output sets, bounded reads
    "atomic_write_text", "atomic_write_bytes", "atomic_path", "OutputSet", "recover_staging", "RecoveryWarning",
    "STAGING_PREFIX",
    "read_bounded", "check_input_file", "MAX_CONFIG_BYTES",
]

__getattr__, __dir__ = lazy_exports(__name__, globals(), _LAZY, __all__, _MOVED)
