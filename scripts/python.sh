#!/usr/bin/env bash
# The Python package in one command, offline: installs what is missing from Debian (scripts/deps.sh;
# nothing from PyPI), builds the extension in build/ (target sffd_python), a wheel into dist/ with
# Debian's setuptools, and installs it into .venv (made with --system-site-packages, so that Debian's
# numpy is seen). Then: .venv/bin/python -c "import sffd". The wheel carries libsffd: it keeps
# working when build/ is gone.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
python=/usr/bin/python3   # Debian's, whose numpy and pybind11 were installed (not a pyenv or conda one first on PATH)
[ -x .venv/bin/python ] || "$python" -m venv --system-site-packages .venv
rm -f dist/sffd-*.whl
SFFD_PYTHON="$python" .venv/bin/python -m pip wheel --quiet --no-build-isolation --no-deps --no-index -w dist ./python
.venv/bin/python -m pip install --quiet --no-deps --no-index --force-reinstall dist/sffd-*.whl
.venv/bin/python -c 'import sffd; print("sffd", sffd.__version__, "installed in .venv:", sffd.__file__)'
