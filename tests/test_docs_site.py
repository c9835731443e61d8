"""The documentation site: ``mkdocs build --strict`` (mkdocs.yml at the repository root)
builds with no warning, every page of the nav is built, every guide in docs/ is in the nav,
and every image a page shows is in the built site where the page's HTML points."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
#: markdown image links ``![alt](target)`` and HTML ``<img src="target">``
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|<img[^>]+src=\"([^\"]+)\"")
#: the ``<img src>`` of a built page
HTML_IMG = re.compile(r"<img[^>]*\ssrc=\"([^\"]+)\"")


def nav_pages() -> list[str]:
    """The markdown files of mkdocs.yml's nav, in order (``- Title: file.md`` lines)."""
    text = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    block = text.split("\nnav:\n", 1)[1]
    pages = []
    for line in block.splitlines():
        if not line.startswith(" "):
            break
        m = re.match(r"\s+- [^:]+:\s*(\S+\.md)\s*$", line)
        assert m, f"mkdocs.yml nav line not of the form '- Title: page.md': {line!r}"
        pages.append(m.group(1))
    return pages


def built_html(site: Path, page: str) -> Path:
    """Where mkdocs (directory URLs) writes a page: index.md -> index.html, x.md ->
    x/index.html."""
    stem = page.removesuffix(".md")
    return site / "index.html" if stem == "index" else site / stem / "index.html"


def markdown_images(page: Path) -> list[str]:
    return [m.group(1) or m.group(2) for m in IMAGE.finditer(page.read_text(encoding="utf-8"))]


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("site")
    proc = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT, capture_output=True, text=True, timeout=300)
    log = proc.stdout + proc.stderr
    assert proc.returncode == 0, f"mkdocs build --strict failed (mkdocs is in the test extra):\n{log}"
    assert "WARNING" not in log, log
    return out


def test_the_nav_holds_every_guide_once():
    pages = nav_pages()
    assert pages[0] == "index.md"
    assert len(pages) == len(set(pages)), pages
    assert set(pages) == {p.name for p in DOCS.glob("*.md")}


def test_every_nav_page_is_built(site):
    missing = [p for p in nav_pages() if not built_html(site, p).is_file()]
    assert not missing, f"nav pages with no built HTML: {missing}"
    assert not (site / "figures" / "make.py").exists()  # the figure script is not published


def test_every_image_of_the_docs_is_in_the_site(site):
    problems = []
    n = 0
    for page in nav_pages():
        html = built_html(site, page)
        sources = HTML_IMG.findall(html.read_text(encoding="utf-8"))
        for target in markdown_images(DOCS / page):
            n += 1
            if not (site / target).is_file():
                problems.append(f"docs/{page}: {target} not in the site")
            if not any(Path(s).name == Path(target).name for s in sources):
                problems.append(f"docs/{page}: {target} not shown by {html.relative_to(site)}")
        for src in sources:
            if not (html.parent / src).resolve().is_file():
                problems.append(f"{html.relative_to(site)}: <img src={src!r}> points at nothing")
    assert not problems, "\n".join(problems)
    assert n >= 8  # every figure of docs/figures is shown by a guide, two on the home page


def test_home_page_commands_are_the_readmes():
    """docs/index.md shows the README's two commands (the ones CI runs), word for word."""

    def blocks(text: str) -> list[str]:
        return [b.strip() for b in re.findall(r"```bash\n(.*?)```", text, re.S)]

    readme = (ROOT / "README.md").read_text()
    ci = []
    for marker in ("<!-- ci:main -->", "<!-- ci:test -->"):
        ci.append(blocks(readme[readme.index(marker):])[0])
    assert blocks((ROOT / "docs" / "index.md").read_text())[:2] == ci
