"""Every relative link in the Markdown docs resolves, and a moved page's links can be repaired."""

import importlib.util
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("docs_links", ROOT / "scripts" / "docs_links.py")
assert _spec and _spec.loader
docs_links = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(docs_links)


def test_every_relative_link_in_the_docs_resolves():
    broken = docs_links.check(ROOT, fix=False)
    assert not broken, "broken links (python scripts/docs_links.py --fix): " + "; ".join(broken)


def test_fix_follows_a_page_moved_into_the_archive(tmp_path):
    results = tmp_path / "docs" / "results"
    (results / "archive").mkdir(parents=True)
    (tmp_path / "docs" / "topic.md").write_text("see [old](results/old.md#why) and [web](https://x.org/a.md)\n")
    (results / "current.md").write_text("replaces [the old page](old.md)\n")
    (results / "archive" / "old.md").write_text("superseded by [current](current.md); [topic](../topic.md)\n")
    assert len(docs_links.check(tmp_path, fix=False)) == 4
    assert docs_links.check(tmp_path, fix=True) == []
    assert "(results/archive/old.md#why)" in (tmp_path / "docs" / "topic.md").read_text()
    assert "(archive/old.md)" in (results / "current.md").read_text()
    assert (results / "archive" / "old.md").read_text() == \
        "superseded by [current](../current.md); [topic](../../topic.md)\n"


def test_a_link_that_names_no_single_file_stays_broken(tmp_path):
    for folder in ("a", "b"):
        (tmp_path / "docs" / folder).mkdir(parents=True)
        (tmp_path / "docs" / folder / "page.md").write_text("x\n")
    (tmp_path / "docs" / "index.md").write_text("[p](page.md) [q](gone.md)\n")
    assert docs_links.check(tmp_path, fix=True) == ["docs/index.md: page.md", "docs/index.md: gone.md"]


def test_every_result_page_is_in_the_index():
    """docs/results/README.md names every page of docs/results/ and of its archive, so a reader
    finds the current page of a topic and nothing is left unlisted."""
    results = ROOT / "docs" / "results"
    index = (results / "README.md").read_text()
    pages = [p.relative_to(results).as_posix() for p in results.rglob("*.md") if p.name != "README.md"
             and "bench-" not in p.parent.name]
    missing = [p for p in pages if f"({p})" not in index and f"`{p}`" not in index]
    assert not missing, f"docs/results/README.md does not list {missing}: add each under its topic"
