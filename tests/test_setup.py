"""A newcomer's first hour (issue 13): the set-up script on a Python that refuses
system-wide installs, a wheel that carries the element library, no Graphviz, the
version and the library listing."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import textwrap

import pytest

from conftest import ROOT
from synth.cli.main import main


def _run(argv: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(argv, capture_output=True, text=True, timeout=600, **kw)


@pytest.mark.slow
def test_setup_uses_a_venv_when_the_system_python_refuses_installs(tmp_path):
    """Debian 12's python3 refuses ``pip install`` (PEP 668, ``externally-managed-environment``).
    The stand-in below does the same for any ``-m pip`` outside a venv; set-up must still
    succeed, because it installs into its own virtual environment only."""
    fake = tmp_path / "python3"
    fake.write_text(textwrap.dedent(f"""\
        #!/bin/sh
        for a in "$@"; do
          if [ "$a" = pip ]; then
            echo "error: externally-managed-environment" >&2; exit 1
          fi
        done
        exec {sys.executable} "$@"
        """))
    fake.chmod(0o755)
    assert _run([str(fake), "-m", "pip", "--version"]).returncode == 1
    venv = tmp_path / "venv"
    env = dict(os.environ, SYNTH_PYTHON=str(fake), SYNTH_VENV=str(venv), SYNTH_SKIP_APT="1",
               SYNTH_VENV_ARGS="--system-site-packages", SYNTH_PIP_ARGS="--no-deps")
    r = _run(["bash", str(ROOT / "scripts/setup.sh")], env=env)
    assert r.returncode == 0, r.stderr
    assert f"ready: {venv}/bin/synth" in r.stderr
    r = _run([str(venv / "bin/synth"), "--version"])
    assert r.returncode == 0 and r.stdout.startswith("synth ")


@pytest.mark.slow
def test_installed_wheel_validates_a_lone_copy_of_tri_rules(tmp_path):
    """The element library ships in the wheel: ``use "lib/…"`` resolves from the installed
    package when nothing is beside the file."""
    wheels = tmp_path / "wheels"
    r = _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", "-w", str(wheels), str(ROOT)])
    assert r.returncode == 0, r.stderr
    venv = tmp_path / "venv"
    assert _run([sys.executable, "-m", "venv", "--without-pip", str(venv)]).returncode == 0
    # synth's dependencies from this interpreter's site-packages, by a path line (the .pth
    # files there, the editable install of this tree among them, are not run)
    site_dirs = dict.fromkeys(sysconfig.get_path(k) for k in ("purelib", "platlib"))
    (new_site,) = venv.glob("lib/python*/site-packages")
    (new_site / "synth_test_dependencies.pth").write_text("".join(d + "\n" for d in site_dirs))
    (wheel,) = wheels.glob("synth-*.whl")
    r = _run([sys.executable, "-m", "pip", "--python", str(venv / "bin/python"), "install", "-q", "--no-deps",
              "--force-reinstall", str(wheel)])
    assert r.returncode == 0, r.stderr
    work = tmp_path / "empty"
    work.mkdir()
    shutil.copy(ROOT / "plants/tri.rules", work)
    shutil.copy(ROOT / "grafcets/tri.g7", work)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    r = _run([str(venv / "bin/synth"), "validate", "tri.g7", "--plant", "tri.rules"], cwd=work, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.startswith("PASS: 0 blocking situation(s)")
    r = _run([str(venv / "bin/python"), "-c", "import synth; print(synth.__file__)"], cwd=work, env=env)
    assert str(venv) in r.stdout  # the installed copy ran, not the source tree


def test_report_without_graphviz_still_answers(tmp_path):
    """No ``dot`` on the PATH: the verdict, the diagnosis and the exit code are the same,
    and the report says where drawings are missing. The venv's interpreter runs by its own
    path (a symlink to it elsewhere would start the base interpreter, without synth's
    dependencies), with a PATH that holds an empty folder only."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    env = dict(os.environ, PATH=str(bin_dir), PYTHONPATH=str(ROOT))
    out = tmp_path / "rep"
    r = _run([sys.executable, "-m", "synth", "validate", str(ROOT / "grafcets/tri_missing_order.g7"),
              "--plant", str(ROOT / "plants/tri.rules"), "--report", str(out)], env=env, cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    assert "diagnosis [missing_order]: missing order AVANCER2 in step 103" in r.stdout
    html = (out / "index.html").read_text()
    assert "drawing missing: Graphviz&#39;s dot program is not installed" in html
    assert "<svg" not in html


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == "synth 0.1.0\n"


def test_lib_lists_models_with_orders_and_sensors(capsys):
    assert main(["lib", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [(m["model"], m["use"], m["orders"], m["sensors"]) for m in data] == [
        ("conveyor", "lib/conveyor.rules", ["TAPIS"], ["small", "large"]),
        ("double_acting", "lib/double_acting.rules", ["AVANCER", "RECULER"], ["v0", "v1"]),
        ("pusher", "lib/four_cylinders.rules", ["Q"], ["b", "h"]),  # seed 000's square: a pusher and its cells
        ("cell", "lib/four_cylinders.rules", [], ["i", "t"]),
        ("full_cell", "lib/four_cylinders.rules", [], ["i", "t"]),
        ("single_acting", "lib/single_acting.rules", ["AVANCER"], ["v0", "v1"]),
    ]
    assert data[1]["initial"] == {"AVANCER": 0, "RECULER": 0, "v0": 1, "v1": 0}
    assert main(["lib"]) == 0
    out = capsys.readouterr().out
    assert "  orders:  AVANCER = 0, RECULER = 0\n  sensors: v0 = 1, v1 = 0\n" in out


def test_use_lib_resolves_beside_the_file_first(tmp_path):
    """A ``lib/`` folder beside the file wins over the installed library."""
    from synth.plant.library import library_file

    (tmp_path / "lib").mkdir()
    mine = tmp_path / "lib" / "double_acting.rules"
    mine.write_text("model double_acting { orders A = 0 }\n")
    assert library_file("lib/double_acting.rules", tmp_path) == mine
    assert library_file("lib/double_acting.rules", tmp_path / "nowhere").parent.name in ("lib", "library")


def test_setup_says_what_failed_when_pip_fails(tmp_path):
    """pip cannot reach its index (here: a venv whose pip always fails as it would offline):
    the set-up ends on one line from synth saying what failed and what to try, exit 2."""
    venv = tmp_path / "venv"
    (venv / "bin").mkdir(parents=True)
    fake = venv / "bin" / "python"
    fake.write_text(textwrap.dedent(f"""\
        #!/bin/sh
        if [ "$1 $2" = "-m pip" ]; then
          echo "ERROR: Could not find a version that satisfies the requirement wheel (from versions: none)" >&2
          exit 1
        fi
        exec {sys.executable} "$@"
        """))
    fake.chmod(0o755)
    env = dict(os.environ, SYNTH_VENV=str(venv), SYNTH_SKIP_APT="1")
    r = _run(["bash", str(ROOT / "scripts/setup.sh")], env=env)
    assert r.returncode == 2
    assert r.stderr.splitlines()[-1] == (
        f"== synth set-up failed: pip could not install the build tools (setuptools, wheel) into {venv} (exit 1). "
        "Is the package index reachable? Behind a proxy set HTTPS_PROXY (and PIP_CERT for its certificate); "
        "offline, point pip at local wheels with SYNTH_PIP_ARGS='--no-index --find-links DIR'. "
        f"Nothing outside {venv} was changed.")


def test_only_the_tests_install_chromium():
    """`.ci/run` (the tests) asks setup.sh for the browser unless SYNTH_SETUP_BROWSER=0; the
    main job (scripts/demo.sh) never does."""
    text = (ROOT / ".ci/run").read_text()
    assert 'browser="${SYNTH_SETUP_BROWSER:-1}"' in text
    assert 'SYNTH_SETUP_BROWSER="$browser" bash scripts/setup.sh' in text
    assert "SYNTH_SETUP_BROWSER" not in (ROOT / "scripts/demo.sh").read_text()
