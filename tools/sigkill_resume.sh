#!/usr/bin/env bash
# Kill an evolution with SIGKILL at random moments and check that resuming it gives the same
# bits as an uninterrupted run (issue 38).
#
#   tools/sigkill_resume.sh [TRIALS]          (default 20)
#
# Environment: MARIONETTE_BIN (default target/release/marionette), SEED (the kill times'
# random seed, default 38), KILLS (kills per trial, each at a random moment of a run or of a
# resume, before the last resume runs to the end; default 1).
#
# A small scenes/evolve_fall.ron (both groups, seeds 1 and 2, 10 chromosomes, 50 generations)
# runs once uninterrupted into a reference folder. Each trial then starts the same run into a
# fresh folder at the same path, kills it with `kill -9` at a random moment within the
# reference run's duration (so the kill may fall in the GA or while the outputs are written;
# a run that finishes before its kill is started again with a new draw within its duration),
# resumes it with `--resume` (or starts it again if no checkpoint was written yet) until it
# completes, and compares with the reference bit for bit: every output file, report.json but
# its two wall times (`wall_time_s`, `ga_wall_time_s`), and the checkpoint. The output and
# checkpoint paths are the same in every run, so the report's `checkpoint` path matches too.
# Exits non-zero if any trial differs.
set -euo pipefail

TRIALS=${1:-20}
SEED=${SEED:-38}
KILLS=${KILLS:-1}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${MARIONETTE_BIN:-$ROOT/target/release/marionette}
SCENE=$ROOT/scenes/evolve_fall.ron
SETS=(--set ga.population=10 --set ga.generations=50 --set 'seeds=[1,2]')

