#!/usr/bin/env bash
# Reproduces docs/RESULTS.md: every table, sweep, chart and timing in it comes from this script.
#
#   bash scripts/results.sh            # everything from scratch (about 45 minutes on 2 cores)
#   RESUME=1 bash scripts/results.sh   # keep the reports already in build/results, run the rest
#   BIN=/some/dir SKIP_BUILD=1 ...     # run binaries copied elsewhere (rebuilding build/ meanwhile)
#
# Needs ../shared/data (the real characters); without it the script says so and stops. Each step
# writes one `animorder evaluate --report` JSON (or a benchmark's output) into build/results/, then
# build/make_results turns that folder into docs/RESULTS.md and docs/results/*.svg. The settings of
# each step are here and are printed into RESULTS.md from the reports themselves.
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
[ "${RESUME:-0}" = 1 ] || rm -rf "$OUT"
mkdir -p "$OUT/characters"
BIN=${BIN:-build}
A=$BIN/animorder
GANFAUL=$DATA/mixamo-ganfaul/Ganfaul.gltf
ALL=original,static-sander07,static-nehab06,tipsify-per-frame,meshopt,single,joint,oracle

# step NAME COMMAND...: runs the command unless NAME exists (RESUME=1), and times it.
step() {
  local name=$1; shift
  if [ -s "$OUT/$name" ]; then echo "results: $name kept"; return; fi
  echo "results: $name: $*" >&2
  local start=$SECONDS
  "$@"
  echo "results: $name took $((SECONDS - start)) s" >&2
}

# Table 1, Ganfaul's Idle clip, the paper's protocol: 300 random views per keyframe, 512x512.
step ganfaul-idle.json $A evaluate "$GANFAUL" --clip Idle -q --methods "${ALL/,joint/}" --lambda 0.85,3 \
  --eval-views 300 --eval-resolution 512 -r "$OUT/ganfaul-idle.json"
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
# Every other skinned character of ../shared/data, lambda 0.85 and 3, 60 views at 256x256.
character() {
  local name=$1; shift
  step "characters/$name.json" $A evaluate "$@" -q --methods "$ALL" --lambda 0.85,3 \
    --eval-views 60 --eval-resolution 256 -r "$OUT/characters/$name.json"
}
character xbot $DATA/glb-xbot/Xbot.glb
character barbarian $DATA/pg-barbarian/model.fbx --clip $DATA/pg-barbarian/anims
character goblin $DATA/pg-goblin/model.fbx --clip $DATA/pg-goblin/anims
character witch $DATA/pg-witch/model.fbx --clip $DATA/pg-witch/anims
character cesiumman $DATA/gltf-cesiumman/CesiumMan.glb
character fox $DATA/gltf-fox/Fox.glb
character robot-expressive $DATA/glb-robot-expressive/RobotExpressive.glb
character bob $DATA/md5-bob/Bob.md5mesh
character wuson $DATA/x-wuson/Testwuson.X
character dwarf $DATA/x-dwarf/dwarf.x
character dwarf2-b3d $DATA/b3d-dwarf2/dwarf2.b3d
character bcn-epileptic $DATA/x-bcn-epileptic/BCN_Epileptic.X
character mrfixit $DATA/iqm-mrfixit/mrfixit.iqm
# Measured cluster orders (issue 15: `measured`, `measured-joint`), beside `single` in the same runs
# (same nodes, same bootstrap), in build/results/measured/: Table 1's setting on Idle; the k sweep
# (OVR and index-buffer bytes against k) with static-nehab06 for k = 1; every Ganfaul clip at the
# lighter every-clip setting; and every skinned character at lambda 0.85 and 3.
mkdir -p "$OUT/measured"
step measured/ganfaul-idle.json $A evaluate "$GANFAUL" --clip Idle -q --methods single,measured \
  --lambda 0.85,3 --eval-views 300 --eval-resolution 512 -r "$OUT/measured/ganfaul-idle.json"
step measured/sweep-k.json $A evaluate "$GANFAUL" --clip Idle -q --methods single,measured,static-nehab06 \
  -k 1,2,3,5,8,12,16 --eval-views 100 --eval-resolution 256 -r "$OUT/measured/sweep-k.json"
step measured/ganfaul-clips.json $A evaluate "$GANFAUL" -q --methods single,joint,measured,measured-joint \
  --lambda 0.85 --resolution 128 --eval-views 60 --eval-resolution 256 -r "$OUT/measured/ganfaul-clips.json"
measured_character() {
  local name=$1; shift
  step "measured/$name.json" $A evaluate "$@" -q --methods single,measured --lambda 0.85,3 \
    --eval-views 60 --eval-resolution 256 -r "$OUT/measured/$name.json"
}
measured_character xbot $DATA/glb-xbot/Xbot.glb
measured_character barbarian $DATA/pg-barbarian/model.fbx --clip $DATA/pg-barbarian/anims
measured_character goblin $DATA/pg-goblin/model.fbx --clip $DATA/pg-goblin/anims
measured_character witch $DATA/pg-witch/model.fbx --clip $DATA/pg-witch/anims
measured_character cesiumman $DATA/gltf-cesiumman/CesiumMan.glb
measured_character fox $DATA/gltf-fox/Fox.glb
measured_character robot-expressive $DATA/glb-robot-expressive/RobotExpressive.glb
measured_character bob $DATA/md5-bob/Bob.md5mesh
measured_character wuson $DATA/x-wuson/Testwuson.X
measured_character dwarf $DATA/x-dwarf/dwarf.x
measured_character dwarf2-b3d $DATA/b3d-dwarf2/dwarf2.b3d
measured_character bcn-epileptic $DATA/x-bcn-epileptic/BCN_Epileptic.X
measured_character mrfixit $DATA/iqm-mrfixit/mrfixit.iqm
# The OpenGL rendering-time check (original vs single, expensive fragment shader).
# llvmpipe renders on the CPU: 10 views at every 4th keyframe (150 nodes) keeps it near a minute.
if [ -x "$BIN/bench/render_time" ]; then
  step render-time.json "$BIN/bench/render_time" "$GANFAUL" --clip Idle --views 10 --keyframe-stride 4 \
    --quiet --json "$OUT/render-time.json"
fi
# Nehab 2006's preprocessing time against Tootle's published 0.7-3.3 s.
if [ -x "$BIN/bench/bench_nehab06" ]; then
  [ -s "$OUT/nehab06-bench.txt" ] || "$BIN/bench/bench_nehab06" > "$OUT/nehab06-bench.txt"
fi
# The prose around the numbers (what differs from the paper and why) is committed beside them.
cp docs/results-notes/notes-*.md "$OUT"/
"$BIN/make_results" "$OUT" docs
echo "results: wrote docs/RESULTS.md and docs/results/"
