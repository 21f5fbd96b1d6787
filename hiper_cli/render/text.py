"""Text a terminal shows as itself, one red error line, ``--json`` on stdout, the console."""

from __future__ import annotations

import json
import re
import sys
from collections.abc import Callable
from typing import Any

__all__ = ["console", "emit", "print_error", "print_json", "safe_text"]

# Terminal escape sequences (CSI ``ESC [ ... final``, OSC/DCS/APC/PM/SOS ``ESC ] ... BEL or ESC \``,
# two-byte ``ESC x``) and the C0/C1 controls other than newline and tab.
_ESCAPES = re.compile(
    r"\x1b\[[0-?]*[ -/]*[@-~]?"
    r"|[\x1b\x9b-\x9f][\]PX^_][^\x07\x1b\x9c]*(?:\x07|\x1b\\|\x9c)?"
    r"|\x1b[ -~]?"
    r"|[\x00-\x08\x0b-\x1f\x7f-\x9f]"
)


def safe_text(value: object, *, markup: bool = True) -> str:
    """``value`` as text that prints as itself: terminal escape sequences and control
    characters (except newline and tab) removed, lone surrogates replaced, and, for rich output
    (``markup``), ``[`` escaped so ``[bold]`` or ``[/]`` is shown rather than applied. Every
    user-supplied or stored string goes through it before rich prints it; the consoles here
    have emoji codes (``:x:``) off."""
    from rich.markup import escape

    text = _ESCAPES.sub("", str(value))
    text = text.encode("utf-8", "replace").decode("utf-8")  # a lone surrogate becomes '?'
    return escape(text) if markup else text


def print_error(message: str) -> None:
    """One red line on stderr."""
    from rich.console import Console

    # Escaped: a message such as "pip install 'hiper[view]'" keeps its brackets.
    Console(stderr=True, highlight=False, soft_wrap=True, emoji=False).print(
        f"[bold red]error:[/] {safe_text(message)}")


def print_json(data: Any) -> None:
    """``data`` as indented JSON on stdout (numpy values and paths included)."""
    from hiper_cli.model import json_default

    sys.stdout.write(json.dumps(data, indent=2, default=json_default) + "\n")


def console() -> Any:
    """The stdout console of the commands: no highlighting, no emoji codes (print user or
    stored strings through ``safe_text``)."""
    from rich.console import Console

    return Console(highlight=False, emoji=False)


def emit(data: Any, as_json: bool, show: Callable[[Any, Any], None]) -> None:
    """What every command ends with: ``data`` as JSON, or ``show(console, data)`` for people."""
    if as_json:
        print_json(data)
    else:
        show(console(), data)
