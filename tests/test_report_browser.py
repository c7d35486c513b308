"""The HTML report opened in a real browser (headless Chromium from Debian, driven by
Playwright): no JavaScript error, no horizontal overflow, the blocking section and its
trace on the first screen, and a click on a trace step updates the state panel and the
Grafcet's active steps. Screenshots are saved in the test's temporary folder."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from conftest import ROOT
from synth.cli.main import main

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
playwright = pytest.importorskip("playwright.sync_api")

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="Debian's chromium is not installed (setup.sh installs it for CI)")


def _report(tmp_path: Path, g7: str, rules: str, *flags: str) -> Path:
    out = tmp_path / Path(g7).stem
    main(["validate", str(ROOT / g7), "--plant", str(ROOT / rules), "--report", str(out), *flags])
    return out / "index.html"


@pytest.fixture(scope="module")
def browser():
    with playwright.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=["--no-sandbox"])
        yield b
        b.close()


def _open(browser, path: Path, errors: list[str]):
    page = browser.new_page(viewport={"width": 1280, "height": 900})
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    requests: list[str] = []
    page.on("request", lambda r: requests.append(r.url))
    page.goto(path.as_uri())
    assert all(u.startswith("file:") for u in requests), requests  # one self-contained file
    return page


def _no_horizontal_overflow(page) -> None:
    assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")


def test_blocking_report_in_a_browser(browser, tmp_path, capsys):
    path = _report(tmp_path, "grafcets/tri_missing_order.g7", "plants/tri.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    page.screenshot(path=str(tmp_path / "missing_order_first_screen.png"))
    _no_horizontal_overflow(page)
    height = page.evaluate("window.innerHeight")
    for selector in ("#blocking-1 h2", "#blocking-1 .diag", "#trace-1"):
        box = page.locator(selector).bounding_box()
        assert box is not None and box["y"] < height, selector
    panel = page.locator("#panel-b1")
    assert "X1, X103, X200, X300" in panel.inner_text()  # the blocking state first
    buttons = page.locator("#trace-1 button")
    assert [buttons.nth(i).inner_text() for i in range(buttons.count())] == [
        "initial", "↑dcy", "↑cp12", "2s/X101", "↓v10", "↑v11"]
    buttons.nth(0).click()
    text = panel.inner_text()
    assert "X0, X100, X200, X300" in text and "initial" in text
    fills = page.evaluate("""() => Array.from(document.querySelectorAll('#grafcet g.node'))
        .filter(g => g.querySelector('title').textContent.startsWith('step_'))
        .filter(g => g.querySelector('polygon').getAttribute('fill') === '#f9d71c')
        .map(g => g.querySelector('title').textContent).sort()""")
    assert fills == ["step_0", "step_100", "step_200", "step_300"]
    buttons.nth(2).click()
    assert "↑cp12" in panel.inner_text() and "TAPIS" in panel.inner_text()
    page.screenshot(path=str(tmp_path / "missing_order_step_2.png"), full_page=True)
    assert errors == []


@pytest.mark.parametrize("case", [
    ("grafcets/tri.g7", "plants/tri.rules"),
    ("grafcets/tri.g7", "plants/tri_overstrict.rules"),
    ("grafcets/tri.g7", "plants/tri_missing_rule.rules", "--expert"),
])
def test_other_reports_open_cleanly(browser, tmp_path, capsys, case):
    path = _report(tmp_path, *case)
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    _no_horizontal_overflow(page)
    page.screenshot(path=str(tmp_path / "report.png"), full_page=True)
    assert errors == []
    if case[1] == "plants/tri.rules":
        assert "What was checked" in page.inner_text("#checked")
        assert "Prohibited orders met: none" in page.inner_text("#checked")


NESTED_SCROLL_BOXES = """() => {
  const scrolls = e => ['auto', 'scroll'].some(v => [getComputedStyle(e).overflowX, getComputedStyle(e).overflowY].includes(v));
  return Array.from(document.body.querySelectorAll('*')).filter(e => scrolls(e))
    .filter(e => { for (let p = e.parentElement; p && p !== document.body; p = p.parentElement) if (scrolls(p)) return true; return false; })
    .map(e => e.tagName + '#' + e.id + '.' + e.className);
}"""


def test_report_layout(browser, tmp_path, capsys):
    """Issue 24: one scroll box per drawing, the drawn trace whole (its blocking state
    inside its box), the element drawing readable at 100 % (text at least 10 px high)."""
    path = _report(tmp_path, "grafcets/tri_missing_order.g7", "plants/tri.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    page.evaluate("document.querySelectorAll('details').forEach(d => d.open = true)")
    assert page.evaluate(NESTED_SCROLL_BOXES) == []
    inside = page.evaluate("""() => {
      const fig = Array.from(document.querySelectorAll('#blocking-1 details'))
        .find(d => d.querySelector('summary').textContent.startsWith('Trace to the blocking state')).querySelector('.figure');
      const nodes = fig.querySelectorAll('svg g.node');
      const last = nodes[nodes.length - 1];
      const f = fig.getBoundingClientRect(), n = last.getBoundingClientRect();
      return [last.querySelector('text').textContent,
              n.top >= f.top && n.left >= f.left && n.bottom <= f.top + fig.clientHeight && n.right <= f.left + fig.clientWidth];
    }""")
    assert inside == ["5: Sit={X1, X103, X200, X300}", True]  # the blocking state, not cut off
    heights = page.evaluate("""() => {
      const el = Array.from(document.querySelectorAll('#blocking-1 details'))
        .find(d => d.querySelector('summary').textContent.startsWith('Element V2'));
      return Array.from(el.querySelector('.figure svg').querySelectorAll('text')).map(t => t.getBoundingClientRect().height);
    }""")
    assert heights and min(heights) >= 10, heights
    assert errors == []


def test_passing_report_draws_the_grafcet(browser, tmp_path, capsys):
    path = _report(tmp_path, "grafcets/tri.g7", "plants/tri.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    steps = page.evaluate("""() => Array.from(document.querySelectorAll('#chart svg g.node title'))
        .map(t => t.textContent).filter(t => t.startsWith('step_'))""")
    assert "step_0" in steps and "step_103" in steps
    assert page.evaluate(NESTED_SCROLL_BOXES) == []
    assert errors == []


# ---------------------------------------------------------------- issue 38: the report's four points

GRAFCET_DRAWINGS = """() => Array.from(document.querySelectorAll('svg'))
    .filter(s => Array.from(s.querySelectorAll('g.node title')).some(t => t.textContent === 'step_0')).length"""

NOTHING_CLIPPED = """() => {
  const fig = document.getElementById('grafcet'), f = fig.getBoundingClientRect();
  const out = Array.from(fig.querySelectorAll('g.node')).filter(g => {
    const n = g.getBoundingClientRect();
    return n.left < f.left - 0.5 || n.right > f.right + 0.5 || n.top < f.top - 0.5 || n.bottom > f.bottom + 0.5;
  });
  return [fig.scrollWidth <= fig.clientWidth, fig.scrollHeight <= fig.clientHeight + 1, out.length,
          fig.querySelectorAll('g.node').length];
}"""


def test_the_grafcet_is_never_clipped_and_the_step_to_fix_is_marked(browser, tmp_path, capsys):
    """The 1 690 px box-sorting Grafcet is drawn whole, fitted to the page (G3 and G4 were cut
    at the right edge); step 103, where the order is missing, outlined in red and named in the
    legend and in the index."""
    path = _report(tmp_path, "grafcets/tri_missing_order.g7", "plants/tri.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    page.screenshot(path=str(tmp_path / "missing_order_after.png"), full_page=True)
    fits_x, fits_y, outside, nodes = page.evaluate(NOTHING_CLIPPED)
    assert (fits_x, fits_y, outside) == (True, True, 0) and nodes > 40
    strokes = page.evaluate("""() => Array.from(document.querySelectorAll('#grafcet g.node'))
        .filter(g => g.querySelector('polygon').getAttribute('stroke') === '#c0392b')
        .map(g => g.querySelector('title').textContent)""")
    assert strokes == ["step_103"]
    assert page.inner_text("#legend tr.fix").strip() == "red outline\tstep to fix (X103): missing order AVANCER2, blocking 1"
    assert page.inner_text("#index li:first-child") == ("Blocking 1: situation {X1, X103, X200, X300}, missing_order: "
                                                       "fix step 103")
    assert page.evaluate(GRAFCET_DRAWINGS) == 1
    assert errors == []


def test_an_index_of_four_blockings_and_one_grafcet(browser, tmp_path, capsys):
    """Four blockings (the boxes as workpieces): an index whose links reach each section, one
    Grafcet drawing (not four), updated by a click on any blocking's trace."""
    path = _report(tmp_path, "grafcets/tri.g7", "plants/tri_boxes.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    links = page.locator("#index a")
    assert [links.nth(i).get_attribute("href") for i in range(links.count())] == [
        "#blocking-1", "#blocking-2", "#blocking-3", "#blocking-4", "#chart"]
    assert page.evaluate(GRAFCET_DRAWINGS) == 1
    links.nth(3).click()
    top = page.locator("#blocking-4").bounding_box()
    assert top is not None and 0 <= top["y"] < 50  # the link brought blocking 4 to the top
    page.locator("#trace-3 button").first.click()
    assert page.inner_text("#chart-shows").startswith("Active steps (filled) of blocking 3, trace step 0 (initial)")
    fills = page.evaluate("""() => Array.from(document.querySelectorAll('#grafcet g.node'))
        .filter(g => g.querySelector('polygon').getAttribute('fill') === '#f9d71c')
        .map(g => g.querySelector('title').textContent).sort()""")
    assert fills == ["step_0", "step_100", "step_200", "step_300"]
    fits_x, fits_y, outside, _ = page.evaluate(NOTHING_CLIPPED)
    assert (fits_x, fits_y, outside) == (True, True, 0)
    page.screenshot(path=str(tmp_path / "four_blockings.png"), full_page=True)
    assert errors == []


def test_the_aggregated_automaton_at_a_readable_scale(browser, tmp_path, capsys):
    """The 90 states of the passing box sorting: text at 100 % (at least 10 px), no longer a
    strip 10 900 px wide and 94 % white (left to right): top to bottom, tight."""
    path = _report(tmp_path, "grafcets/tri.g7", "plants/tri.rules")
    capsys.readouterr()
    errors: list[str] = []
    page = _open(browser, path, errors)
    page.evaluate("document.querySelectorAll('details').forEach(d => d.open = true)")
    width, height, nodes, covered, text = page.evaluate("""() => {
      const s = document.querySelector('#aggregated svg'), r = s.getBoundingClientRect();
      const g = Array.from(s.querySelectorAll('g.node'));
      const area = g.map(n => n.getBoundingClientRect()).reduce((a, b) => a + b.width * b.height, 0);
      const text = Math.min(...Array.from(s.querySelectorAll('text')).map(t => t.getBoundingClientRect().height));
      return [r.width, r.height, g.length, area / (r.width * r.height), text];
    }""")
    assert nodes == 90
    assert text >= 10
    assert width < 4000 and width / height < 1.5
    assert covered > 0.10
    page.locator("#aggregated").screenshot(path=str(tmp_path / "aggregated.png"))
    assert errors == []
