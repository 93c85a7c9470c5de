#!/usr/bin/env bash
# Times the newcomer's path (issue 48): a fresh clone of this repository's HEAD beside it (so
# ../shared is where the tests look for it), an empty compiler cache, then the README's two
# commands in order, `bash scripts/demo.sh` and `bash scripts/test.sh`, each timed to its last
# output. Prints each wall time against its goal and ends with one JSON line.
#
#   bash scripts/time-newcomer.sh                    # packages as this machine has them
#   bash scripts/time-newcomer.sh --purge-packages   # THROWAWAY MACHINES ONLY: first removes the
#                                                    # Debian packages install-deps.sh installs
#
# Without --purge-packages the times leave out installing packages the machine already has (say
# so when you quote them). The clone is removed afterwards unless KEEP=1.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
purge=0
case "${1:-}" in
  "") ;;
  --purge-packages) purge=1 ;;
  *) echo "time-newcomer: unknown option '$1' (use --purge-packages, or nothing)" >&2; exit 2 ;;
esac
demo_goal=180 test_goal=420

if [ "$purge" = 1 ]; then
  # Every package name install-deps.sh lists, as it lists them (one per array entry).
  # Every package name install-deps.sh lists that is installed and that a fresh Debian does not
  # have (not essential or important: apt would refuse to remove util-linux, say, and everything
  # with it), as install-deps.sh lists them (one per array entry).
  mapfile -t listed < <(sed -n '/^tool_packages=(/,/^)/p; /^packages=(/,/^)/p' "$here/scripts/install-deps.sh" |
    grep -v '^[a-z_]*=(\|^)' | sed 's/#.*//' | tr ' ' '\n' | grep -v '^$' | grep -v '^build-essential$\|^cmake$\|^pkg-config$')
  listed+=(gltfpack python3-jsonschema chromium)
  packages=()
  for p in "${listed[@]}"; do
    fields=$(dpkg-query -W -f='${Status} ${Essential} ${Priority}' "$p" 2>/dev/null || true)
    case "$fields" in
      "install ok installed no "*) case "$fields" in *important | *required) ;; *) packages+=("$p") ;; esac ;;
      "install ok installed "*) ;;  # essential
    esac
  done
  echo "time-newcomer: removing ${packages[*]}" >&2
  DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq "${packages[@]}" >/dev/null
  DEBIAN_FRONTEND=noninteractive apt-get autoremove -y -qq >/dev/null
  apt-get clean
fi

clone="$(mktemp -d "$(dirname "$here")/newcomer.XXXXXX")"
[ "${KEEP:-0}" = 1 ] || trap 'rm -rf "$clone"' EXIT
git clone -q "$here" "$clone/animorder"
export CCACHE_DIR="$clone/ccache"  # a newcomer's cache is empty
cd "$clone/animorder"

run_timed() {  # name, log → seconds on stdout
  local start end
  start=$(date +%s.%N)
  if ! bash "scripts/$1.sh" >"$clone/$1.log" 2>&1; then
    echo "time-newcomer: scripts/$1.sh failed; its log ends:" >&2
    tail -n 30 "$clone/$1.log" >&2
    exit 1
  fi
  end=$(date +%s.%N)
  awk -v s="$start" -v e="$end" 'BEGIN { printf "%.0f", e - s }'
}
demo_s=$(run_timed demo)
echo "scripts/demo.sh: ${demo_s} s (goal ${demo_goal} s)" >&2
test_s=$(run_timed test)
echo "scripts/test.sh: ${test_s} s (goal ${test_goal} s)" >&2
tests=$(grep -o '[0-9]* tests failed out of [0-9]*' "$clone/test.log" | tail -n 1)
printf '{"demo_s": %s, "test_s": %s, "demo_goal_s": %s, "test_goal_s": %s, "packages_purged": %s, "ctest": "%s", "cores": %s}\n' \
  "$demo_s" "$test_s" "$demo_goal" "$test_goal" "$([ "$purge" = 1 ] && echo true || echo false)" "$tests" "$(nproc)"
