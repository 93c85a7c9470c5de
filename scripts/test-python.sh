#!/usr/bin/env bash
# The Python module's tests (python/tests, pytest) with Debian's python3, from CTest:
#   test-python.sh MODULE_DIR ANIMORDER_EXE
# Without the module (pybind11 absent at configure time) or pytest/numpy: skipped (exit 77) with
# the reason, failed where ANIMORDER_REQUIRE names "python".
set -uo pipefail
module_dir=$1
export ANIMORDER_EXE=$2
python=/usr/bin/python3
[ -x "$python" ] || python=python3
why=""
if ! ls "$module_dir"/animorder*.so > /dev/null 2>&1; then
  why="the Python module was not built (python3-pybind11 and python3-dev at configure time)"
elif ! "$python" -c "import numpy, pytest" 2> /dev/null; then
  why="$python lacks numpy or pytest (Debian: python3-numpy, python3-pytest)"
fi
if [ -n "$why" ]; then
  case ",${ANIMORDER_REQUIRE:-}," in
    *,python,*|*,all,*) echo "$why (required: ANIMORDER_REQUIRE)"; exit 1 ;;
  esac
  echo "skipped: $why"
  exit 77
fi
cd "$(dirname "$0")/../python/tests" || exit 1
PYTHONDONTWRITEBYTECODE=1 PYTHONPATH="$module_dir" exec "$python" -m pytest -q -p no:cacheprovider .
