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
