#!/usr/bin/env bash
# Reproduces docs/RESULTS.md: every table, sweep, chart and timing in it comes from this script.
#
#   bash scripts/results.sh            # everything from scratch (60-90 minutes on 2 loaded cores)
#   RESUME=1 bash scripts/results.sh   # keep the reports already in build/results, run the rest
#   BIN=/some/dir SKIP_BUILD=1 ...     # run binaries copied elsewhere (rebuilding build/ meanwhile)
#   STEPS_FROM_LOG=results.log RESUME=1 ...  # kept reports of an older run: commands from its log
#   ONLY=measured/,sweep-k RESUME=1 ...  # only the steps whose names start with one of these prefixes;
#       docs/results/reports then gets only those files replaced (its other files and their rows in
#       MANIFEST.md, SHA256SUMS and steps.tsv stay as they are) before RESULTS.md is regenerated
#
# Needs ../shared/data (the real characters); without it the script says so and stops. Each step
# writes one `animorder evaluate --report` JSON (or a benchmark's output) into build/results/ and
# records its name, wall time and exact command line in build/results/steps.tsv. At the end the
# reports (JSON and text, each under 300 KB) are kept in docs/results/reports/ with MANIFEST.md
# (each file's sha256 and command; larger outputs are listed there, not kept) and SHA256SUMS, and
# build/make_results turns the kept reports into docs/RESULTS.md, docs/results/*.svg and README.md's
# generated block; the notes' figures are placeholders resolved from the same reports. To add a
# method or a benchmark: append a `step` (or `step_stdout`) line below.
set -euo pipefail
cd "$(dirname "$0")/.."
DATA=../shared/data
OUT=build/results
if [ ! -d "$DATA/mixamo-ganfaul" ]; then
  echo "results: $DATA is absent; the results need the real characters (see $DATA/README.md)" >&2
  exit 1
fi
if [ "${SKIP_BUILD:-0}" != 1 ]; then
  bash scripts/install-deps.sh
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
  cmake --build build -j"$(nproc)"
fi
[ "${RESUME:-0}" = 1 ] || [ -n "${ONLY:-}" ] || rm -rf "$OUT"
mkdir -p "$OUT/characters"
BIN=${BIN:-build}
A=$BIN/animorder
GANFAUL=$DATA/mixamo-ganfaul/Ganfaul.gltf
ALL=original,static-sander07,static-nehab06,tipsify-per-frame,meshopt,single,joint,oracle

