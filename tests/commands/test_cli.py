"""The CLI answers --help quickly, documents every command with an example, and exits cleanly."""

import subprocess
import sys

import pytest
import typer.main
from typer.testing import CliRunner

from hiper_cli import __version__
from hiper_cli.cli import app

runner = CliRunner()


def _all_commands():
    root = typer.main.get_command(app)
    stack = [((), root)]
    while stack:
        path, cmd = stack.pop()
        if hasattr(cmd, "commands"):  # a group (typer's own group class is no click.Group)
            for name, sub in cmd.commands.items():
                stack.append(((*path, name), sub))
        else:
            yield path, cmd


def test_version():
    result = runner.invoke(app, ["--version"])
    assert result.exit_code == 0
    assert __version__ in result.output


COMMANDS = list(_all_commands())


def test_command_tree_is_discovered():
    names = {" ".join(path) for path, _ in COMMANDS}
    assert {"info", "perceive", "sim", "kb info", "eval background", "eval foreground"} <= names


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_every_command_has_an_example(path, cmd):
    assert "Example:" in (cmd.help or ""), f"hiper {' '.join(path)} has no 'Example:' in its help"


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_every_command_is_listed_in_whole_lines(path, cmd):
    # the list of commands shows this text; a docstring's own line breaks would cut it mid-line
    first = (cmd.help or "").split("\n\n")[0]
    assert cmd.short_help == " ".join(first.split()), f"hiper {' '.join(path)}: short help"


def test_help_does_not_import_heavy_packages():
    code = (
        "import sys; from hiper_cli.cli import app; "
        "heavy = [m for m in ('numpy', 'open3d', 'pyoxigraph', 'onnxruntime', 'scipy') "
        "if m in sys.modules]; "
        "print(','.join(heavy))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "", f"hiper --help imports {out.stdout.strip()}"


@pytest.mark.parametrize("path,cmd", COMMANDS, ids=[" ".join(p) for p, _ in COMMANDS])
def test_install_hints_keep_their_extra(path, cmd):
    """Rich markup reads "[mcp]" as a style tag; a help text must escape it or lose it."""
    result = runner.invoke(app, [*path, "--help"], terminal_width=200)
    assert result.exit_code == 0
    assert "pip install 'hiper'" not in result.output, f"hiper {' '.join(path)} --help drops an extra's name"
