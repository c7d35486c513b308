"""synth.toml (issue 39, build 1): stations, variants, expectations, paths relative to the
file, and a located error (file:line:col, caret, close names) for every mistake."""

from __future__ import annotations

from pathlib import Path

import pytest

from synth.errors import InputError
from synth.line.project import Check, Expect, load_line

HOME = Path(__file__).parent / "data" / "home"


def project(tmp_path: Path, text: str) -> Path:
    (tmp_path / "m").mkdir(exist_ok=True)
    for name in ("cylinder.rules", "production_loop.g7"):
        (tmp_path / "m" / name).write_text((HOME / name).read_text(encoding="utf-8"), encoding="utf-8")
    path = tmp_path / "synth.toml"
    path.write_text(text, encoding="utf-8")
    return path


STATION = '[[station]]\nname = "cyl"\nplant = "m/cylinder.rules"\ngrafcets = ["m/production_loop.g7"]\n'


def error(tmp_path: Path, text: str) -> str:
    with pytest.raises(InputError) as info:
        load_line(project(tmp_path, text))
    return info.value.render()


def test_a_station_with_a_variant_and_its_defaults(tmp_path: Path) -> None:
    path = project(tmp_path, '[line]\nname = "L"\n' + STATION + 'homes = ["X1"]\nfilter = "m/cylinder.rules"\n'
                   'checks = ["validate", "filter-check"]\n'
                   '[[station.variant]]\nname = "no home"\nhomes = []\nexpect = "fail"\n')
    line = load_line(path)
    (s,) = line.stations
    assert (line.name, s.name, s.plant, s.grafcets) == ("L", "cyl", tmp_path / "m" / "cylinder.rules",
                                                          (tmp_path / "m" / "production_loop.g7",))
    assert s.checks == (Check.VALIDATE, Check.FILTER_CHECK) and s.expect is Expect.PASS and s.homes == ("X1",)
    (v,) = s.variants
    assert (v.name, v.grafcet, v.plant, v.expect, v.homes) == ("no home", s.grafcets[0], s.plant, Expect.FAIL, ())
    assert (s.loc.line, v.loc.line) == (3, 10)


def test_a_toml_syntax_error_keeps_tomllib_s_line_and_column(tmp_path: Path) -> None:
    text = error(tmp_path, STATION + 'expect = "fail\n').splitlines()
    assert text[0].endswith("synth.toml:5:15: error: Illegal character '\\n'")
    assert text[1:3] == ['  5 | expect = "fail', "    |               ^"]
    text = error(tmp_path, STATION + "homes = [\n").splitlines()
    assert text[0].endswith("synth.toml:6:1: error: Invalid value (at end of document)")


def test_an_unknown_key_points_at_it_with_the_close_names(tmp_path: Path) -> None:
    text = error(tmp_path, STATION + 'grafcet = "m/production_loop.g7"\n').splitlines()
    assert text[0].endswith("synth.toml:5:1: error: unknown key 'grafcet' in station")
    assert text[1:3] == ['  5 | grafcet = "m/production_loop.g7"', "    | ^~~~~~~"]
    assert text[-1] == "  = did you mean grafcets?"


def test_a_missing_file_points_at_its_value_in_the_right_station(tmp_path: Path) -> None:
    text = error(tmp_path, STATION + STATION.replace('"cyl"', '"two"').replace("cylinder.rules", "cylindre.rules"))
    lines = text.splitlines()
    assert lines[0].endswith("synth.toml:7:9: error: plant: no file 'm/cylindre.rules' (paths are relative to "
                             f"{tmp_path / 'synth.toml'})")
    assert lines[2] == "    |         ^~~~~~~~~~~~~~~~~~"


def test_a_wrong_value_a_duplicate_station_and_an_empty_line(tmp_path: Path) -> None:
    text = error(tmp_path, STATION + 'expect = "fails"\n').splitlines()
    assert text[0].endswith("synth.toml:5:10: error: expect = 'fails' is not one of pass, fail")
    assert text[-1] == "  = did you mean fail?"
    text = error(tmp_path, STATION + STATION).splitlines()
    assert text[0].endswith("synth.toml:6:8: error: station 'cyl' is declared twice")
    assert error(tmp_path, '[line]\nname = "x"\n').splitlines()[0].endswith(
        "synth.toml:1:1: error: the line has no station: add [[station]] tables")
    text = error(tmp_path, STATION + 'checks = ["validate", "filter-check"]\n').splitlines()
    assert text[0].endswith("synth.toml:5:10: error: a filter check needs filter = \"F.filter\"")


def test_the_example_line_plans_its_twelve_checks() -> None:
    from synth.line.jobs import line_jobs

    line = load_line(Path(__file__).parent.parent / "lines" / "example" / "synth.toml")
    assert [(s.name, s.expect) for s in line.stations] == [
        ("box sorting", Expect.PASS), ("boxes as workpieces", Expect.PASS), ("four cylinders", Expect.PASS),
        ("press", Expect.PASS), ("gate", Expect.FAIL)]
    assert [(j.id, None if j.expect is None else str(j.expect)) for j in line_jobs(line)] == [
        ("box sorting/validate tri.g7", "pass"), ("box sorting/st --check tri.g7", "pass"),
        ("box sorting/variant missing order", "fail"),
        ("boxes as workpieces/validate tri_boxes.g7", "pass"),
        ("boxes as workpieces/variant plain box-sorting grafcet", "fail"),
        ("four cylinders/filter verify four_cylinders.filter", "pass"),
        ("four cylinders/st --check four_cylinders.g7", "pass"), ("four cylinders/variant without the filter", "fail"),
        ("press/validate clamp.g7", "pass"), ("press/filter check clamp.filter", "pass"),
        ("press/st --check clamp.g7", "pass"), ("gate/validate gate.g7", "fail")]


@pytest.mark.nightly
def test_the_example_line_meets_every_expectation(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """The whole example line (about a minute of CPU): pytest -m nightly."""
    from synth.cli.main import main

    toml = Path(__file__).parent.parent / "lines" / "example" / "synth.toml"
    assert main(["check", str(toml), "--no-cache", "--quiet", "--report", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines()[6] == "5 station(s), 5 meet their expectation; 12 job(s): 12 run, 0 from the cache"