# step NAME COMMAND...: runs the command (which writes $OUT/NAME) unless NAME exists (RESUME=1),
# times it and records NAME, the seconds and the command line in $OUT/steps.tsv.
# step_stdout NAME COMMAND...: the same for a command that prints its output: stdout into $OUT/NAME.
STEPS=$OUT/steps.tsv
record() {
  local name=$1 seconds=$2; shift 2
  [ -s "$STEPS" ] || printf 'name\tseconds\tcommand\n' > "$STEPS"
  awk -F'\t' -v n="$name" '$1 != n' "$STEPS" > "$STEPS.tmp"
  printf '%s\t%s\t%s\n' "$name" "$seconds" "$*" >> "$STEPS.tmp"
  mv "$STEPS.tmp" "$STEPS"
}
# selected NAME: NAME starts with one of ONLY's comma-separated prefixes (every name without ONLY).
selected() {
  [ -n "${ONLY:-}" ] || return 0
  local prefix
  for prefix in ${ONLY//,/ }; do
    case "$1" in "$prefix"*) return 0 ;; esac
  done
  return 1
}
run_step() {
  local name=$1 to_stdout=$2; shift 2
  if ! selected "$name"; then echo "results: $name not selected (ONLY=$ONLY)"; return; fi
  if [ -s "$OUT/$name" ]; then echo "results: $name kept"; return; fi
  echo "results: $name: $*" >&2
  local start end
  start=$(date +%s.%N)
  if [ "$to_stdout" = 1 ]; then
    "$@" > "$OUT/$name.tmp"   # set -e stops the script here when the command fails
    mv "$OUT/$name.tmp" "$OUT/$name"
  else
    "$@"
  fi
  end=$(date +%s.%N)
  local seconds
  seconds=$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')
  local command
  command=$(printf '%q ' "$@")  # shell-quoted: the line can be pasted back
  record "$name" "$seconds" "${command% }$([ "$to_stdout" = 1 ] && echo " > $OUT/$name")"
  echo "results: $name took $seconds s" >&2
}
step() { run_step "$1" 0 "${@:2}"; }
step_stdout() { run_step "$1" 1 "${@:2}"; }
# STEPS_FROM_LOG=FILE (with RESUME=1): reports kept from a run of an older version of this script,
# which wrote no steps.tsv, get their command and seconds from that run's stderr log (its
# "results: NAME: COMMAND" and "results: NAME took N s" lines).
if [ -n "${STEPS_FROM_LOG:-}" ]; then
  awk '/^results: [^ ]+: / { n = $2; sub(/:$/, "", n); c = $0; sub(/^results: [^ ]+: /, "", c); cmd[n] = c; order[++k] = n }
       /^results: [^ ]+ took [0-9.]+ s$/ { t[$2] = $4 }
       END { for (i = 1; i <= k; i++) if (order[i] in t) print order[i] "\t" t[order[i]] "\t" cmd[order[i]] }' \
    "$STEPS_FROM_LOG" | while IFS=$'\t' read -r name seconds command; do
    if [ -s "$OUT/$name" ] && ! { [ -s "$STEPS" ] && cut -f1 "$STEPS" | grep -qxF "$name"; }; then
      record "$name" "$seconds" "$command"
    fi
  done
fi

# Table 1, Ganfaul's Idle clip, the paper's protocol: 300 random views per keyframe, 512x512.
step ganfaul-idle.json $A evaluate "$GANFAUL" --clip Idle -q --methods "${ALL/,joint/}" --lambda 0.85,3 \
  --eval-views 300 --eval-resolution 512 -r "$OUT/ganfaul-idle.json"
# Table 1's ACMR note: the original order (Tipsify) with a 32-entry FIFO.
step ganfaul-idle-cache32.json $A optimize -m original --cache-size 32 "$GANFAUL" --clip Idle -q \
  --report "$OUT/ganfaul-idle-cache32.json"
# The Loop-subdivided levels (13.8k -> 55k -> 220k triangles), one subdivision operator for all keyframes.
for level in 1 2; do
  step "ganfaul-idle-sub$level.glb" $A subdivide "$GANFAUL" --clip Idle --levels $level -q -o "$OUT/ganfaul-idle-sub$level.glb"
done
step ganfaul-idle-sub1.json $A evaluate "$OUT/ganfaul-idle-sub1.glb" -q \
  --methods original,static-sander07,static-nehab06,tipsify-per-frame,single,oracle --lambda 0.85,3 \
  --eval-views 300 --eval-resolution 512 -r "$OUT/ganfaul-idle-sub1.json"
step ganfaul-idle-sub2.json $A evaluate "$OUT/ganfaul-idle-sub2.glb" -q \
  --methods original,static-sander07,static-nehab06,tipsify-per-frame,single,oracle --lambda 0.85 \
  --eval-views 100 --eval-resolution 512 -r "$OUT/ganfaul-idle-sub2.json"
# All twelve Ganfaul clips (1,079 keyframes): per-clip OVR (Fig. 8) and k-means time per clip (Fig. 5).
# Clustering at 128x128 keeps joint's fragments of 174,798 nodes in memory (6 GiB); 60 views at 256x256.
step ganfaul-clips.json $A evaluate "$GANFAUL" -q --methods "$ALL" \
  --lambda 0.85,3 --resolution 128 --eval-views 60 --eval-resolution 256 -r "$OUT/ganfaul-clips.json"
