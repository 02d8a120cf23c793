#!/bin/sh
# Writes the seed corpus for the bvh_parse fuzz target into fuzz/corpus/bvh_parse (gitignored):
# a few small hand-made BVH files and, when the data folder is present, the hierarchy and first
# two frames of each public data file (with `Frames:` set to 2 so each seed is a valid file).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
data=${MARIONETTE_DATA:-$here/../../shared/data}
out=$here/corpus/bvh_parse
mkdir -p "$out"

printf 'HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT Chest\n\t{\n\t\tOFFSET 0 10 0\n\t\tCHANNELS 3 Zrotation Xrotation Yrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 5 0\n\t\t}\n\t}\n}\nMOTION\nFrames: 2\nFrame Time: .0083333\n1 2 3 4 5 6 7 8 9\n-0 1e-06 .5 0 0 0 0 0 -1.5\n' > "$out/small_lf.bvh"
sed 's/$/\r/' "$out/small_lf.bvh" > "$out/small_crlf.bvh"
printf 'HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\n}\nMOTION\nFrames: 0\nFrame Time: 0.1\n' > "$out/no_channels.bvh"
printf 'HIERARCHY\nROOT r\n{\n  OFFSET 1 2 3\n  CHANNELS 1 Xrotation\n}\nROOT s\n{\n  OFFSET 0 0 0\n  CHANNELS 2 Yposition Zrotation\n  End Site\n  {\n    OFFSET 0 1 0\n  }\n}\nMOTION\nFrames:1\nFrame Time:0.5\n1 2 3\n4 5 6\n' > "$out/two_roots_extra_line.bvh"

if [ -d "$data" ]; then
  for f in "$data"/cmu/*.bvh "$data"/bandai/*.bvh; do
    name=$(basename "$f" .bvh)
    awk 'BEGIN{m=0} /^Frames:/{print "Frames: 2"; next} {print} /^Frame Time:/{m=1; n=0; next} m{n++; if(n>=2) exit}' "$f" > "$out/head_$name.bvh"
  done
else
  echo "data folder not found at $data; seeding with the hand-made files only"
fi
ls "$out" | wc -l

# Seeds of the other targets: scene_set (every scene file, then after a NUL byte a few
# overrides), dance_db (a manifest, and a database built by the marionette binary when one is
# built), checkpoint (the content of a tiny evolution's checkpoint, when the binary is built)
# and worker_protocol (a batch, and lines each worker must refuse).
root=$here/..
bin=${MARIONETTE_BIN:-$root/target/release/marionette}
mkdir -p "$here/corpus/scene_set" "$here/corpus/dance_db" "$here/corpus/checkpoint" "$here/corpus/worker_protocol"
for f in "$root"/scenes/*.ron; do
  name=$(basename "$f" .ron)
  cp "$f" "$here/corpus/scene_set/$name.ron"
  { cat "$f"; printf '\0name=fuzz\nrender.gif=false\nformat_version=2\nseeds=[1,x]\n'; } > "$here/corpus/scene_set/${name}_set.ron"
done
printf '(format_version: 1, clips: [(file: "dance_bars.ron", tempo_bpm: 120.0, first_beat_s: 0.0, window: (0.0, 8.0))])\n' > "$here/corpus/dance_db/manifest.ron"
printf '(format_version: 1, clips: [(file: "a.bvh", tempo: 120.0)])\n' > "$here/corpus/dance_db/manifest_typo.ron"
w=$here/corpus/worker_protocol
printf '{"genome":{"index":0,"genes":[1.5,2]}}\n{"genome":{"index":1,"genes":[1],"refine":2}}\n{"evaluate":{"count":2}}\n' > "$w/batch"
printf '{"genome":{"index":0,"genes":[1],"refin":2}}\n' > "$w/misspelt"
printf '{"genome":{"index":0,"genes":[1]},"evaluate":{"count":1}}\n' > "$w/two_messages"
printf '{"evaluate":false}\n' > "$w/evaluate_false"
if [ -x "$bin" ]; then
  tmp=$(mktemp -d)
  cp "$root/scenes/clips/dance_bars.ron" "$tmp/"
  cp "$here/corpus/dance_db/manifest.ron" "$tmp/manifest.ron"
  "$bin" dance db "$tmp/manifest.ron" --out "$tmp/db.json" >/dev/null 2>&1 \
    && cp "$tmp/db.json" "$here/corpus/dance_db/db.json"
  (cd "$root" && "$bin" run scenes/evolve_fall.ron --out "$tmp/out" --set 'groups=[adult]' \
    --set 'seeds=[1]' --set ga.population=4 --set ga.generations=1 --set render.gif=false \
    --set "checkpoint_dir=\"$tmp/ck\"" >/dev/null 2>&1) \
    && cp "$tmp/ck/checkpoint.json" "$here/corpus/checkpoint/checkpoint.json" \
    && sed 's/^.*"content"://; s/}$//' "$tmp/ck/checkpoint.json" > "$here/corpus/checkpoint/content.json"
  rm -rf "$tmp"
else
  echo "no marionette binary at $bin: the dance_db and checkpoint seeds are the hand-made ones only"
fi
printf '{"format_version":2,"checksum":"fnv1a64:0000000000000000","content":[]}\n' > "$here/corpus/checkpoint/empty.json"
for t in scene_set dance_db checkpoint worker_protocol; do
  echo "$t: $(ls "$here/corpus/$t" | wc -l) seeds"
done
