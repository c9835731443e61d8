"""Self-contained HTML reports: one file, figures embedded, no network, no JavaScript.

    rep = Report("Robotic boring study")
    rep.add_section("Stiffness").add_text("Identified at the paper's posture.")
    rep.add_table(df, caption="Joint stiffness")          # DataFrame, list of dicts, ...
    rep.add_figure(fig, caption="Force over half a revolution")   # matplotlib Figure
    rep.write("report.html")                               # atomic

Figures are embedded as base64 PNG (``<img src="data:image/png;base64,...">``, default) or
as inline SVG. The page carries a Content-Security-Policy that forbids every network
resource and every script (``default-src 'none'``), so a browser would refuse (and log) any
external reference that slipped in; :func:`check_self_contained` checks the same thing on
the text before it is written. Text is HTML-escaped; only :meth:`Report.add_html` inserts
markup as given (for trusted snippets).
"""

from __future__ import annotations

import base64
import html
import io
import re
from collections.abc import Iterable, Mapping, Sequence
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from robobore.errors import RoboboreError
from robobore.io.results import atomic_write_text

CSP = ("default-src 'none'; img-src data:; style-src 'unsafe-inline'; font-src data:; "
       "base-uri 'none'; form-action 'none'")

_CSS = """
body{font-family:-apple-system,"Segoe UI",Roboto,"DejaVu Sans",Arial,sans-serif;
 max-width:1100px;margin:2em auto;padding:0 1em;color:#1d2330;line-height:1.45}
h1{border-bottom:2px solid #2b5797;padding-bottom:.2em}
h2{margin-top:1.8em;border-bottom:1px solid #ccd}
table{border-collapse:collapse;margin:.8em 0;font-size:.9em}
th,td{border:1px solid #bbc;padding:.25em .6em;text-align:right}
th{background:#eef1f7} td.t,th.t{text-align:left}
caption{caption-side:top;font-weight:bold;text-align:left;padding:.3em 0}
figure{margin:1.2em 0} figure img,figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#445}
.note{background:#fff7e0;border-left:4px solid #e0a800;padding:.5em .8em}
.meta{color:#667;font-size:.85em} nav ul{columns:2}
"""

_NUM_FMT = "{:.4g}"


class ReportError(RoboboreError):
    """A report that would not be self-contained (an external resource or a script)."""


def _fmt_cell(v: Any, float_fmt: str) -> tuple[str, bool]:
    """(text, is_numeric) of a table cell."""
    import numpy as np

    if v is None:
        return "—", False
    if isinstance(v, bool | np.bool_):
        return ("yes" if v else "no"), False
    if isinstance(v, int | np.integer):
        return str(int(v)), True
    if isinstance(v, float | np.floating):
        f = float(v)
        if f != f:
            return "NaN", True
        return float_fmt.format(f), True
    return html.escape(str(v)), False


def _rows_of(data: Any, columns: Sequence[str] | None) -> tuple[list[str], list[list[Any]]]:
    """Column names and rows from a DataFrame, a list of dicts/sequences or a dict of lists."""
    if hasattr(data, "to_dict") and hasattr(data, "columns"):  # pandas DataFrame
        cols = [str(c) for c in data.columns]
        return cols, [list(r) for r in data.itertuples(index=False, name=None)]
    if isinstance(data, Mapping):
        cols = [str(c) for c in data]
        lists = [list(v) for v in data.values()]
        n = len(lists[0]) if lists else 0
        if any(len(v) != n for v in lists):
            raise ValueError("all columns of a table must have the same length")
        return cols, [[col[i] for col in lists] for i in range(n)]
    rows = list(data)
    if rows and isinstance(rows[0], Mapping):
        cols = list(columns) if columns else list(dict.fromkeys(k for r in rows for k in r))
        return [str(c) for c in cols], [[r.get(c) for c in cols] for r in rows]
    if columns is None:
        raise ValueError("a table of sequences needs column names (columns=...)")
    return list(columns), [list(r) for r in rows]


def _slug(text: str, used: set[str]) -> str:
    base = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-") or "section"
    s, i = base, 2
    while s in used:
        s, i = f"{base}-{i}", i + 1
    used.add(s)
    return s


