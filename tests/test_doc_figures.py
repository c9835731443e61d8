"""The figures of README.md and docs/: every image link points at a file that exists, every
figure docs/figures/make.py draws is linked from a page, and CI runs the script (the README's
test command, which .ci/run executes)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
FIGURES = ROOT / "docs" / "figures"
#: markdown image links ``![alt](target)`` and HTML ``<img src="target">``
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|<img[^>]+src=\"([^\"]+)\"")


def _pages() -> list[Path]:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def image_links(page: Path) -> list[tuple[int, str]]:
    """(line number, target) of every image link of a markdown page."""
    out = []
    for i, line in enumerate(page.read_text(encoding="utf-8").splitlines(), start=1):
        for m in IMAGE.finditer(line):
            out.append((i, m.group(1) or m.group(2)))
    return out


def test_the_link_pattern_finds_markdown_and_html_images(tmp_path):
    p = tmp_path / "x.md"
    p.write_text('text ![a](figures/a.png) and ![b](b.png "title")\n<img src="c.png" alt="c">\n')
    assert image_links(p) == [(1, "figures/a.png"), (1, "b.png"), (2, "c.png")]


def test_every_image_link_points_at_a_file():
    missing = []
    n = 0
    for page in _pages():
        for line, target in image_links(page):
            n += 1
            if re.match(r"[a-z]+://", target):
                missing.append(f"{page.relative_to(ROOT)}:{line}: {target} (a remote image)")
                continue
            if not (page.parent / target).is_file():
                missing.append(f"{page.relative_to(ROOT)}:{line}: {target}")
    assert not missing, "image links to missing files:\n" + "\n".join(missing)
    assert n >= 3  # the README's three figures at least


def test_the_readme_shows_the_three_figures():
    targets = {t for _, t in image_links(ROOT / "README.md")}
    for name in ("lobes_verdicts.png", "posture_map.png", "fe_chip.png"):
        assert f"docs/figures/{name}" in targets, name


def _drawn_names() -> set[str]:
    """The PNG names make.py writes (string constants ending in .png in its source)."""
    tree = ast.parse((FIGURES / "make.py").read_text(encoding="utf-8"))
    return {n.value.rsplit("/", 1)[-1] for n in ast.walk(tree)
            if isinstance(n, ast.Constant) and isinstance(n.value, str)
            and n.value.endswith(".png") and "*" not in n.value}


def test_every_drawn_figure_is_committed_and_linked():
    linked = {Path(t).name for page in _pages() for _, t in image_links(page)}
    drawn = _drawn_names()  # includes the names of the plots it copies from
    written = {p.name for p in FIGURES.glob("*.png")}
    assert {"lobes_verdicts.png", "posture_map.png", "fe_chip.png"} <= written
    unlinked = sorted(written - linked)
    assert not unlinked, f"figures in docs/figures that no page shows: {unlinked}"
    assert written <= drawn, f"figures make.py does not draw: {sorted(written - drawn)}"


def test_ci_runs_the_figure_script():
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text.split("<!-- ci:test -->", 1)[1].split("```", 2)[1]
    # chained with &&, so that a failing script fails the CI step
    assert "&& python docs/figures/make.py" in block