# Sweeps on Idle (Figs. 3, 6, 7), 100 views at 256x256.
step sweep-views.json $A evaluate "$GANFAUL" --clip Idle -q --methods single --views 12,42,162,642 \
  --eval-views 100 --eval-resolution 256 -r "$OUT/sweep-views.json"
step sweep-lambda.json $A evaluate "$GANFAUL" --clip Idle -q --methods original,static-sander07,single,oracle \
  --lambda 0.7,0.85,1,1.5,2,3 --eval-views 100 --eval-resolution 256 -r "$OUT/sweep-lambda.json"
step sweep-k.json $A evaluate "$GANFAUL" --clip Idle -q --methods single -k 1,2,3,5,7,10 \
  --eval-views 100 --eval-resolution 256 -r "$OUT/sweep-k.json"
# The skinned characters of ../shared/data, each as FUNC NAME INPUT [--clip CLIPS]: one list for
# every per-character step.
each_character() {
  "$1" xbot $DATA/glb-xbot/Xbot.glb
  "$1" barbarian $DATA/pg-barbarian/model.fbx --clip $DATA/pg-barbarian/anims
  "$1" goblin $DATA/pg-goblin/model.fbx --clip $DATA/pg-goblin/anims
  "$1" witch $DATA/pg-witch/model.fbx --clip $DATA/pg-witch/anims
  "$1" cesiumman $DATA/gltf-cesiumman/CesiumMan.glb
  "$1" fox $DATA/gltf-fox/Fox.glb
  "$1" robot-expressive $DATA/glb-robot-expressive/RobotExpressive.glb
  "$1" bob $DATA/md5-bob/Bob.md5mesh
  "$1" wuson $DATA/x-wuson/Testwuson.X
  "$1" dwarf $DATA/x-dwarf/dwarf.x
  "$1" dwarf2-b3d $DATA/b3d-dwarf2/dwarf2.b3d
  "$1" bcn-epileptic $DATA/x-bcn-epileptic/BCN_Epileptic.X
  "$1" mrfixit $DATA/iqm-mrfixit/mrfixit.iqm
}
# Every other skinned character of ../shared/data, lambda 0.85 and 3, 60 views at 256x256.
character() {
  local name=$1; shift
  step "characters/$name.json" $A evaluate "$@" -q --methods "$ALL" --lambda 0.85,3 \
    --eval-views 60 --eval-resolution 256 -r "$OUT/characters/$name.json"
}
each_character character
# static-nehab06 with --nehab-all-keyframes against the default (first keyframe), the same
# evaluation as the character tables (their static-nehab06 rows are the default's).
mkdir -p "$OUT/nehab06-keyframes"
nehab_keyframes() {
  local name=$1; shift
  step "nehab06-keyframes/$name.json" $A evaluate "$@" -q --methods static-nehab06 \
    --eval-views 60 --eval-resolution 256 -r "$OUT/nehab06-keyframes/$name.json"
}
nehab_keyframes character                     # no input: the bundled character
nehab_keyframes character-all --nehab-all-keyframes
nehab_keyframes mrfixit-all $DATA/iqm-mrfixit/mrfixit.iqm --nehab-all-keyframes
nehab_keyframes dwarf2-b3d-all $DATA/b3d-dwarf2/dwarf2.b3d --nehab-all-keyframes
# Issue 18, materials (build/results/materials/, RESULTS.md's "Materials"): the bundled
# character's blended hair cards and cape — the blend table of `evaluate` (input order, original,
# static-sander07 and static-nehab06 reversed, k = 5 buffers on the opaque clusters, the same with their own blend
# clusters, the per-node back-to-front bound) — and MorphStressTest's double-sided materials (Xbot's
# are in characters/xbot.json). 100 views at 256x256.
mkdir -p "$OUT/materials"
step materials/bundled.json $A evaluate -q --methods original,static-sander07,static-nehab06,single \
  --eval-views 100 --eval-resolution 256 -r "$OUT/materials/bundled.json"
step materials/bundled-blend-clusters.json $A evaluate -q --methods original,single --blend-clusters \
  --eval-views 100 --eval-resolution 256 -r "$OUT/materials/bundled-blend-clusters.json"
