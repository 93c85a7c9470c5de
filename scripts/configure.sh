# Sourced by scripts/demo.sh and scripts/test.sh: one configuration of build/ for both, so the
# demo's tool and the tests' build share every object file. Extra arguments only choose which
# targets exist; none changes a compile flag.
configure_build() {
  local dir="$1"
  shift
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DANIMORDER_WERROR=ON "$@" >/dev/null
}
