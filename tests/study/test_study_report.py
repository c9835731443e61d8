"""HTML report: self-contained by construction, escaped text, embedded figures; and the
headless-Chromium test that the report opens with every figure loaded and no errors."""

from __future__ import annotations

import base64
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from robobore.study.report import Report, ReportError, check_self_contained  # noqa: E402


def _fig():
    fig, ax = plt.subplots(figsize=(4, 3))
    t = np.linspace(0, 1, 200)
    ax.plot(t, np.sin(2 * np.pi * 3 * t))
    ax.set_xlabel("time [s]")
    return fig


def _report() -> Report:
    fig = _fig()
    rep = (Report("Study <demo>", subtitle="SYNTHETIC data")
           .add_section("Tables")
           .add_text("A <b>bold</b> claim & more.\n\nSecond paragraph.")
           .add_table([{"mode": 1, "f [Hz]": 6.71, "zeta": 0.031, "ok": True},
                       {"mode": 2, "f [Hz]": 16.9, "zeta": None, "ok": False}],
                      caption="Modes")
           .add_table({"a": [1.0, 2.0], "b": ["x", "y"]})
           .add_key_values({"k_xx [N/m]": 1.25e6})
           .add_section("Figures")
           .add_figure(fig, "PNG figure")
           .add_figure(fig, "SVG figure", fmt="svg")
           .add_note("Where the model disagrees with the paper, it says so."))
    plt.close(fig)
    return rep


def test_report_content_is_escaped_and_embedded(tmp_path):
    p = _report().write(tmp_path / "r.html")
    text = p.read_text()
    assert "<title>Study &lt;demo&gt;</title>" in text
    assert "A &lt;b&gt;bold&lt;/b&gt; claim &amp; more." in text and "<b>" not in text
    assert text.count("<p>") == 2
    assert "<caption>Table 1. Modes</caption>" in text and "6.71" in text and "—" in text
    assert "Figure 1. PNG figure" in text and "Figure 2. SVG figure" in text
    (b64,) = re.findall(r'src="data:image/png;base64,([A-Za-z0-9+/=]+)"', text)
    png = base64.b64decode(b64)
    assert png.startswith(b"\x89PNG\r\n\x1a\n") and len(png) > 2000
    assert text.count("<svg") >= 1 and "<?xml" not in text
    assert "default-src 'none'" in text  # CSP: the browser itself refuses anything external
    assert '<a href="#tables">' in text
    check_self_contained(text)
    assert not list(tmp_path.glob(".*.tmp"))


@pytest.mark.parametrize("bad", [
    '<img src="http://example.org/a.png">', '<img src="a.png">', "<img src='//cdn/x.png'>",
    '<a href="https://example.org">x</a>', '<link rel="stylesheet" href="data:,">',
    "<script>alert(1)</script>", '<div onclick="x()">', '<p style="background:url(a.png)">',
    "<style>@import 'x.css';</style>", "<style>body{background:url(http://x/y)}</style>",
    '<iframe src="data:text/html,x"></iframe>', '<svg><image xlink:href="file:///x.png"/></svg>',
])
def test_check_self_contained_catches_external_references(bad):
    with pytest.raises(ReportError, match="not self-contained"):
        check_self_contained(f"<html><body>{bad}</body></html>")
    with pytest.raises(ReportError):
        Report("x").add_html(bad)


def test_check_self_contained_accepts_local_references():
    check_self_contained('<a href="#sec">s</a><img src="data:image/png;base64,AAAA">'
                         '<svg><use xlink:href="#p"/><rect style="fill:url(#g)"/></svg>'
                         "<p>one = 1, url(x) and @import in plain text are fine</p>")


# --- the browser test ------------------------------------------------------------------

def _browser_or_skip():
    from robobore.study.browser import browser_available

    why = browser_available()
    if why is None:
        return
    if os.environ.get("ROBOBORE_SKIP_BROWSER") == "1":
        pytest.skip(f"ROBOBORE_SKIP_BROWSER=1 and no browser: {why}")
    pytest.fail(f"headless Chromium test cannot run: {why}. Install chromium and "
                "chromium-driver (see .ci/apt-packages) or set ROBOBORE_SKIP_BROWSER=1 "
                "to skip it locally.")


def test_report_opens_in_headless_chromium_with_every_figure_loaded(tmp_path):
    _browser_or_skip()
    from robobore.study.browser import check_html_in_browser

    p = _report().write(tmp_path / "report.html")
    res = check_html_in_browser(p)
    assert res.problems == ()
    assert res.title == "Study <demo>"
    assert res.images == 1 and res.svgs == 1