step materials/morph-stress-test.json $A evaluate "$DATA/gltf-morph-stress-test/MorphStressTest.gltf" -q \
  --methods original,static-sander07,single --eval-views 60 --eval-resolution 256 -r "$OUT/materials/morph-stress-test.json"
# The cost of double-sided materials: the same runs with every material culled (`--single-sided`,
# orders and OVR as before issue 18), MorphStressTest and Xbot's walk clip.
step materials/morph-stress-test-single-sided.json $A evaluate "$DATA/gltf-morph-stress-test/MorphStressTest.gltf" -q \
  --single-sided --methods original,static-sander07,single --eval-views 60 --eval-resolution 256 \
  -r "$OUT/materials/morph-stress-test-single-sided.json"
step materials/xbot-walk.json $A evaluate "$DATA/glb-xbot/Xbot.glb" --clip walk -q \
  --methods original,static-sander07,static-nehab06,single --eval-views 60 --eval-resolution 256 -r "$OUT/materials/xbot-walk.json"
step materials/xbot-walk-single-sided.json $A evaluate "$DATA/glb-xbot/Xbot.glb" --clip walk -q --single-sided \
  --methods original,static-sander07,static-nehab06,single --eval-views 60 --eval-resolution 256 \
  -r "$OUT/materials/xbot-walk-single-sided.json"
# Measured cluster orders (issue 15: `measured`, `measured-joint`), beside `single` in the same runs
# (same nodes, same bootstrap), in build/results/measured/: Table 1's setting on Idle; the k sweep
# (OVR and index-buffer bytes against k) with static-nehab06 for k = 1; every Ganfaul clip at the
# lighter every-clip setting; and every skinned character at lambda 0.85 and 3.
mkdir -p "$OUT/measured"
step measured/ganfaul-idle.json $A evaluate "$GANFAUL" --clip Idle -q --methods single,measured \
  --lambda 0.85,3 --eval-views 300 --eval-resolution 512 -r "$OUT/measured/ganfaul-idle.json"
# The same, counting every depth level in front (--front-levels 0) instead of the nearest two.
step measured/ganfaul-idle-every-level.json $A evaluate "$GANFAUL" --clip Idle -q --methods measured \
  --front-levels 0 --lambda 0.85,3 --eval-views 300 --eval-resolution 512 \
  -r "$OUT/measured/ganfaul-idle-every-level.json"
step measured/sweep-k.json $A evaluate "$GANFAUL" --clip Idle -q --methods single,measured,static-nehab06 \
  -k 1,2,3,5,8,12,16 --eval-views 100 --eval-resolution 256 -r "$OUT/measured/sweep-k.json"
step measured/ganfaul-clips.json $A evaluate "$GANFAUL" -q --methods single,joint,measured,measured-joint \
  --lambda 0.85 --resolution 128 --eval-views 60 --eval-resolution 256 -r "$OUT/measured/ganfaul-clips.json"
measured_character() {
  local name=$1; shift
  step "measured/$name.json" $A evaluate "$@" -q --methods single,measured --lambda 0.85,3 \
    --eval-views 60 --eval-resolution 256 -r "$OUT/measured/$name.json"
}
each_character measured_character
# Why measured loses to single on Xbot at lambda 3 (RESULTS.md): single-triangle units learnt from the
# few nodes of a 2-keyframe pose, with the default 162 and with 642 learnt views per keyframe.
mkdir -p "$OUT/measured-views"
for views in 162 642; do
  step "measured-views/xbot-sad-pose-$views.json" $A evaluate $DATA/glb-xbot/Xbot.glb --clip sad_pose -q \
    --methods single,measured --lambda 3 --views $views --eval-views 60 --eval-resolution 256 \
    -r "$OUT/measured-views/xbot-sad-pose-$views.json"
