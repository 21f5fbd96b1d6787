"""Hostile text shown to the user: rich markup (``[/]``, ``[bold]``), emoji codes (``:x:``) and
terminal escape sequences (OSC, CSI) in stored class and environment names, in queries and in
paths, over the tables and every command's error path. What is printed must show the text as
itself (markup and emoji codes literal) and hold no escape or control character.
"""

from __future__ import annotations

from collections.abc import Callable

from tests.faults import inputs
from tests.faults.case import Case
from tests.faults.runner import Result, Workspace

MARKUP = "[/] [bold]x[/bold] :x:"
ESCAPES = "\x1b]0;pwned\x07\x1b]8;;http://evil.example\x07link\x1b]8;;\x07\x1b[31m"
HOSTILE = MARKUP + ESCAPES
SHOWN = ("[/]", "[bold]x[/bold]", ":x:")
HOSTILE_KB = "{root}/m.hiper"
# a path named after the hostile text (braces would be format fields: there are none)
HOSTILE_PATH = "{root}/" + HOSTILE.replace("/", "|")


def _hostile_kb(ws: Workspace) -> None:
    """A knowledge base whose class and environment names are the hostile text."""
    doc = inputs.export_doc(
        instances=[inputs._instance(**{"class": HOSTILE})],
        environments=[{"uuid": inputs.ENV_UUID, "name": HOSTILE}],
    )
    inputs.write_json(ws.root / "hostile.json", doc)
    result = ws.hiper("import", "{root}/hostile.json", "--kb", HOSTILE_KB)
    if result.returncode != 0:
        raise RuntimeError(result.stderr)


def _perceived_with_env(ws: Workspace) -> None:
    result = ws.hiper("perceive", "{log}", "--kb", "{root}/e.hiper", "--detector", "truth", "--env", HOSTILE,
                      "--json")
    if result.returncode != 0:
        raise RuntimeError(result.stderr)


def _shown_as_text(*must_show: str) -> Callable[[Workspace, Result], str | None]:
    def check(ws: Workspace, result: Result) -> str | None:
        text = result.stdout + result.stderr
        controls = sorted({f"{ord(c):#x}" for c in text
                           if (ord(c) < 32 and c not in "\n\t") or 0x7f <= ord(c) < 0xa0})
        problems = [f"control characters printed: {controls}"] if controls else []
        if "\u274c" in text:
            problems.append("':x:' became an emoji")
        missing = [m for m in must_show if m not in text]
        if missing:
            problems.append(f"not shown as text: {missing}")
        return "; ".join(problems) or None

    return check


STORED = {
    "kb-info": ("kb", "info", "--kb", HOSTILE_KB),
    "describe": ("describe", "--kb", HOSTILE_KB),
    "query-workspace": ("query", "workspace", "--center", "1,2,0.5", "--size", "2", "--kb", HOSTILE_KB),
    "query-sparql": ("query", "--sparql", "SELECT ?c WHERE {{ ?i hiper:className ?c }}", "--kb", HOSTILE_KB),
}
# commands whose output names no class or environment: nothing hostile to show, none printed
QUIET = {
    "kb-check": ("kb", "check", "--kb", HOSTILE_KB),
    "export": ("export", "{root}/out.graphml", "--kb", HOSTILE_KB),
}
# every command that takes a path, given the hostile one: one line naming it as text
ERROR_PATHS = {
    "info": ("info", HOSTILE_PATH),
    "perceive": ("perceive", HOSTILE_PATH, "--kb", "{root}/new.hiper"),
    "convert": ("convert", HOSTILE_PATH, "{root}/out.bag", "--to", "rosbag1"),
    "export": ("export", "{root}/out.json", "--kb", HOSTILE_PATH),
    "import": ("import", HOSTILE_PATH, "--kb", "{root}/new.hiper"),
    "kb-info": ("kb", "info", "--kb", HOSTILE_PATH),
    "kb-check": ("kb", "check", "--kb", HOSTILE_PATH),
    "describe": ("describe", "--kb", HOSTILE_PATH),
    "query": ("query", "cups", "--kb", HOSTILE_PATH),
    "query-sparql-file": ("query", "--sparql", HOSTILE_PATH, "--kb", "{kb}"),
    "analyze-features": ("analyze", "features", "--kb", HOSTILE_PATH),
    "analyze-heatmap": ("analyze", "heatmap", "--kb", HOSTILE_PATH),
    "analyze-map": ("analyze", "map", "-o", "{root}/map.yaml", "--kb", HOSTILE_PATH),
    "reanchor": ("reanchor", "--kb", HOSTILE_PATH, "--poses", "{log}/groundtruth.txt"),
    "serve": ("serve", "--kb", HOSTILE_PATH, "--port", "0"),
    "view": ("view", "--kb", HOSTILE_PATH, "--png", "{root}/v.png"),
    "eval-foreground": ("eval", "foreground", HOSTILE_PATH),
}
# hostile text as an option value or query
ERROR_VALUES: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "query-words": (("query", HOSTILE, "--kb", "{kb}"), SHOWN),
    "sparql-text": (("query", "--sparql", "SELECT " + HOSTILE, "--kb", "{kb}"), ()),
    "perceive-classes": (("perceive", "{log}", "--kb", "{root}/new.hiper", "--detector", "truth",
                          "--classes", HOSTILE), (":x:",)),
    "heatmap-class": (("analyze", "heatmap", "--class", HOSTILE, "--kb", "{kb}"), (":x:",)),
    "export-format": (("export", "{root}/out.json", "--format", HOSTILE, "--kb", "{kb}"), (":x:",)),
}


def cases() -> list[Case]:
    out = [
        Case(f"markup/stored-{name}", "markup", args, "ok",
             "class and environment names shown as text: markup and :x: literal, escapes removed",
             prepare=_hostile_kb, check=_shown_as_text(*SHOWN), kb=None)
        for name, args in STORED.items()
    ]
    out += [
        Case(f"markup/stored-{name}", "markup", args, "ok", "no escape or control character printed",
             prepare=_hostile_kb, check=_shown_as_text(), kb=None)
        for name, args in QUIET.items()
    ]
    out.append(Case("markup/stored-env-from-perceive", "markup", ("describe", "--kb", "{root}/e.hiper"), "ok",
                    "an --env name with markup and escapes shown as text", prepare=_perceived_with_env,
                    check=_shown_as_text(*SHOWN), kb=None))
    out += [
        Case(f"markup/error-path-{name}", "markup", args, "error",
             "one error line naming the path as text: markup and :x: literal, escapes removed",
             check=_shown_as_text(":x:", "[bold]x["), kb=None, timeout_s=60.0)
        for name, args in ERROR_PATHS.items()
    ]
    out += [
        Case(f"markup/error-value-{name}", "markup", args, "error",
             "one error line quoting the value as text", check=_shown_as_text(*shown), timeout_s=60.0)
        for name, (args, shown) in ERROR_VALUES.items()
    ]
    return out