_TAG = re.compile(r"<\s*([a-zA-Z][\w:-]*)((?:[^>\"']|\"[^\"]*\"|'[^']*')*)>", re.S)
_ATTR = re.compile(r"""([\w:-]+)\s*=\s*("[^"]*"|'[^']*'|[^\s>]+)""", re.S)
_STYLE = re.compile(r"<style[^>]*>(.*?)</style>", re.S | re.I)
_CSS_URL = re.compile(r"""url\(\s*["']?\s*([^)"'\s]*)""", re.I)
_FORBIDDEN_TAGS = {"script", "iframe", "frame", "object", "embed", "link", "base", "applet",
                   "audio", "video", "source", "track", "portal", "noscript"}
_URL_ATTRS = {"src", "href", "xlink:href", "action", "formaction", "poster", "data", "srcset",
              "background", "cite", "longdesc", "usemap", "ping", "manifest", "codebase"}


def _local(url: str) -> bool:
    u = url.strip().strip("\"'").strip().lower()
    return u.startswith("data:") or u.startswith("#")


def _css_problem(css: str) -> str | None:
    if "@import" in css.lower():
        return "@import in a style sheet"
    for m in _CSS_URL.finditer(css):
        if not _local(m.group(1)):
            return f"url({m.group(1)}) in a style sheet"
    return None


def check_self_contained(text: str) -> None:
    """Raise :class:`ReportError` if the HTML references anything outside itself: a URL
    attribute (src, href, ...) that is not ``data:`` or ``#fragment``, a CSS ``url()`` or
    ``@import`` to elsewhere, an inline event handler, or a script/iframe/object/embed/link/
    base/media element. Text outside tags is not inspected (it is escaped)."""

    def fail(why: str, pos: int) -> None:
        a, b = max(0, pos - 40), min(len(text), pos + 60)
        raise ReportError(f"report is not self-contained ({why}) near: {text[a:b]!r}")

    for m in _TAG.finditer(text):
        name = m.group(1).lower()
        if name in _FORBIDDEN_TAGS:
            fail(f"<{name}> element", m.start())
        for a in _ATTR.finditer(m.group(2)):
            an, av = a.group(1).lower(), a.group(2)
            if an.startswith("on"):
                fail(f"event handler {an}", m.start())
            if an in _URL_ATTRS and not _local(av):
                fail(f"{an}={av[:40]}", m.start())
            if an == "style":
                why = _css_problem(av)
                if why:
                    fail(why, m.start())
    for m in _STYLE.finditer(text):
        why = _css_problem(m.group(1))
        if why:
            fail(why, m.start())