def test_browser_check_detects_broken_and_external_content(tmp_path):
    """Negative control: the browser test must fail on a report that does not load."""
    _browser_or_skip()
    from robobore.study.browser import check_html_in_browser

    p = tmp_path / "bad.html"
    p.write_text(
        '<!DOCTYPE html><html><head><meta charset="utf-8"><title>bad</title></head><body>'
        '<img src="data:image/png;base64,iVBORw0KGgoAAAA" alt="truncated png">'
        '<img src="http://127.0.0.1:9/x.png" alt="external">'
        '<img src="missing.png" alt="missing file"><svg width="0" height="0"></svg>'
        "<script>console.error('boom')</script></body></html>")
    res = check_html_in_browser(p)
    text = "\n".join(res.problems)
    assert not res.ok
    assert "truncated png" in text and "external" in text and "missing file" in text
    assert "console error" in text and "boom" in text
    assert "request failed" in text or "outside the report" in text
    assert "inline svg 1" in text


def test_comparison_and_sweep_reports_open_in_headless_chromium(tmp_path):
    """The reports that `robobore compare --report` and `robobore sweep --report` write."""
    _browser_or_skip()
    from conftest import write_sweep_toml

    from robobore.study.browser import check_html_files_in_browser
    from robobore.study.compare import compare, parse_measured_csv
    from robobore.study.plots import comparison_report, sweep_report
    from robobore.study.store import ResultsStore
    from robobore.study.sweep import plan_from_file, run_sweep

    head = "speed_rpm,feed_mm_per_rev,depth_of_cut_mm,pressure_MPa"
    t = parse_measured_csv(f"{head},force_amplitude_x_N,feed_amplitude_um,stable\n"
                           "300,0.15,0.05,0,100,10,true\n400,0.15,0.2,0,300,60,false\n")
    sims = [({"speed_rpm": 300, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.05,
              "pressure_MPa": 0}, {"force_amplitude_x_N": 104.0, "feed_amplitude_um": 11.0,
                                   "stable": True}),
            ({"speed_rpm": 400, "feed_mm_per_rev": 0.15, "depth_of_cut_mm": 0.2,
              "pressure_MPa": 0}, {"force_amplitude_x_N": 250.0, "feed_amplitude_um": 70.0,
                                   "stable": True})]
    cmp_html = comparison_report(compare(t, sims)).write(tmp_path / "cmp.html")

    plan = plan_from_file(write_sweep_toml(tmp_path / "c.toml", speeds=(300, 600), feeds=(0.1,),
                                           depths=(0.05, 0.3), pressures=(0.0, 0.3),
                                           runner_options="fail_speeds_rpm = [600]"))
    run_sweep(plan, tmp_path / "s", workers=0)
    rep = sweep_report(ResultsStore(tmp_path / "s"), [i.key for i in plan.items])
    sweep_html = rep.write(tmp_path / "sweep.html")
    text = sweep_html.read_text()
    assert "Failed conditions" in text and "asked to fail at 600" in text
    assert "DEMO runner" in text
    # 2 stability maps (P = 0 and 0.3 MPa) + 1 trend figure per amplitude quantity (4)
    assert text.count("data:image/png;base64,") == 6

    res_cmp, res_sweep = check_html_files_in_browser([cmp_html, sweep_html])
    assert res_cmp.problems == () and res_cmp.images == 1
    assert res_sweep.problems == () and res_sweep.images == 6


def test_missing_browser_is_reported_not_ignored(monkeypatch, tmp_path):
    """Without chromium the check raises BrowserUnavailable with the reason, and the tests
    above fail (unless ROBOBORE_SKIP_BROWSER=1): nothing passes silently."""
    import robobore.study.browser as br

    monkeypatch.setattr(br, "CHROMIUM", str(tmp_path / "no-chromium"))
    assert "no-chromium not found" in br.browser_available()
    with pytest.raises(br.BrowserUnavailable, match="chromium-driver"):
        br.check_html_in_browser(tmp_path / "x.html")
    monkeypatch.delenv("ROBOBORE_SKIP_BROWSER", raising=False)
    with pytest.raises(pytest.fail.Exception, match="cannot run"):
        _browser_or_skip()
    monkeypatch.setenv("ROBOBORE_SKIP_BROWSER", "1")
    with pytest.raises(pytest.skip.Exception, match="ROBOBORE_SKIP_BROWSER"):
        _browser_or_skip()
