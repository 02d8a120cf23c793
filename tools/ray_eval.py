#!/usr/bin/env python3
"""Evaluate marionette GA generations on a Ray cluster.

This program speaks marionette's JSON-lines evaluation protocol (marionette-eval/2) on its own
standard input and output, exactly as `marionette eval --stdin` does, so the engine's GA uses it
as an evaluator (scene field `evaluator: Command(["python3", "tools/ray_eval.py"])`) while the GA
loop, its checkpoints and its bits stay in the engine. Behind it, each Ray actor holds one
long-lived `marionette eval --stdin` worker that uses all the cores of its node; a generation's
genomes are split into one contiguous chunk per actor, and the replies are returned in index
order.

On a laptop (a local Ray started by this program):
    marionette run scenes/evolve_fall.ron --set 'evaluator={"Command":["python3","tools/ray_eval.py"]}'
On a cluster (the engine and this program run on the head node; actors on every node):
    ray job submit --working-dir . -- marionette run scenes/evolve_fall.ron \
        --set 'evaluator={"Command":["python3","tools/ray_eval.py","--address","auto"]}'

Options: --address ADDR (Ray cluster, default: start a local one), --actors N (default: one
per node, or 1 locally), --worker PATH (the marionette binary, default `marionette` on PATH or
target/release/marionette), --cpus-per-actor N.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

PROTOCOL = "marionette-eval/2"


def find_worker(given):
    if given:
        return given
    here = os.path.dirname(os.path.abspath(__file__))
    local = os.path.join(here, "..", "target", "release", "marionette")
    if os.path.exists(local):
        return os.path.abspath(local)
    found = shutil.which("marionette")
    if found:
        return found
    sys.exit("ray_eval: no marionette binary (pass --worker PATH)")


def make_actor_class(ray):
    @ray.remote
    class Worker:
        """One long-lived `marionette eval --stdin` process."""

        def __init__(self, binary, header_line):
            self.proc = subprocess.Popen(
                [binary, "eval", "--stdin"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                text=True,
                bufsize=1,
            )
            self.proc.stdin.write(header_line)
            self.proc.stdin.flush()

        def evaluate(self, lines):
            """Sends genome lines, then the batch end; returns the reply lines."""
            for line in lines:
                self.proc.stdin.write(line)
            self.proc.stdin.write('{"evaluate":true}\n')
            self.proc.stdin.flush()
            replies = []
            while True:
                reply = self.proc.stdout.readline()
                if not reply:
                    raise RuntimeError("marionette eval worker closed its output")
                if json.loads(reply).get("done") is not None:
                    return replies
                replies.append(reply)

        def close(self):
            self.proc.stdin.close()
            self.proc.wait()
            return self.proc.returncode

    return Worker


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--address", default=None)
    ap.add_argument("--actors", type=int, default=None)
    ap.add_argument("--worker", default=None)
    ap.add_argument("--cpus-per-actor", type=float, default=None)
    args = ap.parse_args()

    import ray  # imported here so --help works without Ray

    header_line = sys.stdin.readline()
    header = json.loads(header_line)
    if header.get("protocol") != PROTOCOL:
        sys.exit(f"ray_eval: protocol {header.get('protocol')!r} is not {PROTOCOL!r}")

    ray.init(address=args.address, include_dashboard=False, log_to_driver=False,
             logging_level="ERROR")
    nodes = [n for n in ray.nodes() if n.get("Alive")]
    n_actors = args.actors or max(1, len(nodes))
    cpus = args.cpus_per_actor or max(1.0, ray.cluster_resources().get("CPU", 1.0) / n_actors)
    Worker = make_actor_class(ray).options(num_cpus=cpus)
    binary = find_worker(args.worker)
    actors = [Worker.remote(binary, header_line) for _ in range(n_actors)]

    batch = []
    for line in sys.stdin:
        if not line.strip():
            continue
        msg = json.loads(line)
        if "genes" in msg:
            batch.append(line if line.endswith("\n") else line + "\n")
            continue
        if msg.get("evaluate"):
            # Contiguous chunks, one per actor; replies carry their index.
            k = max(1, -(-len(batch) // len(actors)))
            chunks = [batch[i:i + k] for i in range(0, len(batch), k)]
            futures = [a.evaluate.remote(c) for a, c in zip(actors, chunks)]
            replies = [r for rs in ray.get(futures) for r in rs]
            replies.sort(key=lambda r: json.loads(r)["index"])
            out = "".join(replies) + json.dumps({"done": len(batch)}) + "\n"
            sys.stdout.write(out)
            sys.stdout.flush()
            batch = []
    ray.get([a.close.remote() for a in actors])
    ray.shutdown()


if __name__ == "__main__":
    main()
