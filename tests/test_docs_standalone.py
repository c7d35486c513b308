"""The repository stands alone: no file points to notes the user does not have, and the
filter's page opens with what a user does."""
import subprocess
from pathlib import Path

from conftest import ROOT
# spelled in pieces so that this file does not match itself
OUTSIDE = ("FILTER" + ".md", "METHOD" + ".md", "../" + "shared")


def _tracked() -> list[Path]:
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [ROOT / line for line in out.splitlines() if (ROOT / line).is_file()]


def test_no_file_points_outside_the_repository() -> None:
    hits = []
    for path in _tracked():
        try:
            text = path.read_text(encoding="utf-8")
        except (UnicodeDecodeError, OSError):
            continue
        hits += [f"{path.relative_to(ROOT)}: {name}" for name in OUTSIDE if name in text]
    assert hits == []


def test_filter_page_opens_with_what_a_user_does() -> None:
    headings = [line for line in (ROOT / "docs" / "filter.md").read_text().splitlines() if line.startswith("## ")]
    assert headings[:2] == ["## What you do with a filter", "## The method in short"]


def test_method_page_says_the_method_itself() -> None:
    text = (ROOT / "docs" / "method.md").read_text()
    assert "## The method in one page" in text
    for word in ("SUP", "ASS", "SYNC", "region", "blocking"):
        assert word in text
