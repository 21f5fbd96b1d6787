"""Re-exports of ``hiper_cli.render`` and ``hiper_cli.cmdline`` under their former path."""

from hiper_cli.cmdline import JSON_OPTION, HiperTyper, group
from hiper_cli.cmdline.usage import is_usage_error, print_usage_error
from hiper_cli.render import console, frame_progress, print_error, print_json, safe_text

__all__ = ["JSON_OPTION", "HiperTyper", "console", "frame_progress", "group", "is_usage_error", "print_error",
           "print_json", "print_usage_error", "safe_text"]