done
# The OpenGL rendering-time check (original vs single, expensive fragment shader).
# llvmpipe renders on the CPU: 10 views at every 4th keyframe (150 nodes) keeps it near a minute.
if [ -x "$BIN/bench/render_time" ]; then
  step render-time.json "$BIN/bench/render_time" "$GANFAUL" --clip Idle --views 10 --keyframe-stride 4 \
    --quiet --json "$OUT/render-time.json"
fi
# Nehab 2006's preprocessing time against Tootle's published 0.7-3.3 s.
if [ -x "$BIN/bench/bench_nehab06" ]; then
  step_stdout nehab06-bench.txt "$BIN/bench/bench_nehab06"
fi
# docs/benchmarks.md, "Performance": Tipsify against meshoptimizer (medians of interleaved repetitions), the
# overdraw engine against llvmpipe, and Han & Sander's preprocessing of Ganfaul Idle with its stages.
if [ -x "$BIN/bench/bench_tipsify" ]; then
  step_stdout bench-tipsify.txt "$BIN/bench/bench_tipsify" --benchmark_repetitions=5 \
    --benchmark_enable_random_interleaving=true --benchmark_color=false
fi
if [ -x "$BIN/bench/bench_overdraw" ]; then
  step_stdout bench-overdraw.txt "$BIN/bench/bench_overdraw"
fi
# Issue 19's production scale: whole sets with their peak memory, each case in a process of its own
# (the engine-ratio case is bench-overdraw.txt above).
# The per-node cost on one thread (thread CPU time), the rasteriser's portable and AVX2 copies in one run.
if [ -x "$BIN/bench/bench_raster" ]; then
  step_stdout bench-raster-ganfaul-idle.txt "$BIN/bench/bench_raster" "$GANFAUL" --clip Idle --simd all
  step_stdout bench-raster-xbot.txt "$BIN/bench/bench_raster" $DATA/glb-xbot/Xbot.glb --simd all
fi
if [ -x "$BIN/bench/bench_scale" ]; then
  step_stdout bench-scale.txt "$BIN/bench/bench_scale" --rounds 3 ganfaul-joint xbot-single xbot-single-sided clip60-single
fi
# The per-clip cases against the engine that issue 19's "today" figures came from (built by
# scripts/build-baseline.sh), each case run by both builds one after the other: a speed-up holds
# on any processor, where the goals' seconds belong to the machine that filed the issue.
if [ -x "$BIN/bench/bench_scale" ] && selected bench-baseline.txt && [ ! -s "$OUT/bench-baseline.txt" ]; then
  BASELINE_ANIMORDER=$(bash scripts/build-baseline.sh | tail -n 1)
  step_stdout bench-baseline.txt "$BIN/bench/bench_scale" --baseline "$BASELINE_ANIMORDER" --rounds 5 xbot-single xbot-single-sided clip60-single
fi
# Issue 52: the Python module's overhead over the CLI, Ganfaul Idle with the default method, each
# a whole process, rounds interleaved (goal: at most 5% over the CLI's time).
if ls "$BIN"/python/animorder*.so > /dev/null 2>&1; then
  step_stdout bench-python.txt env PYTHONPATH="$BIN/python" /usr/bin/python3 bench/bench_python.py "$BIN/animorder" \
    "$GANFAUL" --clip Idle --rounds 5
fi
mkdir -p "$OUT/out"
step optimize-ganfaul-idle.json $A optimize --method single "$GANFAUL" --clip Idle -q \
  -o "$OUT/out/ganfaul-idle" --report "$OUT/optimize-ganfaul-idle.json"

