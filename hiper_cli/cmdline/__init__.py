"""The command line's shared parts: the typer app class, the options several commands share,
the log flags, usage errors and option value parsers.

The commands in ``hiper_cli.commands`` declare their own options and call one library
function each; what they share lives here so each command module stays a few lines. Only the
commands and ``cli.py`` import it: it sits above the library, beside ``hiper_cli.render``.
"""

from hiper_cli.cmdline.app import HiperTyper, group
from hiper_cli.cmdline.log_flags import LOG_FLAGS, with_log_flags
from hiper_cli.cmdline.options import (
    DEFAULT_KB,
    JSON_OPTION,
    LOG_ARGUMENT,
    Json,
    Kb,
    KbDocs,
    KbDocsOption,
    KbOption,
    Log,
)
from hiper_cli.cmdline.values import keep_duration_s

__all__ = ["DEFAULT_KB", "JSON_OPTION", "LOG_ARGUMENT", "LOG_FLAGS", "HiperTyper", "Json", "Kb", "KbDocs",
           "KbDocsOption", "KbOption", "Log", "group", "keep_duration_s", "with_log_flags"]
