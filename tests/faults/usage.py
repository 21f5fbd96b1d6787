"""Usage errors: unknown commands, options and values (exit 2 with the usage line)."""

from __future__ import annotations

from tests.faults.case import Case
from tests.faults.case import argv as _argv


def cases() -> list[Case]:
    rows = [
        ("unknown-command", "nosuch", "usage line, 'no such command', exit 2"),
        ("unknown-command-typo", "perceve", "usage line, did you mean 'perceive', exit 2"),
        ("unknown-option", "perceive --nosuch {log}", "usage line, 'no such option', exit 2"),
        ("option-typo", "perceive --stage background {log}", "did you mean '--stages', exit 2"),
        ("missing-argument", "info", "usage line, 'missing argument', exit 2"),
        ("unknown-subcommand", "kb chek", "did you mean 'check', exit 2"),
        ("not-a-number", "sim --seed abc --out {root}/sim", "invalid value for --seed, exit 2"),
    ]
    return [Case(f"usage/{n}", "usage", _argv(a), "usage", b, kb=None) for n, a, b in rows]