# Keep the reports: every JSON, TSV and text report under 300 KB is copied into docs/results/reports
# (larger ones, and the subdivided meshes, are listed in MANIFEST.md with their sha256 only).
KEEP=docs/results/reports
# With ONLY, the rows of the files not selected are taken from the kept MANIFEST.md, SHA256SUMS and
# steps.tsv (their files stay); the selected files and steps.tsv are written afresh below.
ROWS=$(mktemp) SUMS=$(mktemp) OLD_STEPS=$(mktemp)
trap 'rm -f "$ROWS" "$SUMS" "$OLD_STEPS"' EXIT
if [ -n "${ONLY:-}" ] && [ -s "$KEEP/MANIFEST.md" ]; then
  sed -n 's/^| `\([^`]*\)` | .*/\1\t&/p' "$KEEP/MANIFEST.md" | while IFS=$'\t' read -r f row; do
    if [ "$f" != steps.tsv ] && ! selected "$f"; then printf '%s\t%s\n' "$f" "$row"; fi
  done > "$ROWS"
  awk '{ f = $0; sub(/^[0-9a-f]+  /, "", f); print f "\t" $0 }' "$KEEP/SHA256SUMS" | while IFS=$'\t' read -r f row; do
    if [ "$f" != steps.tsv ] && ! selected "$f"; then printf '%s\t%s\n' "$f" "$row"; fi
  done > "$SUMS"
  tail -n +2 "$KEEP/steps.tsv" | while IFS=$'\t' read -r f rest; do
    selected "$f" || printf '%s\t%s\n' "$f" "$rest"
  done > "$OLD_STEPS"
  # steps.tsv: the kept rows of the steps not selected, then this run's rows of the selected ones.
  { printf 'name\tseconds\tcommand\n'; cat "$OLD_STEPS"
    [ -s "$STEPS" ] && tail -n +2 "$STEPS" | while IFS=$'\t' read -r f rest; do
      selected "$f" && printf '%s\t%s\n' "$f" "$rest"; done; true; } > "$STEPS.merged"
  mv "$STEPS.merged" "$STEPS"
  while IFS= read -r f; do if selected "$f"; then rm -f "$KEEP/$f"; fi; done < <(cd "$KEEP" && find . -type f | sed 's|^\./||')
else
  rm -rf "$KEEP"
fi
mkdir -p "$KEEP"
{
  echo "# The reports behind docs/RESULTS.md"
  echo
  echo "Written by \`scripts/results.sh\`; \`sha256sum -c SHA256SUMS\` checks the kept files. Commands ran from the"
  echo "repository root (\`$BIN\` holds the binaries)."
  echo
  echo "| file | kept | bytes | sha256 | seconds | command |"
  echo "|---|---|---|---|---|---|"
} > "$KEEP/MANIFEST.md"
(cd "$OUT" && find . -type f \( -name '*.json' -o -name '*.txt' -o -name '*.tsv' -o -name '*.glb' \) \
  ! -path './out/*' ! -name '*.tmp' | sed 's|^\./||' | LC_ALL=C sort) | while read -r f; do
  if [ -n "${ONLY:-}" ] && [ "$f" != steps.tsv ] && ! selected "$f"; then continue; fi
  bytes=$(stat -c %s "$OUT/$f")
  sum=$(sha256sum "$OUT/$f" | cut -d' ' -f1)
  kept=no
  if [ "$bytes" -le 307200 ] && [ "${f##*.}" != glb ]; then
    mkdir -p "$KEEP/$(dirname "$f")"
    cp "$OUT/$f" "$KEEP/$f"
    printf '%s\t%s  %s\n' "$f" "$sum" "$f" >> "$SUMS"
    kept=yes
  fi
  line=$(awk -F'\t' -v n="$f" '$1 == n { print $2 "\t" $3 }' "$STEPS" 2>/dev/null || true)
  seconds=${line%%$'\t'*}; command=${line#*$'\t'}
  printf '%s\t%s\n' "$f" "| \`$f\` | $kept | $bytes | \`$sum\` | ${seconds:-—} | \`${command:-—}\` |" >> "$ROWS"
done
LC_ALL=C sort -t$'\t' -k1,1 "$ROWS" | cut -f2- >> "$KEEP/MANIFEST.md"
LC_ALL=C sort -t$'\t' -k1,1 "$SUMS" | cut -f2- > "$KEEP/SHA256SUMS"
"$BIN/make_results" --notes docs/results-notes --readme README.md "$KEEP" docs
echo "results: wrote docs/RESULTS.md, docs/results/ and README.md's generated block"
