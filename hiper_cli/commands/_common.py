"""Re-exports of ``hiper_cli.cmdline`` under their former path (commands written against it)."""

from hiper_cli.cmdline import (
    DEFAULT_KB,
    JSON_OPTION,
    LOG_ARGUMENT,
    LOG_FLAGS,
    KbDocsOption,
    KbOption,
    with_log_flags,
)

__all__ = ["DEFAULT_KB", "JSON_OPTION", "LOG_ARGUMENT", "LOG_FLAGS", "KbDocsOption", "KbOption",
           "with_log_flags"]
