#!/usr/bin/env bash
# CI for the NASTRAN extra: pyNastran 1.4.1 pins numpy < 2 (np.in1d), so it gets its own
# virtual environment.  Installs microg with pyNastran, pyyeti and pyuff there and runs the
# modal-model tests (those that need pyNastran importorskip it, so they run only here).
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
VENV=$(mktemp -d)/venv-nastran
"$PY" -m venv "$VENV"
# shellcheck disable=SC1091
source "$VENV/bin/activate"
python -m pip install --quiet --upgrade pip
python -m pip install --quiet "numpy<2" "pyNastran==1.4.1" "pyyeti>=1.4.7" "pyuff>=2.4" \
  pytest pytest-timeout hypothesis
python -m pip install --quiet --no-deps -e . && python -m pip install --quiet .
python -c "import numpy, pyNastran; print('nastran extra env: numpy', numpy.__version__, 'pyNastran', pyNastran.__version__)"
if python -m pytest --markers 2>/dev/null | grep -q "@pytest.mark.nastran"; then
  python -m pytest -q -m nastran
else
  python -m pytest -q tests/models/test_modal.py tests/models/test_nastran.py \
    tests/models/test_uff.py tests/structure/test_structure_modal.py \
    tests/validation/test_nastran_op2.py
fi
