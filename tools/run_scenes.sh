#!/usr/bin/env bash
# Runs every scene in scenes/ (the ones on ${MARIONETTE_DATA} only when the data is there) and
# prints each scene's output folder and the pictures to look at; stops at the first failure.
set -euo pipefail
cd "$(dirname "$0")/.."
export MARIONETTE_DATA="${MARIONETTE_DATA:-$(cd .. && pwd)/shared/data}"
cargo build --release --quiet
for scene in scenes/*.ron; do
  if grep -q 'MARIONETTE_DATA' "$scene" && [ ! -d "$MARIONETTE_DATA" ]; then
    echo "skip $scene (MARIONETTE_DATA=$MARIONETTE_DATA is absent)"
    continue
  fi
  ./target/release/marionette run "$scene" > /dev/null
  dir="out/$(basename "$scene" .ron)"
  echo "ok   $scene -> $dir/ (pictures: $(cd "$dir" && ls *.png *.gif 2>/dev/null | tr '\n' ' '))"
done