[[ -x $BIN ]] || { echo "no binary at $BIN (cargo build --release, or set MARIONETTE_BIN)" >&2; exit 2; }
command -v jq >/dev/null || { echo "jq is needed (the generation a kill reached)" >&2; exit 2; }
[[ $TRIALS =~ ^[0-9]+$ && $KILLS =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [TRIALS]; KILLS ≥ 1" >&2; exit 2; }

T=$(mktemp -d)
child=
cleanup() {
    if [[ -n $child ]]; then kill -9 "$child" 2>/dev/null || true; fi
    rm -rf "$T"
}
trap cleanup EXIT

RUN=$T/run/out          # every run writes here: outputs in out/, checkpoint in out.checkpoint/
CK=$RUN.checkpoint
now_ms() { echo $(( $(date +%s%N) / 1000000 )); }

# The generation the checkpoint is at ("-" if none was written).
ck_generation() {
    if [[ -f $CK/checkpoint.json ]]; then
        jq '[.content[].state.generation] | min' "$CK/checkpoint.json" 2>/dev/null || echo "unreadable"
    else
        echo "-"
    fi
}

# Starts `marionette run` (with the given extra arguments) in the background, logging to LOG.
start_run() {
    "$BIN" run "$SCENE" --out "$RUN" "${SETS[@]}" "$@" >>"$LOG" 2>&1 &
    child=$!
}

# Waits for the background run; sets rc.
wait_run() {
    rc=0
    wait "$child" 2>/dev/null || rc=$?
    child=
}

# The report without its wall times (top-level lines of the pretty-printed report).
report_sans_wall() { grep -v -E '^  "(ga_)?wall_time_s": ' "$1"; }

# Compares the run in $RUN with the reference; prints nothing if equal, else what differs.
compare() {
    local diffs=() f
    if [[ $(cd "$REF" && ls -A | sort) != $(cd "$RUN" && ls -A | sort) ]]; then
        diffs+=("file list: $(diff <(cd "$REF" && ls -A | sort) <(cd "$RUN" && ls -A | sort) | grep '^[<>]' | tr '\n' ' ')")
    fi
    for f in "$REF"/*; do
        f=$(basename "$f")
        [[ -f $RUN/$f ]] || continue
        if [[ $f == report.json ]]; then
            if ! cmp -s <(report_sans_wall "$REF/$f") <(report_sans_wall "$RUN/$f"); then
                diffs+=("report.json: $(diff <(report_sans_wall "$REF/$f") <(report_sans_wall "$RUN/$f") | grep '^[<>]' | head -4 | tr -s ' ' | tr '\n' ' ')")
            fi
        elif ! cmp -s "$REF/$f" "$RUN/$f"; then
            diffs+=("$f")
        fi
    done
    if ! cmp -s "$REF_CK/checkpoint.json" "$CK/checkpoint.json"; then
        diffs+=("checkpoint.json")
    fi
    (( ${#diffs[@]} == 0 )) || printf '%s; ' "${diffs[@]}"
}

# The reference: one uninterrupted run, at the same path as every trial's.
LOG=$T/reference.log
t0=$(now_ms)
start_run
wait_run
DUR_MS=$(( $(now_ms) - t0 ))
REF_MS=$DUR_MS
if (( rc != 0 )); then
    echo "the reference run failed (exit $rc):" >&2
    tail -5 "$LOG" >&2
    exit 1
fi
REF=$T/ref/out
REF_CK=$REF.checkpoint
mkdir -p "$T/ref"
mv "$RUN" "$REF"
mv "$CK" "$REF_CK"
echo "reference: $BIN run scenes/evolve_fall.ron ${SETS[*]}"
echo "           $DUR_MS ms uninterrupted, generation $(jq '[.content[].state.generation] | min' "$REF_CK/checkpoint.json"); kill-time seed $SEED, $KILLS kill(s) a trial"

RANDOM=$SEED
matched=0
kmin=; kmax=
for (( i = 1; i <= TRIALS; i++ )); do
    rm -rf "$T/run"
    LOG=$T/trial$i.log
    kills=()
    leftovers=
    k=1
    while (( k <= KILLS )); do
        at=$(( (RANDOM * 32768 + RANDOM) % DUR_MS ))
        resuming=no
        if [[ -f $CK/checkpoint.json ]]; then start_run --resume "$CK"; resuming=yes; else start_run; fi
        t0=$(now_ms)
        sleep "$(printf '%d.%03d' $(( at / 1000 )) $(( at % 1000 )))"
        kill -9 "$child" 2>/dev/null || true
        wait_run
        if (( rc == 0 && k > 1 )); then
            # A resume after a kill finished before the next kill: the trial is complete.
            kills+=("${at} ms: the resume finished first")
            break
        elif (( rc == 0 )); then
            # The run was faster than the reference (the machine's load varies): it finished
            # before the kill. Draw again within its duration, from the start.
            elapsed=$(( $(now_ms) - t0 ))
            kills+=("${at} ms finished first (${elapsed} ms)")
            (( elapsed >= DUR_MS )) || DUR_MS=$elapsed
            rm -rf "$T/run"
            k=1
            attempts=$(( ${attempts:-0} + 1 ))
            if (( attempts > 5 )); then
                echo "trial $i: finished before the kill 6 times" >&2
                exit 1
            fi
            continue
        elif (( rc != 137 )); then
            echo "trial $i: the run failed (exit $rc) before the kill:" >&2
            tail -5 "$LOG" >&2
            exit 1
        fi
        # A killed run leaves no output folder (it writes into a temporary one).
        [[ -e $RUN ]] && leftovers+=" out/ present after the kill;"
        kills+=("${at} ms → generation $(ck_generation)")
        if [[ -z $kmin ]] || (( at < kmin )); then kmin=$at; fi
        if [[ -z $kmax ]] || (( at > kmax )); then kmax=$at; fi
        k=$(( k + 1 ))
    done
    attempts=0
    if (( rc != 0 )); then
        resuming=no
        if [[ -f $CK/checkpoint.json ]]; then start_run --resume "$CK"; resuming=yes; else start_run; fi
        wait_run
        if (( rc != 0 )); then
            echo "trial $i: the resume failed (exit $rc):" >&2
            tail -5 "$LOG" >&2
            exit 1
        fi
        [[ $resuming == yes ]] || kills+=("no checkpoint yet: started again")
    fi
    # Temporary files left by the killed runs (e.g. a checkpoint's `.checkpoint.json.tmp<pid>-<n>`
    # when the kill fell between its write and its rename: never read, but never removed either).
    stray=$(cd "$T/run" && find . -name '.*' -not -name '.' | sort | tr '\n' ' ')
    [[ -z $stray ]] || leftovers+=" left: $stray;"
    diff_text=$(compare)
    if [[ -z $diff_text ]]; then
        matched=$(( matched + 1 ))
        verdict="match"
    else
        verdict="MISMATCH: $diff_text"
        cp -r "$T/run" "${KEEP_FAILED:-/tmp}/sigkill_resume_trial$i" 2>/dev/null || true
        cp "$LOG" "${KEEP_FAILED:-/tmp}/sigkill_resume_trial$i/" 2>/dev/null || true
    fi
    printf 'trial %2d: kill at %s; %s%s\n' "$i" "$(printf '%s; ' "${kills[@]}" | sed 's/; $//')" "$verdict" "${leftovers:+ (${leftovers# })}"
done

echo "$matched of $TRIALS matched (kill times ${kmin:--}–${kmax:--} ms; the reference ran $REF_MS ms)"
(( matched == TRIALS ))