class Report:
    """Builder of one self-contained HTML report (see module doc). Methods chain."""

    def __init__(self, title: str, subtitle: str | None = None) -> None:
        self.title = title
        self.subtitle = subtitle
        self._parts: list[str] = []
        self._toc: list[tuple[int, str, str]] = []
        self._slugs: set[str] = set()
        self._n_fig = 0
        self._n_tab = 0

    def add_section(self, title: str, level: int = 2) -> Report:
        if level not in (2, 3, 4):
            raise ValueError("section level must be 2, 3 or 4")
        sid = _slug(title, self._slugs)
        self._toc.append((level, sid, title))
        self._parts.append(f'<h{level} id="{sid}">{html.escape(title)}</h{level}>')
        return self

    def add_text(self, text: str) -> Report:
        """Paragraphs of plain text (blank line = new paragraph), escaped."""
        for para in re.split(r"\n\s*\n", text.strip()):
            if para.strip():
                self._parts.append(f"<p>{html.escape(para.strip())}</p>")
        return self

    def add_note(self, text: str) -> Report:
        """A highlighted remark (e.g. where the model disagrees with the paper)."""
        self._parts.append(f'<p class="note">{html.escape(text)}</p>')
        return self

    def add_html(self, snippet: str) -> Report:
        """Trusted HTML inserted as given (checked to be self-contained)."""
        check_self_contained(snippet)
        self._parts.append(snippet)
        return self

    def add_key_values(self, items: Mapping[str, Any] | Iterable[tuple[str, Any]],
                       caption: str | None = None, float_fmt: str = _NUM_FMT) -> Report:
        pairs = list(items.items()) if isinstance(items, Mapping) else list(items)
        return self.add_table([{"quantity": k, "value": v} for k, v in pairs],
                              caption=caption, float_fmt=float_fmt)

    def add_table(self, data: Any, caption: str | None = None,
                  columns: Sequence[str] | None = None, float_fmt: str = _NUM_FMT,
                  max_rows: int | None = None) -> Report:
        """A table from a DataFrame, a list of dicts, a list of sequences (``columns``
        needed) or a dict of column lists. Numbers use ``float_fmt``."""
        cols, rows = _rows_of(data, columns)
        shown = rows if max_rows is None else rows[:max_rows]
        self._n_tab += 1
        out = ['<table>']
        if caption:
            out.append(f"<caption>Table {self._n_tab}. {html.escape(caption)}</caption>")
        out.append("<thead><tr>" + "".join(
            f'<th class="t">{html.escape(c)}</th>' for c in cols) + "</tr></thead><tbody>")
        for r in shown:
            cells = []
            for v in r:
                text, num = _fmt_cell(v, float_fmt)
                cells.append(f"<td>{text}</td>" if num else f'<td class="t">{text}</td>')
            out.append("<tr>" + "".join(cells) + "</tr>")
        out.append("</tbody></table>")
        if max_rows is not None and len(rows) > max_rows:
            out.append(f'<p class="meta">{len(rows) - max_rows} more rows not shown.</p>')
        self._parts.append("".join(out))
        return self

    def add_figure(self, fig: Any, caption: str = "", fmt: str = "png", dpi: int = 110,
                   alt: str | None = None) -> Report:
        """A matplotlib figure, embedded as base64 PNG (``fmt="png"``) or inline SVG.

        The figure is not closed (the caller owns it)."""
        self._n_fig += 1
        cap = f"Figure {self._n_fig}. {caption}".strip()
        alt_text = html.escape(alt or caption or f"figure {self._n_fig}", quote=True)
        if fmt == "png":
            buf = io.BytesIO()
            fig.savefig(buf, format="png", dpi=dpi, bbox_inches="tight")
            b64 = base64.b64encode(buf.getvalue()).decode("ascii")
            body = f'<img src="data:image/png;base64,{b64}" alt="{alt_text}">'
        elif fmt == "svg":
            buf = io.BytesIO()
            fig.savefig(buf, format="svg", bbox_inches="tight")
            svg = buf.getvalue().decode("utf-8")
            svg = svg[svg.index("<svg"):]  # drop the XML declaration and DOCTYPE
            body = svg.replace("<svg ", f'<svg role="img" aria-label="{alt_text}" ', 1)
        else:
            raise ValueError("fmt must be 'png' or 'svg'")
        self._parts.append(f"<figure>{body}<figcaption>{html.escape(cap)}</figcaption></figure>")
        return self

    def add_image_png(self, png: bytes, caption: str = "", alt: str | None = None) -> Report:
        """A PNG image given as bytes."""
        if not png.startswith(b"\x89PNG\r\n\x1a\n"):
            raise ValueError("not PNG data")
        self._n_fig += 1
        cap = f"Figure {self._n_fig}. {caption}".strip()
        b64 = base64.b64encode(png).decode("ascii")
        alt_text = html.escape(alt or caption or f"figure {self._n_fig}", quote=True)
        self._parts.append(f'<figure><img src="data:image/png;base64,{b64}" alt="{alt_text}">'
                           f"<figcaption>{html.escape(cap)}</figcaption></figure>")
        return self

    def to_html(self) -> str:
        from robobore import __version__

        toc = ""
        if len(self._toc) > 1:
            items = "".join(f'<li><a href="#{sid}">{html.escape(t)}</a></li>'
                            for lvl, sid, t in self._toc if lvl == 2)
            toc = f"<nav><ul>{items}</ul></nav>"
        sub = f'<p class="meta">{html.escape(self.subtitle)}</p>' if self.subtitle else ""
        stamp = datetime.now(UTC).isoformat(timespec="seconds")
        text = (
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
            '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>{html.escape(self.title)}</title><style>{_CSS}</style></head><body>"
            f"<h1>{html.escape(self.title)}</h1>{sub}{toc}"
            + "\n".join(self._parts)
            + f'<hr><p class="meta">Written by robobore {html.escape(__version__)} at {stamp}.'
            "</p></body></html>\n"
        )
        check_self_contained(text)
        return text

    def write(self, path: str | Path) -> Path:
        """Write the report atomically; returns the path."""
        return atomic_write_text(path, self.to_html())


__all__ = ["Report", "ReportError", "check_self_contained", "CSP"]
