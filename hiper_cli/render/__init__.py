"""How results look on a terminal: rich tables and lines for people, JSON for machines.

One presentation layer on top of the library and below the commands: each ``show_*`` takes a
result's ``to_dict()`` form, the data ``--json`` prints, so what a person reads and what a
machine reads cannot drift apart. The library packages never import it (nor rich), so the MCP
server and Python users get the same results without a terminal. The modules are named after
the package whose results they show (``render.evaluate`` shows ``hiper_cli.evaluate``'s).
"""

from hiper_cli.render.progress import FrameBar, download_bar, frame_progress, log_bars, unit_progress
from hiper_cli.render.text import console, emit, print_error, print_json, safe_text

__all__ = ["FrameBar", "console", "download_bar", "emit", "frame_progress", "log_bars", "print_error",
           "print_json", "safe_text", "unit_progress"]
