"""The README's figures block is written by scripts/readme_figures.py: its block replacement, its
rendering, and that the README holds exactly what the figures file renders (nothing typed)."""

import importlib.util
import json
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("readme_figures", ROOT / "scripts" / "readme_figures.py")
assert _spec and _spec.loader
figures = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(figures)

FIGURES = {
    "kb": {"rows": [["knowledge base", "`hiper kb bench`", "15 k obs/s", ""]], "source": "run B"},
    "background": {"rows": [["per keyframe", "`hiper eval background LOG`", "0.016 s", "0.2 s | i9"]],
                   "source": "run A"},
}


def test_render_orders_sections_escapes_pipes_and_names_each_source():
    block = figures.render(FIGURES)
    lines = block.splitlines()
    assert lines[:2] == figures.HEADER
    assert lines[2] == "| per keyframe | `hiper eval background LOG` | 0.016 s | 0.2 s \\| i9 |"
    assert lines[3].startswith("| knowledge base |")
    assert block.index("- background: run A") < block.index("- kb: run B")


def test_replace_block_changes_only_what_lies_between_the_markers():
    text = f"# t\n\nbefore\n{figures.BEGIN}\nold | typed\n{figures.END}\n\nafter\n"
    new = figures.replace_block(text, "NEW")
    assert new == f"# t\n\nbefore\n{figures.BEGIN}\nNEW\n{figures.END}\n\nafter\n"
    assert figures.replace_block(new, "NEW") == new


@pytest.mark.parametrize("text", [
    "no markers\n",
    f"{figures.BEGIN}\nonly the start\n",
    f"{figures.END}\n{figures.BEGIN}\n",
    f"{figures.BEGIN}\na\n{figures.END}\n{figures.BEGIN}\nb\n{figures.END}\n",
])
def test_replace_block_refuses_a_text_without_one_pair_of_markers(text):
    with pytest.raises(ValueError, match="figures:begin"):
        figures.replace_block(text, "NEW")


def test_the_readme_block_is_what_the_figures_file_renders():
    readme = (ROOT / "README.md").read_text()
    stored = json.loads((ROOT / "docs" / "readme_figures.json").read_text())
    assert figures.replace_block(readme, figures.render(stored)) == readme, \
        "README.md's figures were edited by hand: run python scripts/readme_figures.py --render-only"
